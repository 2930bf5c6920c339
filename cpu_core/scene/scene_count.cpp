// THE COUNT BEFORE THE BUILD (scene_load_state.hpp check_scene_triangles): the caps are
// checked against the triangles the whole scene will have before its first object is
// tessellated or its first mesh file parsed, so that a refused scene has built nothing.
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <vector>

#include "base/error.hpp"
#include "base/input_file.hpp"
#include "scene/scene_load_state.hpp"

namespace abcube::detail {

namespace {

constexpr int DEFAULT_SEGMENTS = 32, MIN_SEGMENTS = 3, MAX_SEGMENTS = 4096;
constexpr size_t MAX_NODE_VISITS = size_t{1} << 20;  // the glTF reader's own bound

// One object's triangles: exact, or (an OBJ file not yet counted) an upper bound.
struct Counted {
  std::string path;  // where a refusal points
  uint64_t triangles = 0;
  std::string obj_file;  // an OBJ file whose faces are counted when the bound is not enough
};

const Json* member(const Json& v, const char* key) {
  if (!v.is_object()) return nullptr;
  const auto it = v.find(key);
  return it == v.end() ? nullptr : &*it;
}

int64_t integer_or(const Json* v, int64_t fallback) {
  return v && v->is_number_integer() ? v->get<int64_t>() : fallback;
}

// The JSON of a glTF file (a .glb's JSON chunk, read alone), or "" when it cannot be read:
// the reader itself says why when the object loads.
std::string gltf_json(const std::string& resolved, uint64_t max_bytes) {
  if (!input_file_problem(resolved, max_bytes).empty()) return "";
  std::ifstream in(resolved, std::ios::binary);
  char header[20] = {};
  in.read(header, sizeof header);
  if (in.gcount() >= 4 && std::string(header, 4) == "glTF") {
    if (in.gcount() < 20) return "";
    uint32_t length = 0;
    std::copy(header + 12, header + 16, reinterpret_cast<char*>(&length));
    // The chunk's length is the file's word: nothing is allocated beyond what the file holds.
    std::error_code ec;
    const uint64_t size = std::filesystem::file_size(resolved, ec);
    if (ec || length > size - 20) return "";
    std::string json(length, '\0');
    in.read(json.data(), length);
    return static_cast<uint32_t>(in.gcount()) == length ? json : "";
  }
  return read_input_file(resolved, max_bytes, "glTF");
}

// A glTF document's triangles as the reader makes them: every node reached from the scene's
// roots (or the nodes no node names as a child), each mesh's triangle, strip and fan
// primitives, as often as nodes instance it.
uint64_t gltf_triangles(const Json& doc) {
  const Json* nodes = member(doc, "nodes");
  const Json* meshes = member(doc, "meshes");
  const Json* accessors = member(doc, "accessors");
  if (!nodes || !nodes->is_array()) return 0;
  const auto accessor_count = [&](const Json* index) -> uint64_t {
    if (!index || !index->is_number_integer() || !accessors || !accessors->is_array()) return 0;
    const int64_t i = index->get<int64_t>();
    if (i < 0 || static_cast<size_t>(i) >= accessors->size()) return 0;
    return static_cast<uint64_t>(
        std::max<int64_t>(integer_or(member((*accessors)[static_cast<size_t>(i)], "count"), 0), 0));
  };
  const auto mesh_triangles = [&](int64_t m) -> uint64_t {
    if (!meshes || !meshes->is_array() || m < 0 || static_cast<size_t>(m) >= meshes->size()) return 0;
    const Json* primitives = member((*meshes)[static_cast<size_t>(m)], "primitives");
    uint64_t sum = 0;
    for (const Json& p : primitives && primitives->is_array() ? *primitives : Json::array()) {
      const int64_t mode = integer_or(member(p, "mode"), 4);
      const uint64_t n =
          member(p, "indices")
              ? accessor_count(member(p, "indices"))
              : accessor_count(member(member(p, "attributes") ? *member(p, "attributes") : p, "POSITION"));
      sum += mode == 4 ? n / 3 : (mode == 5 || mode == 6) && n >= 2 ? n - 2 : 0;
    }
    return sum;
  };
  std::vector<int64_t> roots;
  const Json* scenes = member(doc, "scenes");
  if (member(doc, "scene") || (scenes && scenes->is_array() && !scenes->empty())) {
    const int64_t s = integer_or(member(doc, "scene"), 0);
    if (!scenes || !scenes->is_array() || s < 0 || static_cast<size_t>(s) >= scenes->size()) return 0;
    const Json* list = member((*scenes)[static_cast<size_t>(s)], "nodes");
    for (const Json& r : list && list->is_array() ? *list : Json::array()) roots.push_back(integer_or(&r, -1));
  } else {
    std::vector<bool> child(nodes->size(), false);
    for (const Json& n : *nodes) {
      const Json* children = member(n, "children");
      for (const Json& c : children && children->is_array() ? *children : Json::array()) {
        const int64_t i = integer_or(&c, -1);
        if (i >= 0 && static_cast<size_t>(i) < child.size()) child[static_cast<size_t>(i)] = true;
      }
    }
    for (size_t i = 0; i < child.size(); ++i) {
      if (!child[i]) roots.push_back(static_cast<int64_t>(i));
    }
  }
  uint64_t total = 0;
  size_t visits = 0;
  std::vector<bool> on_path(nodes->size(), false);
  const std::function<void(int64_t)> visit = [&](int64_t i) {
    if (i < 0 || static_cast<size_t>(i) >= nodes->size() || on_path[static_cast<size_t>(i)]) return;
    if (++visits > MAX_NODE_VISITS) return;  // the reader refuses such a file
    on_path[static_cast<size_t>(i)] = true;
    const Json& n = (*nodes)[static_cast<size_t>(i)];
    if (const Json* m = member(n, "mesh")) total += mesh_triangles(integer_or(m, -1));
    const Json* children = member(n, "children");
    for (const Json& c : children && children->is_array() ? *children : Json::array()) visit(integer_or(&c, -1));
    on_path[static_cast<size_t>(i)] = false;
  };
  for (const int64_t r : roots) visit(r);
  return total;
}

// A mesh or gltf object's file, resolved, when it can be read inside the root; "" otherwise
// (the object's own load says why).
std::string object_file(const LoadState& st, const Json& object) {
  const Json* file = member(object, "file");
  if (!file || !file->is_string() || file->get<std::string>().empty()) return "";
  const std::string resolved = resolve_mesh_path(st.src, file->get<std::string>());
  if (!st.root.empty() && !inside_root(st.root, resolved)) return "";
  return input_file_problem(resolved, st.limits.max_mesh_bytes).empty() ? resolved : "";
}

Counted count_object(const LoadState& st, const Json& object, size_t index) {
  Counted c;
  c.path = index_path("objects", index);
  const Json* type = member(object, "type");
  if (!type || !type->is_string()) return c;
  const std::string t = type->get<std::string>();
  if (t == "triangle") c.triangles = 1;
  if (t == "quad") c.triangles = 2;
  if (t == "box") c.triangles = 12;
  if (t == "sphere") {
    const int64_t segments = integer_or(member(object, "segments"), member(object, "segments") ? 0 : DEFAULT_SEGMENTS);
    if (segments >= MIN_SEGMENTS && segments <= MAX_SEGMENTS) {
      c.triangles = sphere_triangle_count(static_cast<int>(segments));
      c.path = member_path(c.path, "segments");  // its count is what the segments make
    }
  }
  if (t == "mesh" || t == "gltf") {
    const std::string resolved = object_file(st, object);
    if (resolved.empty()) return c;
    c.path = member_path(c.path, "file");
    if (t == "mesh") {
      std::error_code ec;
      c.triangles = std::filesystem::file_size(resolved, ec) / 2;  // "f 1 2 3\n": 2n + 2 bytes, n - 2 triangles
      c.obj_file = resolved;
    } else {
      try {
        c.triangles =
            gltf_triangles(parse_document(gltf_json(resolved, st.limits.max_mesh_bytes), Source{resolved, "."}));
      } catch (const InputError&) {
        c.triangles = 0;  // not JSON: the reader says so when the object loads
      }
    }
  }
  return c;
}

}  // namespace

void check_scene_triangles(const LoadState& st, const Json& objects) {
  if (!objects.is_array()) return;
  std::vector<Counted> counted;
  uint64_t bound = 0;
  for (size_t i = 0; i < objects.size(); ++i) {
    counted.push_back(count_object(st, objects[i], i));
    bound += counted.back().triangles;
  }
  const bool capped = st.limits.max_triangles > 0 && bound > st.limits.max_triangles;
  const bool budgeted = st.memory_budget > 0 && bound > st.memory_budget / SCENE_TRIANGLE_BYTES;
  if (!capped && !budgeted && bound <= MAX_TRIANGLES) return;  // even the bound fits: nothing to count
  uint64_t total = 0;
  for (Counted& c : counted) {
    if (!c.obj_file.empty()) c.triangles = count_face_triangles(c.obj_file);
    total += c.triangles;
    if (total > MAX_TRIANGLES) {
      fail(st.src, c.path, "the scene would exceed " + std::to_string(MAX_TRIANGLES) + " triangles");
    }
    check_triangle_cap(st, c.path, total);
  }
}

}  // namespace abcube::detail
