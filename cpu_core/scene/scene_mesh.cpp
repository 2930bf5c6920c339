// Mesh objects: triangles from a Wavefront OBJ file, materials from the MTL files it
// names, and the confinement of both to LoadLimits::root.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <utility>

#include <tiny_obj_loader.h>

#include "base/error.hpp"
#include "base/input_file.hpp"
#include "base/memory.hpp"
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

// First line of a tinyobjloader message that contains `needle`, or "".
std::string find_line(const std::string& text, const char* needle) {
  const std::vector<std::string> lines = find_lines(text, needle);
  return lines.empty() ? "" : lines.front();
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

// Appends one OBJ face (already validated) to `out` (indexed, positions, normals and
// texture coordinates already copied from the file's), triangulating polygons.
void add_obj_face(const tinyobj::index_t* corners, size_t n, int material, LocalMesh* out) {
  std::vector<glm::dvec3> p(n);
  bool smooth = true;
  for (size_t k = 0; k < n; ++k) {
    p[k] = out->positions[static_cast<size_t>(corners[k].vertex_index)];
    smooth = smooth && corners[k].normal_index >= 0;
  }
  for (const auto& t : triangulate_polygon(p)) {
    for (int k : t) {
      const tinyobj::index_t& c = corners[static_cast<size_t>(k)];
      out->position_index.push_back(static_cast<uint32_t>(c.vertex_index));
      out->normal_index.push_back(smooth ? static_cast<uint32_t>(c.normal_index) : LocalMesh::NO_NORMAL);  // flat
      if (!out->uvs.empty()) {
        out->uv_index.push_back(c.texcoord_index >= 0 ? static_cast<uint32_t>(c.texcoord_index) : LocalMesh::NO_UV);
      }
    }
    out->material.push_back(material);
  }
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

// What tinyobjloader read of one OBJ file and its MTL files.
struct ObjFile {
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::map<std::string, std::string> mtl_file_of;  // material name -> the MTL file it came from
  std::string warning, error;
};

// tinyobj::ObjReader::ParseFromFile (MTL files looked up in the OBJ's folder, no
// triangulation, no vertex colours) with the MTL files confined to the root.
ObjFile parse_obj(const LoadState& st, const std::string& path, const std::string& resolved) {
  ObjFile obj;
  std::ifstream in(resolved);
  if (!in) fail(st.src, path, "cannot read mesh " + quote_path(resolved) + ": " + std::strerror(errno));
  const size_t slash = resolved.find_last_of("/\\");
  const std::string base_dir = slash == std::string::npos || slash == 0 ? "" : resolved.substr(0, slash) + "/";
  ConfinedMaterialReader mtl(base_dir, st.root, st.limits.max_scene_bytes);
  const bool ok = tinyobj::LoadObj(&obj.attrib, &obj.shapes, &obj.materials, &obj.warning, &obj.error, &in, &mtl,
                                   false /* triangulate: ear-clipped here, keeping the winding */, false);
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
  obj.mtl_file_of = std::move(mtl.file_of);
  if (!ok)
    fail(st.src, path, "cannot parse mesh " + quote_path(resolved) + ": " + printable(find_line(obj.error, ""), 160));
  return obj;
}

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

// Triangles the faces of an OBJ file become (ear clipping: n - 2 per polygon of n corners).
uint64_t obj_triangle_count(const ObjFile& obj) {
  uint64_t count = 0;
  for (const tinyobj::shape_t& shape : obj.shapes) {
    for (const auto n : shape.mesh.num_face_vertices) count += n >= 3 ? n - 2u : 0u;
  }
  return count;
}

}  // namespace

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
              (st.limits.max_memory_bytes > 0 ? " of --max-memory" : " of memory available");
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

// The OBJ file's faces as triangles of `m` (its vertex arrays filled), each with its MTL
// material when `use_mtl` (mtl_ids: per material of the file, the scene's).
void add_obj_faces(LoadState& st, const std::string& path, const std::string& resolved, const ObjFile& obj,
                   const std::vector<uint32_t>& mtl_ids, bool use_mtl, LocalMesh* out) {
  LocalMesh& m = *out;
  const tinyobj::attrib_t& a = obj.attrib;
  const int vertex_count = static_cast<int>(a.vertices.size() / 3);
  const int normal_count = static_cast<int>(a.normals.size() / 3);
  const int uv_count = static_cast<int>(a.texcoords.size() / 2);
  const uint64_t triangles = obj_triangle_count(obj);
  m.position_index.reserve(3 * triangles);
  m.normal_index.reserve(3 * triangles);
  if (uv_count > 0) m.uv_index.reserve(3 * triangles);
  m.material.reserve(triangles);
  for (const tinyobj::shape_t& shape : obj.shapes) {
    size_t offset = 0;
    for (size_t face = 0; face < shape.mesh.num_face_vertices.size(); ++face) {
      const size_t n = shape.mesh.num_face_vertices[face];
      if (n < 3) {
        fail(st.src, path,
             "mesh " + quote_path(resolved) + ": face " + std::to_string(face + 1) + " of shape " + quote(shape.name) +
                 " has " + std::to_string(n) + " corners (a face needs 3 or more)");
      }
      const tinyobj::index_t* corners = &shape.mesh.indices[offset];
      offset += n;
      for (size_t k = 0; k < n; ++k) {
        if (corners[k].vertex_index < 0 || corners[k].vertex_index >= vertex_count ||
            corners[k].normal_index >= normal_count || corners[k].texcoord_index >= uv_count) {
          fail(st.src, path,
               "mesh " + quote_path(resolved) + ": face of shape " + quote(shape.name) + " has an index out of range");
        }
      }
      const int mtl = face < shape.mesh.material_ids.size() ? shape.mesh.material_ids[face] : -1;
      int material = -1;  // the object's own
      if (use_mtl) {
        material = mtl >= 0 && static_cast<size_t>(mtl) < mtl_ids.size()
                       ? static_cast<int>(mtl_ids[static_cast<size_t>(mtl)])
                       : static_cast<int>(default_material(st));
      }
      add_obj_face(corners, n, material, &m);
      if (st.scene.triangles->triangle_count() + m.triangle_count() > MAX_TRIANGLES) {
        fail(st.src, path, "the scene would exceed " + std::to_string(MAX_TRIANGLES) + " triangles");
      }
    }
  }
}

LocalMesh read_obj(LoadState& st, const Fields& f, bool use_mtl) {
  const std::string path = f.at("file");
  const std::string file = read_string(st.src, f.need("file"), path);
  if (file.empty()) fail(st.src, path, "must name an OBJ file, got \"\"");
  const std::string resolved = resolve_mesh_path(st.src, file);
  check_inside_root(st, path, file, resolved);
  check_obj_file(st, path, resolved);
  const ObjFile obj = parse_obj(st, path, resolved);
  check_triangle_cap(st, path, obj_triangle_count(obj));  // before anything is made
  if (use_mtl) warn_missing_mtl(st, path, file, obj);
  const std::vector<uint32_t> mtl_ids =
      use_mtl ? mtl_material_ids(st, path, file, resolved, obj.materials, obj.mtl_file_of) : std::vector<uint32_t>{};
  const tinyobj::attrib_t& a = obj.attrib;
  const int vertex_count = static_cast<int>(a.vertices.size() / 3);
  const int normal_count = static_cast<int>(a.normals.size() / 3);
  const int uv_count = static_cast<int>(a.texcoords.size() / 2);
  LocalMesh m;
  m.indexed = true;
  m.positions.reserve(static_cast<size_t>(vertex_count));
  for (size_t v = 0; v < static_cast<size_t>(vertex_count); ++v) {
    m.positions.emplace_back(a.vertices[3 * v], a.vertices[3 * v + 1], a.vertices[3 * v + 2]);
  }
  m.normals.reserve(static_cast<size_t>(normal_count));
  for (size_t v = 0; v < static_cast<size_t>(normal_count); ++v) {
    m.normals.emplace_back(a.normals[3 * v], a.normals[3 * v + 1], a.normals[3 * v + 2]);
  }
  m.uvs.reserve(static_cast<size_t>(uv_count));
  for (size_t v = 0; v < static_cast<size_t>(uv_count); ++v) {
    m.uvs.emplace_back(a.texcoords[2 * v], a.texcoords[2 * v + 1]);
    if (!std::isfinite(m.uvs.back().x) || !std::isfinite(m.uvs.back().y)) {
      fail(st.src, path, "mesh " + quote_path(resolved) + ": vt " + std::to_string(v + 1) + " is not finite");
    }
  }
  add_obj_faces(st, path, resolved, obj, mtl_ids, use_mtl, &m);
  return m;
}

}  // namespace abcube::detail
