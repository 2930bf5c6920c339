// What the scene-loading tests share (test_scene_load.cpp, test_scene_mesh.cpp,
// test_scene_limits.cpp, test_scene_gltf.cpp, test_framing.cpp): scratch folders, the
// format's example, scenes as text, loading them, and geometric checks.
#pragma once
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <tuple>

#include "base/error.hpp"
#include "base/input_file.hpp"
#include "scene/framing.hpp"
#include "scene/scene_json.hpp"
#include "scene/scene_load.hpp"
#include "scene/tessellate.hpp"

namespace abcube::scene_test {

namespace fs = std::filesystem;

// A fresh folder under the system temp dir, removed with its contents afterwards.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "abcube_scene_XXXXXX").string();
    path_ = ::mkdtemp(pattern.data()) ? fs::path(pattern) : fs::path();
    EXPECT_FALSE(path_.empty()) << "mkdtemp failed";
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }
  std::string write(const std::string& relative, const std::string& text) const {
    const fs::path p = path_ / relative;
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }

 private:
  fs::path path_;
};

// The example of scene-format.md, verbatim.
inline const char* const FORMAT_EXAMPLE = R"({
  "version": 1,
  "camera": {
    "position": [0, 1, -4], "look_at": [0, 0.5, 0], "up": [0, 1, 0],
    "fov_y": 60, "width": 512, "height": 512
  },
  "background": [0, 0, 0],
  "ambient": [0.1, 0.1, 0.1],
  "lights": [
    { "type": "point", "position": [3, 5, -3], "color": [1, 1, 1], "cast_shadows": true }
  ],
  "materials": {
    "white":  { "color": [0.8, 0.8, 0.8] },
    "mirror": { "color": [0.1, 0.1, 0.1], "specular": 0.5, "shininess": 64, "reflect": 0.9 },
    "glass":  { "color": [1, 1, 1], "diffuse": 0.0, "transmit": 0.9, "ior": 1.5 },
    "veil":   { "color": [0.2, 0.4, 1.0], "opacity": 0.5 }
  },
  "objects": [
    { "type": "triangle", "vertices": [[-1,0,0],[1,0,0],[0,1,0]], "material": "white" },
    { "type": "quad", "vertices": [[-5,0,-5],[5,0,-5],[5,0,5],[-5,0,5]], "material": "white" },
    { "type": "box", "min": [-0.5,0,-0.5], "max": [0.5,1,0.5], "material": "mirror" },
    { "type": "sphere", "center": [0,1,0], "radius": 1, "segments": 64, "material": "glass" },
    { "type": "mesh", "file": "meshes/knot.obj", "material": "white",
      "transform": { "translate": [0,0,2], "rotate_deg": [0,45,0], "scale": 0.5 } }
  ],
  "render": {
    "method": "abuffer",
    "cube_resolution": 512,
    "max_depth": 4
  }
})";

// A unit cube written with quad faces, wound outward: closed, 12 triangles.
inline const char* const CUBE_OBJ = R"(v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
f 1 4 3 2
f 5 6 7 8
f 1 5 8 4
f 2 3 7 6
f 1 2 6 5
f 4 8 7 3
)";

// A small valid scene whose parts a test replaces one at a time.
struct SceneText {
  std::string version = "1";
  std::string camera =
      R"({"position": [0, 1, 5], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y": 60, "width": 64, "height": 48})";
  std::string lights = R"([{"type": "point", "position": [2, 4, 3], "color": [1, 1, 1]}])";
  std::string materials = R"({"white": {"color": [0.8, 0.8, 0.8]}, "m": {"reflect": 0.5}})";
  std::string objects = R"([{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "white"}])";
  std::string render = R"({"method": "abuffer", "cube_resolution": 64, "max_depth": 2})";
  std::string extra;  // more top-level members, with a leading comma

  std::string str() const {
    return "{\n\"version\": " + version + ",\n\"camera\": " + camera + ",\n\"lights\": " + lights +
           ",\n\"materials\": " + materials + ",\n\"objects\": " + objects + ",\n\"render\": " + render + extra +
           "\n}\n";
  }
};

inline SceneText with_objects(const std::string& objects) {
  SceneText s;
  s.objects = objects;
  return s;
}

inline SceneData load_text(const std::string& text, const std::string& dir = ".") {
  return load_scene_text(text, "scene.json", dir);
}

// The message of the InputError that load() raises (a test failure if none, or if the
// message is not exactly one line); `what` names the load in the failure.
template <class Load>
inline std::string input_error(Load&& load, const std::string& what) {
  try {
    load();
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    return m;
  }
  ADD_FAILURE() << "no error for:\n" << what;
  return "";
}

inline std::string load_error(const std::string& text, const std::string& dir = ".") {
  return input_error([&] { load_text(text, dir); }, text);
}

#define EXPECT_ERROR(text, place)                                   \
  do {                                                              \
    const std::string message_ = load_error(text);                  \
    EXPECT_NE(message_.find(place), std::string::npos) << message_; \
  } while (0)

inline glm::dvec3 corner(const SceneData& s, size_t triangle, int k) {
  return glm::dvec3(s.triangles->positions[3 * triangle + static_cast<size_t>(k)]);
}

inline glm::dvec3 geometric_normal(const SceneData& s, size_t t) {
  return glm::normalize(glm::cross(corner(s, t, 1) - corner(s, t, 0), corner(s, t, 2) - corner(s, t, 0)));
}

// Every edge of the object used exactly twice, once in each direction (checked here
// independently of is_closed_surface, with an ordered map of corner positions).
inline bool edges_shared_twice(const SceneData& s, const SceneObject& o) {
  using Point = std::tuple<float, float, float>;
  std::map<std::pair<Point, Point>, int> directed;
  for (uint32_t t = o.first_triangle; t < o.first_triangle + o.triangle_count; ++t) {
    for (int k = 0; k < 3; ++k) {
      const glm::vec3 a = s.triangles->positions[3 * t + static_cast<size_t>(k)];
      const glm::vec3 b = s.triangles->positions[3 * t + static_cast<size_t>((k + 1) % 3)];
      ++directed[{Point(a.x, a.y, a.z), Point(b.x, b.y, b.z)}];
    }
  }
  for (const auto& [edge, count] : directed) {
    const auto reverse = directed.find({edge.second, edge.first});
    if (count != 1 || reverse == directed.end() || reverse->second != 1) return false;
  }
  return !directed.empty();
}

inline double object_volume(const SceneData& s, const SceneObject& o) {
  return signed_volume(*s.triangles, o.first_triangle, o.triangle_count);
}

// The message of the InputError that loading the scene file `path` under `limits` raises.
inline std::string limited_load_error(const std::string& path, const LoadLimits& limits) {
  return input_error([&] { load_scene(path, limits); }, path);
}

}  // namespace abcube::scene_test
