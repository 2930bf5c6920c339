// Mesh objects: triangles from a Wavefront OBJ file, materials from the MTL files it
// names, and the confinement of both to LoadLimits::root.
#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <utility>

#include <tiny_obj_loader.h>

#include "base/error.hpp"
#include "base/input_file.hpp"
#include "base/memory.hpp"
#include "base/parallel.hpp"
#include "scene/obj_text.hpp"
#include "scene/scene_load_state.hpp"
#include "scene/tessellate.hpp"

namespace abcube::detail {

namespace {

// The 1-based line of `key` (e.g. "map_Kd") in material `material` of the MTL file `file`,
// or 0 when it cannot be found (for messages only).
size_t mtl_line(const std::string& file, const std::string& material, const std::string& key) {
  std::ifstream in(file);
  bool inside = false;
  size_t number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    std::istringstream words(line);
    std::string first, rest;
    words >> first;
    if (first == "newmtl") {
      std::getline(words >> std::ws, rest);
      while (!rest.empty() && (rest.back() == '\r' || rest.back() == ' ')) rest.pop_back();
      inside = rest == material;
    } else if (inside && first == key) {
      return number;
    }
  }
  return 0;
}

// The format's material from an MTL entry: Kd -> color, mean of Ks -> specular,
// Ns -> shininess, d -> opacity, Ni -> ior (Ni below 1, which exporters write for
// "unset", is taken as 1), map_Kd -> texture (relative to the MTL file `mtl_file`).
// `where` prefixes messages.
Material convert_mtl(LoadState& st, const std::string& path, const std::string& where, const tinyobj::material_t& in,
                     const std::string& name, const std::string& mtl_file) {
  Material m;
  m.name = name;
  m.color = glm::dvec3(in.diffuse[0], in.diffuse[1], in.diffuse[2]);
  m.specular = (static_cast<double>(in.specular[0]) + in.specular[1] + in.specular[2]) / 3.0;
  m.shininess = in.shininess;
  m.opacity = in.dissolve;
  m.ior = std::max(1.0, static_cast<double>(in.ior));
  auto bad = [&](const char* what, double x) {
    fail(st.src, path,
         "mesh " + quote_path(where) + ": material " + quote(in.name) + ": " + what + ", got " + format_number(x));
  };
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(m.color[i]) || m.color[i] < 0) bad("Kd must be finite and >= 0", m.color[i]);
  }
  if (!(m.specular >= 0 && m.specular <= 1)) bad("mean Ks must be in [0, 1]", m.specular);
  if (!(m.shininess >= 0 && std::isfinite(m.shininess))) bad("Ns must be finite and >= 0", m.shininess);
  if (!(m.opacity >= 0 && m.opacity <= 1)) bad("d must be in [0, 1]", m.opacity);
  if (!std::isfinite(m.ior)) bad("Ni must be finite", m.ior);
  if (!in.diffuse_texname.empty()) {
    const size_t line = mtl_line(mtl_file, in.name, "map_Kd");
    const std::string at = quote_path(mtl_file) + (line > 0 ? ":" + std::to_string(line) : "") + ": map_Kd ";
    // MTL files written on Windows separate folders by '\' (assimp-testmodels' spider.mtl:
    // ".\wal67ar_small.jpg"): read as '/' here. (A file name holding a
    // '\' of its own cannot be named from an MTL file then.)
    std::string texture = in.diffuse_texname;
    std::replace(texture.begin(), texture.end(), '\\', '/');
    m.texture = texture_file(st, path, at, texture, std::filesystem::path(mtl_file).parent_path().string());
  }
  return m;
}

// Scene material index for each MTL material of an OBJ, made once per file.
std::vector<uint32_t> mtl_material_ids(LoadState& st, const std::string& path, const std::string& file,
                                       const std::string& resolved, const std::vector<tinyobj::material_t>& materials,
                                       const std::map<std::string, std::string>& mtl_file_of) {
  std::vector<uint32_t> ids;
  for (const tinyobj::material_t& mtl : materials) {
    const std::string key = resolved + '\n' + mtl.name;
    auto it = st.mtl_materials.find(key);
    if (it == st.mtl_materials.end()) {
      const auto from = mtl_file_of.find(mtl.name);
      const std::string mtl_file = from == mtl_file_of.end() ? resolved : from->second;
      const uint32_t id = add_material(st, convert_mtl(st, path, resolved, mtl, file + ":" + mtl.name, mtl_file));
      it = st.mtl_materials.emplace(key, id).first;
    }
    ids.push_back(it->second);
  }
  return ids;
}

// The distinct lines of a tinyobjloader message that contain `needle`.
std::vector<std::string> find_lines(const std::string& text, const char* needle) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.find(needle) != std::string::npos && std::find(lines.begin(), lines.end(), line) == lines.end()) {
      lines.push_back(line);  // once: tinyobjloader repeats a name at each use
    }
  }
  return lines;
}

// tinyobjloader's warning of a material it did not find, the name it holds quoted:
// "material [ 'NAME' ] not found in .mtl" (usemtl) and "Material file [ NAME ] not found
// in a path : DIR" (mtllib). Other lines are shown as they are, cut short.
std::string missing_material_message(const std::string& line) {
  const auto between = [&](const std::string& head, const std::string& tail, const char* what) -> std::string {
    if (line.rfind(head, 0) != 0) return "";
    const size_t end = line.rfind(tail);
    if (end == std::string::npos || end < head.size()) return "";
    return std::string(what) + " " + quote(line.substr(head.size(), end - head.size())) + " not found";
  };
  std::string m = between("material [ '", "' ] not found", "usemtl: material");
  if (m.empty()) m = between("Material file [ ", " ] not found", "mtllib: material file");
  return m.empty() ? printable(line) : m;
}

// tinyobjloader's MaterialFileReader, refusing before it is opened an MTL file outside the
// root (the first such name is kept in `escaped`) or one that is no regular file or larger
// than `max_bytes` (kept in `unreadable`, with why); the reader then reports failure.
class ConfinedMaterialReader final : public tinyobj::MaterialReader {
 public:
  ConfinedMaterialReader(const std::string& base_dir, const std::string& root, uint64_t max_bytes)
      : files_(base_dir), base_dir_(base_dir), root_(root), max_bytes_(max_bytes) {}
  bool operator()(const std::string& name, std::vector<tinyobj::material_t>* materials,
                  std::map<std::string, int>* by_name, std::string* warn, std::string* err) override {
    // The paths MaterialFileReader tries: each ':'-separated folder joined with `name`.
    std::vector<std::string> tried;
    std::istringstream folders(base_dir_);
    for (std::string folder; std::getline(folders, folder, ':');) {
      tried.push_back(folder.empty() || folder.back() == '/' ? folder + name : folder + "/" + name);
    }
    if (base_dir_.empty()) tried.push_back(name);
    for (const std::string& t : tried) {
      if (!root_.empty() && !inside_root(root_, t)) {
        if (escaped.empty()) escaped = name;
        return false;
      }
    }
    std::string opened;
    for (const std::string& t : tried) {
      std::error_code ec;
      if (!std::filesystem::exists(t, ec)) continue;  // MaterialFileReader tries the next
      const std::string problem = input_file_problem(t, max_bytes_);
      if (!problem.empty()) {
        if (unreadable.first.empty()) unreadable = {name, problem};
        return false;
      }
      opened = t;
      break;  // the one MaterialFileReader opens
    }
    const size_t before = materials->size();
    const bool ok = files_(name, materials, by_name, warn, err);
    for (size_t i = before; i < materials->size(); ++i) file_of.emplace((*materials)[i].name, opened);
    return ok;
  }
  std::string escaped;
  std::pair<std::string, std::string> unreadable;  // the name as written, and why
  std::map<std::string, std::string> file_of;      // each material's MTL file (its map_Kd is relative to it)

 private:
  tinyobj::MaterialFileReader files_;
  std::string base_dir_, root_;
  uint64_t max_bytes_;
};

// What one OBJ file holds, and the MTL materials its faces use.
struct ObjFile {
  ObjText text;
  std::vector<tinyobj::material_t> materials;
  std::map<std::string, std::string> mtl_file_of;  // material name -> the MTL file it came from
  // From face `first` on, the faces use materials[material] (-1: none), ascending.
  struct Run {
    uint64_t first;
    int material;
  };
  std::vector<Run> material_runs;
  std::string warning;  // tinyobjloader's words for a missing MTL file or material
};

// The file's MTL statements in order, as tinyobjloader resolved them: `mtllib` reads the
// first of its files not read before that can be (tinyobjloader's MaterialFileReader,
// confined to the root), `usemtl` names a material of the files read so far, or none (a
// warning).
void resolve_materials(const LoadState& st, const std::string& path, const std::string& resolved, ObjFile* obj) {
  const size_t slash = resolved.find_last_of("/\\");
  const std::string base_dir = slash == std::string::npos || slash == 0 ? "" : resolved.substr(0, slash) + "/";
  ConfinedMaterialReader mtl(base_dir, st.root, st.limits.max_scene_bytes);
  std::map<std::string, int> by_name;
  std::set<std::string> read;
  int material = -1;
  obj->material_runs.push_back({0, -1});
  for (const ObjStatement& s : obj->text.statements) {
    if (s.kind == ObjStatement::mtllib) {
      for (const std::string& name : split_mtllib(s.text)) {
        if (read.count(name) > 0) continue;
        std::string warning, error;
        const bool ok = mtl(name, &obj->materials, &by_name, &warning, &error);
        obj->warning += warning;
        if (ok) {
          read.insert(name);
          break;
        }
      }
      continue;
    }
    const auto it = by_name.find(s.text);
    if (it == by_name.end()) obj->warning += "material [ '" + s.text + "' ] not found in .mtl\n";
    const int id = it == by_name.end() ? -1 : it->second;
    if (id == material) continue;
    material = id;
    if (obj->material_runs.back().first == s.faces_before) obj->material_runs.pop_back();
    obj->material_runs.push_back({s.faces_before, id});
  }
  if (!mtl.escaped.empty()) {
    fail(st.src, path,
         "mtllib " + quote_path(mtl.escaped) + " of mesh " + quote_path(resolved) + " resolves outside --root " +
             st.root);
  }
  if (!mtl.unreadable.first.empty()) {
    fail(st.src, path,
         "mtllib " + quote_path(mtl.unreadable.first) + " of mesh " + quote_path(resolved) + ": " +
             mtl.unreadable.second);
  }
  obj->mtl_file_of = std::move(mtl.file_of);
}

// The OBJ file read on the load's threads (obj_text.hpp), its materials resolved.
ObjFile parse_obj(const LoadState& st, const std::string& path, const std::string& resolved) {
  ObjFile obj;
  try {
    ObjReading reading;
    reading.threads = st.limits.threads;
    obj.text = read_obj_text(resolved, reading);
  } catch (const std::runtime_error& e) {
    fail(st.src, path, "cannot read mesh " + quote_path(resolved) + ": " + e.what());
  }
  if (!obj.text.error.empty()) {
    fail(st.src, path,
         "cannot parse mesh " + quote_path(resolved) + ": line " + std::to_string(obj.text.error_line) + ": " +
             obj.text.error);
  }
  resolve_materials(st, path, resolved, &obj);
  return obj;
}

// Triangles the faces of an OBJ file become (ear clipping: n - 2 per polygon of n corners).
uint64_t obj_triangle_count(const ObjFile& obj) {
  uint64_t count = 0;
  for (const uint32_t n : obj.text.face_sizes) count += n - 2u;
  return count;
}

}  // namespace

// The triangles an OBJ file's face lines make (n - 2 for a line of n corners), counted
// without parsing, so that a mesh over the caps is refused before tinyobjloader holds it
// (its arrays take about what the triangles will). A face continued onto the next line
// with a backslash counts short: the count after parsing is the exact one.
uint64_t count_face_triangles(const std::string& resolved) {
  std::ifstream in(resolved, std::ios::binary);
  std::vector<char> buffer(size_t{1} << 20);
  uint64_t triangles = 0, corners = 0;
  enum { line_start, leading_space, after_f, in_face, other } state = line_start;
  bool in_token = false;
  const auto end_face = [&] {
    if (in_token) ++corners;
    if (corners >= 3) triangles += corners - 2;
    corners = 0;
    in_token = false;
  };
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const std::streamsize got = in.gcount();
    for (std::streamsize i = 0; i < got; ++i) {
      const char c = buffer[static_cast<size_t>(i)];
      if (c == '\n') {
        if (state == in_face) end_face();
        state = line_start;
        continue;
      }
      const bool space = c == ' ' || c == '\t' || c == '\r';
      switch (state) {
        case line_start:
        case leading_space: state = space ? leading_space : c == 'f' ? after_f : other; break;
        case after_f:
          state = space ? in_face : other;  // "f" then a blank: a face ("fo" is not)
          break;
        case in_face:
          if (space && in_token) ++corners;
          in_token = !space;
          break;
        case other: break;
      }
    }
  }
  if (state == in_face) end_face();
  return triangles;
}

std::string resolve_mesh_path(const Source& src, const std::string& file) {
  namespace fs = std::filesystem;
  const fs::path p(file);
  return (p.is_absolute() ? p : fs::path(src.base_dir) / p).lexically_normal().string();
}

std::string canonical_root(const std::string& root) {
  std::error_code ec;
  const std::filesystem::path p = std::filesystem::canonical(root, ec);
  if (ec || !std::filesystem::is_directory(p, ec)) {
    throw InputError(one_line("--root " + root + ": not a folder"));
  }
  return p.string();
}

bool inside_root(const std::string& root, const std::string& file) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path p = fs::weakly_canonical(fs::absolute(file, ec), ec);
  if (ec) return false;
  const fs::path r(root);
  // Component by component: /a/bc is not inside /a/b.
  auto pi = p.begin();
  for (auto ri = r.begin(); ri != r.end(); ++ri, ++pi) {
    if (ri->empty()) continue;  // a trailing separator
    if (pi == p.end() || *pi != *ri) return false;
  }
  return true;
}

void check_inside_root(const LoadState& st, const std::string& path, const std::string& file,
                       const std::string& resolved) {
  if (!st.root.empty() && !inside_root(st.root, resolved)) {
    fail(st.src, path, quote_path(file) + " resolves outside --root " + st.root);
  }
}

// A missing MTL file or material is what Assimp, Blender and three.js forgive: the faces
// get the default material, and one warning line names the first (and counts the rest).
void warn_missing_mtl(LoadState& st, const std::string& path, const std::string& file, const ObjFile& obj) {
  std::vector<std::string> missing = find_lines(obj.warning, "not found");
  if (!missing.empty()) {
    std::string more;
    if (missing.size() > 1) more = " (and " + std::to_string(missing.size() - 1) + " more)";
    st.scene.warnings.push_back(one_line(st.src.name + ": " + path + ": warning: mesh " + quote_path(file) + ": " +
                                         missing_material_message(missing.front()) + more +
                                         "; the default material is used"));
  }
}

// Refuses, with its place, an OBJ file that cannot be read or is larger than the memory
// budget, and one that holds more triangles than the caps leave room for.
void check_obj_file(LoadState& st, const std::string& path, const std::string& resolved) {
  std::string problem = input_file_problem(resolved, st.limits.max_mesh_bytes);
  std::error_code ec;
  const uint64_t size = problem.empty() ? std::filesystem::file_size(resolved, ec) : 0;
  if (problem.empty() && st.memory_budget > 0 && size > st.memory_budget) {
    problem = "is " + format_bytes(size) + ", more than the " + format_bytes(st.memory_budget) +
              (st.limits.max_memory_mib > 0 ? " of --max-memory" : " of memory available");
  }
  if (!problem.empty()) fail(st.src, path, "cannot read mesh " + quote_path(resolved) + ": " + problem);
  // A face line of n corners takes at least 2n + 2 bytes ("f 1 2 3\n") for its n - 2
  // triangles: a file that may hold more triangles than the caps leave room for is counted
  // before it is parsed.
  const uint64_t most = size / 2;
  const uint64_t held = st.scene.triangles->triangle_count();
  const bool over_cap = st.limits.max_triangles > 0 && held + most > st.limits.max_triangles;
  const bool over_budget = st.memory_budget > 0 && held + most > st.memory_budget / SCENE_TRIANGLE_BYTES;
  if (over_cap || over_budget) check_triangle_cap(st, path, count_face_triangles(resolved));
}

// A run of faces with the first corner and triangle of its first face: the faces of a
// run are made into triangles by one thread, writing only the run's places.
struct FaceRun {
  static constexpr size_t FACES = size_t{1} << 14;
  uint64_t face, corner, triangle;
};

std::vector<FaceRun> face_runs(const ObjText& text) {
  std::vector<FaceRun> runs;
  uint64_t corner = 0, triangle = 0;
  for (size_t f = 0; f < text.face_count(); ++f) {
    if (f % FaceRun::FACES == 0) runs.push_back({f, corner, triangle});
    corner += text.face_sizes[f];
    triangle += text.face_sizes[f] - 2u;
  }
  return runs;
}

// The scene material of each of obj's material runs (-1: the object's own, without
// use_mtl), made here, before the faces are taken on several threads: the default
// material is added to the scene only when a face uses it.
std::vector<int> run_materials(LoadState& st, const ObjFile& obj, const std::vector<uint32_t>& mtl_ids, bool use_mtl) {
  std::vector<int> out;
  const std::vector<ObjFile::Run>& runs = obj.material_runs;
  for (size_t r = 0; r < runs.size(); ++r) {
    const uint64_t end = r + 1 < runs.size() ? runs[r + 1].first : obj.text.face_count();
    const int mtl = runs[r].material;
    if (!use_mtl || runs[r].first >= end) {
      out.push_back(-1);
    } else {
      out.push_back(mtl >= 0 && static_cast<size_t>(mtl) < mtl_ids.size()
                        ? static_cast<int>(mtl_ids[static_cast<size_t>(mtl)])
                        : static_cast<int>(default_material(st)));
    }
  }
  return out;
}

// A face's corner whose index is out of range: the face's number, the corner's, which index
// (0 v, 1 vt, 2 vn) and its value (0-based; ObjCorner::OUT_OF_RANGE past 32 bits or before
// the first line).
struct BadCorner {
  uint64_t face = UINT64_MAX;
  uint32_t corner = 0;
  int field = 0;
  int32_t index = 0;
};

// The faces of `run` as triangles of m (its index arrays sized), each with its run's scene
// material; false at a face with an index out of range (which, in *bad).
bool triangulate_run(const ObjFile& obj, const FaceRun& run, const std::vector<int>& materials, LocalMesh* out,
                     BadCorner* bad) {
  LocalMesh& m = *out;
  const ObjText& text = obj.text;
  const int64_t counts[3] = {static_cast<int64_t>(m.positions.size()), static_cast<int64_t>(m.uvs.size()),
                             static_cast<int64_t>(m.normals.size())};
  const auto in_range = [&](int32_t index, int field, bool optional) {
    return (optional && index == ObjCorner::ABSENT) || (index >= 0 && index < counts[field]);
  };
  const uint64_t end = std::min<uint64_t>(run.face + FaceRun::FACES, text.face_count());
  uint64_t c = run.corner, t = run.triangle;
  size_t material_run =
      static_cast<size_t>(std::upper_bound(obj.material_runs.begin(), obj.material_runs.end(), run.face,
                                           [](uint64_t face, const ObjFile::Run& r) { return face < r.first; }) -
                          obj.material_runs.begin() - 1);
  std::vector<glm::dvec3> polygon;
  for (uint64_t f = run.face; f < end; ++f) {
    const ObjCorner* corners = &text.corners[c];
    const uint32_t n = text.face_sizes[f];
    c += n;
    while (material_run + 1 < obj.material_runs.size() && obj.material_runs[material_run + 1].first <= f)
      ++material_run;
    bool smooth = true;
    for (uint32_t k = 0; k < n; ++k) {
      const int32_t index[3] = {corners[k].v, corners[k].vt, corners[k].vn};
      for (int field = 0; field < 3; ++field) {
        if (!in_range(index[field], field, field > 0)) {
          *bad = {f, k, field, index[field]};
          return false;
        }
      }
      smooth = smooth && corners[k].vn != ObjCorner::ABSENT;
    }
    const auto emit = [&](const std::array<int, 3>& tri) {
      for (size_t k = 0; k < 3; ++k) {
        const ObjCorner& q = corners[tri[k]];
        m.position_index[3 * t + k] = static_cast<uint32_t>(q.v);
        m.normal_index[3 * t + k] = smooth ? static_cast<uint32_t>(q.vn) : LocalMesh::NO_NORMAL;  // flat
        if (!m.uvs.empty()) m.uv_index[3 * t + k] = q.vt >= 0 ? static_cast<uint32_t>(q.vt) : LocalMesh::NO_UV;
      }
      m.material[t++] = materials[material_run];
    };
    if (n == 3) {
      emit({0, 1, 2});
      continue;
    }
    polygon.resize(n);
    for (uint32_t k = 0; k < n; ++k) polygon[k] = m.positions[static_cast<size_t>(corners[k].v)];
    for (const auto& tri : triangulate_polygon(polygon)) emit(tri);
  }
  return true;
}

// The OBJ file's faces as triangles of `m` (its vertex arrays filled), each with its MTL
// material when `use_mtl` (mtl_ids: per material of the file, the scene's); polygons ear
// clipped. The face runs are taken on the load's threads.
void add_obj_faces(LoadState& st, const std::string& path, const std::string& resolved, const ObjFile& obj,
                   const std::vector<uint32_t>& mtl_ids, bool use_mtl, LocalMesh* out) {
  LocalMesh& m = *out;
  const uint64_t triangles = obj_triangle_count(obj);
  if (st.scene.triangles->triangle_count() + triangles > MAX_TRIANGLES) {
    fail(st.src, path, "the scene would exceed " + std::to_string(MAX_TRIANGLES) + " triangles");
  }
  m.position_index.resize(3 * triangles);
  m.normal_index.resize(3 * triangles);
  if (!m.uvs.empty()) m.uv_index.resize(3 * triangles);
  m.material.resize(triangles);
  const std::vector<FaceRun> runs = face_runs(obj.text);
  const std::vector<int> materials = run_materials(st, obj, mtl_ids, use_mtl);
  std::vector<BadCorner> bad(runs.size());
  parallel_for(runs.size(), thread_count(st.limits.threads, runs.size()),
               [&](size_t r, int) { triangulate_run(obj, runs[r], materials, &m, &bad[r]); });
  const BadCorner first =
      bad.empty() ? BadCorner{} : *std::min_element(bad.begin(), bad.end(), [](const BadCorner& a, const BadCorner& b) {
        return a.face < b.face;
      });
  if (first.face != UINT64_MAX) {
    const uint64_t line = obj_face_line(resolved, first.face);
    const char* name[3] = {"v", "vt", "vn"};
    const size_t lines[3] = {m.positions.size(), m.uvs.size(), m.normals.size()};
    const std::string value =
        first.index == ObjCorner::OUT_OF_RANGE ? std::string("out of range") : std::to_string(int64_t{first.index} + 1);
    fail(st.src, path,
         "mesh " + quote_path(resolved) + (line > 0 ? ": line " + std::to_string(line) : std::string()) +
             ": f: corner " + std::to_string(first.corner + 1) + ": " + name[first.field] + " index " + value +
             ", but the file has " + std::to_string(lines[first.field]) + " " + name[first.field] + " lines");
  }
}

LocalMesh read_obj(LoadState& st, const Fields& f, bool use_mtl) {
  const std::string path = f.at("file");
  const std::string file = read_string(st.src, f.need("file"), path);
  if (file.empty()) fail(st.src, path, "must name an OBJ file, got \"\"");
  const std::string resolved = resolve_mesh_path(st.src, file);
  check_inside_root(st, path, file, resolved);
  check_obj_file(st, path, resolved);
  ObjFile obj = parse_obj(st, path, resolved);
  check_triangle_cap(st, path, obj_triangle_count(obj));  // before anything is made
  if (use_mtl) warn_missing_mtl(st, path, file, obj);
  const std::vector<uint32_t> mtl_ids =
      use_mtl ? mtl_material_ids(st, path, file, resolved, obj.materials, obj.mtl_file_of) : std::vector<uint32_t>{};
  LocalMesh m;
  m.indexed = true;
  // As floats in the file's text: the values any reader of it sees.
  const auto take3 = [](std::vector<float>& from, std::vector<glm::dvec3>* to) {
    to->reserve(from.size() / 3);
    for (size_t k = 0; k + 3 <= from.size(); k += 3) to->emplace_back(from[k], from[k + 1], from[k + 2]);
    from = std::vector<float>();
  };
  take3(obj.text.v, &m.positions);
  take3(obj.text.vn, &m.normals);
  m.uvs.reserve(obj.text.vt.size() / 2);
  for (size_t k = 0; k + 2 <= obj.text.vt.size(); k += 2) m.uvs.emplace_back(obj.text.vt[k], obj.text.vt[k + 1]);
  obj.text.vt = std::vector<float>();
  for (size_t v = 0; v < m.uvs.size(); ++v) {
    if (!std::isfinite(m.uvs[v].x) || !std::isfinite(m.uvs[v].y)) {
      fail(st.src, path, "mesh " + quote_path(resolved) + ": vt " + std::to_string(v + 1) + " is not finite");
    }
  }
  add_obj_faces(st, path, resolved, obj, mtl_ids, use_mtl, &m);
  return m;
}

}  // namespace abcube::detail
