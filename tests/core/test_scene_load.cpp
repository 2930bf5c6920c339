// Scene loading (cpu_core/scene/scene_load.cpp, tessellate.cpp) against scene-format.md:
// the format's own example, one test per class of bad input (each message must name
// its place), and known answers for the tessellated primitives and the transform.
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

namespace abcube {
namespace {

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
const char* FORMAT_EXAMPLE = R"({
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
const char* CUBE_OBJ = R"(v 0 0 0
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

SceneText with_objects(const std::string& objects) {
  SceneText s;
  s.objects = objects;
  return s;
}

SceneData load_text(const std::string& text, const std::string& dir = ".") {
  return load_scene_text(text, "scene.json", dir);
}

// The message of the InputError that load() raises (a test failure if none, or if the
// message is not exactly one line); `what` names the load in the failure.
template <class Load>
std::string input_error(Load&& load, const std::string& what) {
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

std::string load_error(const std::string& text, const std::string& dir = ".") {
  return input_error([&] { load_text(text, dir); }, text);
}

#define EXPECT_ERROR(text, place)                                   \
  do {                                                              \
    const std::string message_ = load_error(text);                  \
    EXPECT_NE(message_.find(place), std::string::npos) << message_; \
  } while (0)

glm::dvec3 corner(const SceneData& s, size_t triangle, int k) {
  return glm::dvec3(s.triangles->positions[3 * triangle + static_cast<size_t>(k)]);
}

glm::dvec3 geometric_normal(const SceneData& s, size_t t) {
  return glm::normalize(glm::cross(corner(s, t, 1) - corner(s, t, 0), corner(s, t, 2) - corner(s, t, 0)));
}

// Every edge of the object used exactly twice, once in each direction (checked here
// independently of is_closed_surface, with an ordered map of corner positions).
bool edges_shared_twice(const SceneData& s, const SceneObject& o) {
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

double object_volume(const SceneData& s, const SceneObject& o) {
  return signed_volume(*s.triangles, o.first_triangle, o.triangle_count);
}

// ---- The format's example ---------------------------------------------------------------

TEST(SceneLoad, FormatExampleLoads) {
  TempDir dir;
  dir.write("meshes/knot.obj", CUBE_OBJ);
  const std::string path = dir.write("scene.json", FORMAT_EXAMPLE);
  const SceneData s = load_scene(path);

  EXPECT_EQ(s.file, path);
  EXPECT_EQ(s.camera.width, 512);
  EXPECT_DOUBLE_EQ(s.camera.fov_y_deg, 60);
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_TRUE(s.lights[0].cast_shadows);
  ASSERT_EQ(s.materials.size(), 4u);  // in file order
  const Material& white = s.materials[0];
  EXPECT_EQ(white.name, "white");
  EXPECT_DOUBLE_EQ(white.ambient, 1.0);
  EXPECT_DOUBLE_EQ(white.diffuse, 1.0);
  EXPECT_DOUBLE_EQ(white.specular, 0.0);
  EXPECT_DOUBLE_EQ(white.shininess, 32);
  EXPECT_DOUBLE_EQ(white.ior, 1.0);
  EXPECT_DOUBLE_EQ(white.opacity, 1.0);
  EXPECT_DOUBLE_EQ(s.materials[1].reflect, 0.9);
  EXPECT_DOUBLE_EQ(s.materials[2].transmit, 0.9);
  EXPECT_DOUBLE_EQ(s.materials[2].ior, 1.5);
  EXPECT_DOUBLE_EQ(s.materials[3].opacity, 0.5);
  EXPECT_EQ(s.render.method, Method::abuffer);
  EXPECT_EQ(s.render.cube_resolution, 512);
  EXPECT_EQ(s.render.max_depth, 4);

  ASSERT_EQ(s.objects.size(), 5u);
  const uint32_t expected_triangles[5] = {1, 2, 12, 2 * 64 * 31, 12};
  const bool expected_closed[5] = {false, false, true, true, true};
  uint32_t first = 0;
  for (size_t i = 0; i < 5; ++i) {
    const SceneObject& o = s.objects[i];
    EXPECT_EQ(o.path, "objects[" + std::to_string(i) + "]");
    EXPECT_EQ(o.first_triangle, first);
    EXPECT_EQ(o.triangle_count, expected_triangles[i]) << o.type;
    EXPECT_EQ(o.closed, expected_closed[i]) << o.type;
    for (uint32_t t = o.first_triangle; t < o.first_triangle + o.triangle_count; ++t) {
      EXPECT_EQ(s.triangles->object_id[t], i);
      EXPECT_EQ(s.triangles->material_id[t], o.material);
    }
    first += o.triangle_count;
  }
  EXPECT_EQ(s.triangles->triangle_count(), first);
  EXPECT_EQ(s.triangles->positions.size(), 3 * first);
  EXPECT_EQ(s.triangles->normals.size(), 3 * first);
  EXPECT_EQ(s.dropped_triangles, 0u);
  EXPECT_EQ(s.objects[2].material, 1u);  // the box is the mirror
  // The knot stand-in: a unit cube scaled by 0.5 has volume 1/8, wherever it is turned.
  EXPECT_NEAR(object_volume(s, s.objects[4]), 0.125, 1e-6);
}

// ---- Syntax errors: FILE:LINE:COL ------------------------------------------------------

TEST(SceneLoadErrors, SyntaxErrorsGiveLineAndColumn) {
  // Line 3, `  "camera": {,`: the comma is column 14.
  const std::string text = "{\n  \"version\": 1,\n  \"camera\": {,\n}";
  const std::string m = load_error(text);
  EXPECT_EQ(m.rfind("scene.json:3:14: ", 0), 0u) << m;
  // Columns count characters, not bytes: "é" is two bytes, one column.
  const std::string m2 = load_error("{\n\"é\": 1 2}");
  EXPECT_EQ(m2.rfind("scene.json:2:8: ", 0), 0u) << m2;
  // Trailing comma, and a file cut short.
  EXPECT_EQ(load_error("{\"a\": [1, 2,]}").rfind("scene.json:1:13: ", 0), 0u);
  EXPECT_EQ(load_error("{\"version\": 1").rfind("scene.json:1:14: ", 0), 0u);
  EXPECT_EQ(load_error("").rfind("scene.json:1:1: ", 0), 0u);
  // A misplaced string is pointed at where it starts.
  EXPECT_EQ(load_error("{\n  \"version\": 1\n  \"camera\": {}\n}").rfind("scene.json:3:3: ", 0), 0u);
}

TEST(SceneLoadErrors, InfiniteNumbersAreRejectedWithTheirPlace) {
  SceneText s;
  s.camera = "{\"position\": [0, 1, 5], \"look_at\": [0, 0, 0], \"fov_y\": 1e999}";
  const std::string m = load_error(s.str());
  EXPECT_EQ(m.rfind("scene.json:3:66: ", 0), 0u) << m;  // where 1e999 starts on the camera line
  EXPECT_NE(m.find("1e999"), std::string::npos) << m;
  // Finite in double but not in the float the renderer stores.
  EXPECT_ERROR(with_objects(R"([{"type": "triangle", "vertices": [[0,0,0],[1,0,0],[0,1,1e300]]}])").str(),
               "scene.json: objects[0].vertices[2][2]: out of range");
  EXPECT_ERROR(with_objects(R"([{"type": "sphere", "center": [0,0,0], "radius": -1e39}])").str(),
               "objects[0].radius: out of range");
}

// Nesting is refused past MAX_JSON_DEPTH before any value is built: 100,000 levels (which
// crashed nlohmann's recursive serializer) are a located one-line error like any other.
TEST(SceneLoadErrors, DeepNestingIsRefusedWithItsPlace) {
  using detail::MAX_JSON_DEPTH;
  const std::string deep = "\n " + std::string(100000, '[') + std::string(100000, ']');
  std::string m = load_error(deep);
  EXPECT_EQ(m, "scene.json:2:" + std::to_string(2 + MAX_JSON_DEPTH) + ": arrays and objects nested deeper than " +
                   std::to_string(MAX_JSON_DEPTH) + " levels");
  EXPECT_EQ(load_error(std::string(100000, '[')).rfind("scene.json:1:65: arrays and objects nested deeper", 0), 0u);
  std::string objects;
  for (int i = 0; i < 100000; ++i) objects += "{\"a\": ";
  EXPECT_EQ(load_error(objects + "1" + std::string(100000, '}')).rfind("scene.json:1:", 0), 0u);
  // MAX_JSON_DEPTH levels are read (and refused for what they hold, not for their depth).
  m = load_error(std::string(MAX_JSON_DEPTH, '[') + std::string(MAX_JSON_DEPTH, ']'));
  EXPECT_EQ(m.rfind("scene.json: must be an object, got [[[[", 0), 0u) << m;
  // Brackets inside strings, escaped quotes included, are not nesting.
  SceneText s;
  s.extra = ",\n\"\\\"" + std::string(1000, '[') + "\": 1";
  m = load_error(s.str());
  EXPECT_NE(m.find("unknown field"), std::string::npos) << m;
}

// ---- Value errors: FILE: path: ... ------------------------------------------------------

TEST(SceneLoadErrors, UnknownFieldsAnywhere) {
  SceneText s;
  s.extra = ",\n\"colour\": [1, 1, 1]";
  EXPECT_ERROR(s.str(), "scene.json: colour: unknown field");
  s = SceneText();
  s.camera = R"({"position": [0, 1, 5], "look_at": [0, 0, 0], "fov": 60})";
  EXPECT_ERROR(s.str(), "scene.json: camera.fov: unknown field");
  s = SceneText();
  s.materials = R"({"m": {"reflection": 0.5}})";
  EXPECT_ERROR(s.str(), "scene.json: materials.m.reflection: unknown field");
  s = SceneText();
  s.lights = R"([{"type": "point", "position": [0, 1, 0], "intensity": 2}])";
  EXPECT_ERROR(s.str(), "scene.json: lights[0].intensity: unknown field");
  s = SceneText();
  s.render = R"({"samples": 4})";
  EXPECT_ERROR(s.str(), "scene.json: render.samples: unknown field");
  EXPECT_ERROR(with_objects(R"([{"type": "box", "min": [0,0,0], "max": [1,1,1]},
                                {"type": "sphere", "center": [0,0,0], "radus": 1}])")
                   .str(),
               "scene.json: objects[1].radus: unknown field");
  // A field of another object type is unknown here too.
  EXPECT_ERROR(with_objects(R"([{"type": "box", "min": [0,0,0], "max": [1,1,1], "radius": 1}])").str(),
               "objects[0].radius: unknown field");
  EXPECT_ERROR(
      with_objects(R"([{"type": "box", "min": [0,0,0], "max": [1,1,1], "transform": {"rotate": [0,1,0]}}])").str(),
      "objects[0].transform.rotate: unknown field");
  EXPECT_ERROR(with_objects(R"([{"type": "cone"}])").str(), "objects[0].type: must be one of");
}

TEST(SceneLoadErrors, RepeatedFieldsAreNotSilentlyReplaced) {
  SceneText s;
  s.camera = R"({"position": [0, 1, 5], "look_at": [0, 0, 0], "fov_y": 60, "fov_y": 30})";
  EXPECT_ERROR(s.str(), "scene.json: camera.fov_y: field appears twice");
  EXPECT_ERROR(with_objects(R"([{"type": "box", "min": [0,0,0], "max": [1,1,1]},
                                {"type": "sphere", "center": [0,0,0], "radius": 1, "radius": 2}])")
                   .str(),
               "scene.json: objects[1].radius: field appears twice");
}

TEST(SceneLoadErrors, DegenerateCamera) {
  SceneText s;
  s.camera = R"({"position": [0, 5, 0], "look_at": [0, 0, 0], "up": [0, 1, 0]})";
  EXPECT_ERROR(s.str(), "scene.json: camera.up: must not be parallel to the view direction");
  s.camera = R"({"position": [0, 5, 0], "look_at": [0, 0, 0], "up": [0, 0, 0]})";
  EXPECT_ERROR(s.str(), "camera.up: must be nonzero");
  s.camera = R"({"position": [1, 2, 3], "look_at": [1, 2, 3]})";
  EXPECT_ERROR(s.str(), "scene.json: camera.look_at: must differ from camera.position");
  s.camera = R"({"position": [0, 1, 5], "look_at": [0, 0, 0], "fov_y": 0})";
  EXPECT_ERROR(s.str(), "scene.json: camera.fov_y: must be > 0 and < 180 (degrees), got 0");
  s.camera = R"({"position": [0, 1, 5], "look_at": [0, 0, 0], "fov_y": 180})";
  EXPECT_ERROR(s.str(), "camera.fov_y: must be > 0 and < 180 (degrees), got 180");
  s.camera = R"({"position": [0, 1, 5], "look_at": [0, 0, 0], "width": 0})";
  EXPECT_ERROR(s.str(), "scene.json: camera.width: must be >= 1, got 0");
  s.camera = R"({"position": [0, 1, 5], "look_at": [0, 0, 0], "height": 2.5})";
  EXPECT_ERROR(s.str(), "camera.height: must be an integer, got 2.5");
  s.camera = R"({"position": [0, 1, 5], "look_at": [0, 0, 0], "width": 40000})";
  EXPECT_ERROR(s.str(), "camera.width: must be <= 32768, got 40000");
  s.camera = R"({"look_at": [0, 0, 0]})";
  EXPECT_ERROR(s.str(), "scene.json: camera.position: missing required field");
}

TEST(SceneLoadErrors, MissingMeshFileNamesFieldAndResolvedPath) {
  TempDir dir;
  const std::string m =
      load_error(with_objects(R"([{"type": "mesh", "file": "meshes/missing.obj"}])").str(), dir.path().string());
  EXPECT_NE(m.find("scene.json: objects[0].file: "), std::string::npos) << m;
  EXPECT_NE(m.find((dir.path() / "meshes/missing.obj").string()), std::string::npos) << m;
  EXPECT_NE(m.find("no such file"), std::string::npos) << m;
  dir.write("meshes/folder.obj/x", "");
  const std::string d =
      load_error(with_objects(R"([{"type": "mesh", "file": "meshes/folder.obj"}])").str(), dir.path().string());
  EXPECT_NE(d.find("objects[0].file: cannot read mesh"), std::string::npos) << d;
  EXPECT_NE(d.find("is a directory"), std::string::npos) << d;
  EXPECT_ERROR(with_objects(R"([{"type": "mesh", "file": ""}])").str(), "objects[0].file: must name an OBJ file");
}

TEST(SceneLoadErrors, UnknownMaterialNamesTheObject) {
  EXPECT_ERROR(with_objects(R"([{"type": "box", "min": [0,0,0], "max": [1,1,1], "material": "white"},
                                {"type": "box", "min": [0,0,0], "max": [1,1,1], "material": "nope"}])")
                   .str(),
               "scene.json: objects[1].material: no material of that name");
}

TEST(SceneLoadErrors, MaterialWeightsAndIor) {
  SceneText s;
  s.materials = R"({"m": {"reflect": 1.5}})";
  EXPECT_ERROR(s.str(), "scene.json: materials.m.reflect: must be in [0, 1], got 1.5");
  s.materials = R"({"m": {"opacity": -0.25}})";
  EXPECT_ERROR(s.str(), "materials.m.opacity: must be in [0, 1], got -0.25");
  s.materials = R"({"m": {"transmit": 2}})";
  EXPECT_ERROR(s.str(), "materials.m.transmit: must be in [0, 1], got 2");
  s.materials = R"({"m": {"ior": 0.9}})";
  EXPECT_ERROR(s.str(), "scene.json: materials.m.ior: must be >= 1, got 0.9");
  s.materials = R"({"m": {"shininess": -1}})";
  EXPECT_ERROR(s.str(), "materials.m.shininess: must be >= 0, got -1");
  s.materials = R"({"m": {"color": [0.5, -0.1, 0.5]}})";
  EXPECT_ERROR(s.str(), "materials.m.color[1]: must be >= 0, got -0.1");
  s.materials = R"({"my glass": {"ior": 0.5}})";
  EXPECT_ERROR(s.str(), "materials[\"my glass\"].ior: must be >= 1");
}

TEST(SceneLoadErrors, WrongTypes) {
  EXPECT_ERROR(with_objects(R"([{"type": "sphere", "center": [0,0,0], "radius": "1"}])").str(),
               "scene.json: objects[0].radius: must be a number, got \"1\"");
  EXPECT_ERROR(with_objects(R"([{"type": "triangle", "vertices": [[0,0,0],[1,0,0]]}])").str(),
               "objects[0].vertices: must be an array of 3 points");
  EXPECT_ERROR(with_objects(R"([{"type": "box", "min": [0,0], "max": [1,1,1]}])").str(),
               "objects[0].min: must be an array of 3 numbers, got [0,0]");
  EXPECT_ERROR(with_objects(R"({"type": "box"})").str(), "scene.json: objects: must be an array");
  EXPECT_ERROR(with_objects(R"([42])").str(), "scene.json: objects[0]: must be an object, got 42");
  SceneText s;
  s.lights = R"([{"type": "point", "position": [0, 1, 0], "cast_shadows": 1}])";
  EXPECT_ERROR(s.str(), "lights[0].cast_shadows: must be true or false, got 1");
  s = SceneText();
  s.materials = R"([{"color": [1, 1, 1]}])";
  EXPECT_ERROR(s.str(), "scene.json: materials: must be an object");
  s = SceneText();
  s.render = R"({"method": 3})";
  EXPECT_ERROR(s.str(), "render.method: must be a string, got 3");
  EXPECT_ERROR("[1, 2]", "scene.json: must be an object");
}

TEST(SceneLoadErrors, Version) {
  SceneText s;
  s.version = "2";
  EXPECT_ERROR(s.str(), "scene.json: version: must be 1");
  s.version = "\"1\"";
  EXPECT_ERROR(s.str(), "scene.json: version: must be 1");
  EXPECT_ERROR(R"({"camera": {"position": [0,1,5], "look_at": [0,0,0]}, "objects": []})",
               "scene.json: version: missing required field");
}

TEST(SceneLoadErrors, QuadMustBeCoplanarAndSimple) {
  EXPECT_ERROR(with_objects(R"([{"type": "quad", "vertices": [[0,0,0],[1,0,0],[1,1,0],[0,1,0.1]]}])").str(),
               "scene.json: objects[0].vertices: the 4 vertices must be coplanar");
  EXPECT_ERROR(with_objects(R"([{"type": "quad", "vertices": [[0,0,0],[1,1,0],[1,0,0],[0,1,0]]}])").str(),
               "objects[0].vertices: the quad crosses itself");
  // Within the relative tolerance: a large quad with a tiny wobble is fine.
  EXPECT_NO_THROW(load_text(
      with_objects(R"([{"type": "quad", "vertices": [[0,0,0],[1000,0,0],[1000,1000,0],[0,1000,1e-7]]}])").str()));
}

TEST(SceneLoadErrors, BoxMinBelowMax) {
  EXPECT_ERROR(with_objects(R"([{"type": "box", "min": [0,1,0], "max": [1,1,1]}])").str(),
               "scene.json: objects[0].max[1]: must be > min[1] = 1, got 1");
  EXPECT_ERROR(with_objects(R"([{"type": "box", "min": [0,0,5], "max": [1,1,1]}])").str(), "objects[0].max[2]");
}

TEST(SceneLoadErrors, SphereRadiusAndSegments) {
  // The very message scene-format.md gives as its example.
  const std::string objects = R"([{"type": "box", "min": [0,0,0], "max": [1,1,1]},
      {"type": "box", "min": [0,0,0], "max": [1,1,1]}, {"type": "box", "min": [0,0,0], "max": [1,1,1]},
      {"type": "sphere", "center": [0,0,0], "radius": -1}])";
  EXPECT_EQ(load_error(with_objects(objects).str()), "scene.json: objects[3].radius: must be > 0, got -1");
  EXPECT_ERROR(with_objects(R"([{"type": "sphere", "center": [0,0,0], "radius": 0}])").str(),
               "objects[0].radius: must be > 0, got 0");
  EXPECT_ERROR(with_objects(R"([{"type": "sphere", "center": [0,0,0], "radius": 1, "segments": 2}])").str(),
               "objects[0].segments: must be >= 3, got 2");
  EXPECT_ERROR(with_objects(R"([{"type": "sphere", "center": [0,0,0], "radius": 1, "segments": 5000}])").str(),
               "objects[0].segments: must be <= 4096, got 5000");
}

TEST(SceneLoadErrors, TransformScaleNonzero) {
  EXPECT_ERROR(with_objects(R"([{"type": "box", "min": [0,0,0], "max": [1,1,1], "transform": {"scale": 0}}])").str(),
               "objects[0].transform.scale: must be nonzero, got 0");
  EXPECT_ERROR(
      with_objects(R"([{"type": "box", "min": [0,0,0], "max": [1,1,1], "transform": {"scale": [1,0,1]}}])").str(),
      "objects[0].transform.scale[1]: must be nonzero");
}

TEST(SceneLoadErrors, LightsAndRender) {
  SceneText s;
  s.lights = R"([{"type": "spot", "position": [0, 1, 0]}])";
  EXPECT_ERROR(s.str(), "scene.json: lights[0].type: must be \"point\", got \"spot\"");
  s.lights = R"([{"type": "point", "position": [0, 1, 0], "color": [1, -1, 1]}])";
  EXPECT_ERROR(s.str(), "lights[0].color[1]: must be >= 0, got -1");
  s = SceneText();
  s.render = R"({"method": "photon"})";
  EXPECT_ERROR(
      s.str(),
      "scene.json: render.method: must be one of abuffer, zbuffer, envmap, raytrace, gpu, hybrid, got \"photon\"");
  s.render = R"({"cube_resolution": 0})";
  EXPECT_ERROR(s.str(), "render.cube_resolution: must be >= 1, got 0");
  s.render = R"({"cube_resolution": 20000})";
  EXPECT_ERROR(s.str(), "render.cube_resolution: must be <= 16384, got 20000");
  s.render = R"({"max_depth": -1})";
  EXPECT_ERROR(s.str(), "render.max_depth: must be >= 0, got -1");
}

TEST(SceneLoadErrors, MissingSceneFileNamesIt) {
  try {
    load_scene("/nonexistent/dir/scene.json");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("/nonexistent/dir/scene.json: cannot read scene", 0), 0u) << e.what();
  }
}

// ---- Input files: regular files under their caps (issue 16) ----------------------------

TEST(SceneLoadFiles, SceneThatIsNoRegularFileIsRefusedUnread) {
  TempDir dir;
  const std::string fifo = (dir.path() / "pipe.json").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::pair<std::string, std::string> cases[] = {
      {"/dev/zero", "/dev/zero: cannot read scene: not a regular file (a character device)"},
      {fifo, fifo + ": cannot read scene: not a regular file (a named pipe)"},  // opening it would block
      {dir.path().string(), dir.path().string() + ": cannot read scene: is a directory"},
      {(dir.path() / "none.json").string(), (dir.path() / "none.json").string() + ": cannot read scene: no such file"},
  };
  for (const auto& [path, expected] : cases) {
    EXPECT_EQ(input_error([&] { load_scene(path); }, path), expected);
  }
}

TEST(SceneLoadFiles, SizeCapsOfScenesAndMeshes) {
  EXPECT_EQ(LoadLimits{}.max_scene_bytes, uint64_t{64} << 20);
  EXPECT_EQ(LoadLimits{}.max_mesh_bytes, uint64_t{8} << 30);
  TempDir dir;
  dir.write("cube.obj", CUBE_OBJ);
  const std::string scene =
      dir.write("scene.json", with_objects(R"([{"type": "mesh", "file": "cube.obj", "material": "white"}])").str());
  const uint64_t scene_bytes = fs::file_size(scene), mesh_bytes = fs::file_size(dir.path() / "cube.obj");
  LoadLimits limits;
  limits.max_scene_bytes = scene_bytes;  // at the cap: read
  limits.max_mesh_bytes = mesh_bytes;
  EXPECT_EQ(load_scene(scene, limits).triangles->triangle_count(), 12u);
  limits.max_scene_bytes = scene_bytes - 1;
  EXPECT_EQ(input_error([&] { load_scene(scene, limits); }, scene),
            scene + ": cannot read scene: is " + format_bytes(scene_bytes) + ", over the cap of " +
                format_bytes(scene_bytes - 1));
  limits.max_scene_bytes = scene_bytes;
  limits.max_mesh_bytes = 100;
  EXPECT_EQ(input_error([&] { load_scene(scene, limits); }, scene),
            scene + ": objects[0].file: cannot read mesh \"" + (dir.path() / "cube.obj").string() + "\": is " +
                format_bytes(mesh_bytes) + ", over the cap of 100 bytes");
  EXPECT_EQ(format_bytes(uint64_t{9} << 30), "9 GiB");
  EXPECT_EQ(format_bytes((uint64_t{3} << 20) / 2), "1.5 MiB");
}

TEST(SceneLoadFiles, MeshAndMtlThatAreNoRegularFilesAreRefusedUnread) {
  TempDir dir;
  fs::create_symlink("/dev/zero", dir.path() / "zero.mtl");
  dir.write("zero_mtl.obj", "mtllib zero.mtl\n" + std::string(CUBE_OBJ));
  std::string m = load_error(with_objects(R"([{"type": "mesh", "file": "/dev/zero"}])").str(), dir.path().string());
  EXPECT_EQ(m, "scene.json: objects[0].file: cannot read mesh \"/dev/zero\": not a regular file (a character device)");
  m = load_error(with_objects(R"([{"type": "mesh", "file": "."}])").str(), dir.path().string());
  EXPECT_NE(m.find("\": is a directory"), std::string::npos) << m;
  // The MTL file is refused even when its materials are not used.
  m = load_error(with_objects(R"([{"type": "mesh", "file": "zero_mtl.obj", "material": "white"}])").str(),
                 dir.path().string());
  EXPECT_NE(m.find("scene.json: objects[0].file: mtllib \"zero.mtl\" of mesh "), std::string::npos) << m;
  EXPECT_NE(m.find(": not a regular file (a character device)"), std::string::npos) << m;
}

// ---- Geometry --------------------------------------------------------------------------

TEST(SceneLoadGeometry, ZeroAreaTrianglesAreDroppedAndCounted) {
  const SceneData s = load_text(with_objects(R"([
      {"type": "triangle", "vertices": [[0,0,0],[1,1,1],[2,2,2]]},
      {"type": "triangle", "vertices": [[0,0,0],[0,0,0],[1,0,0]]},
      {"type": "quad", "vertices": [[0,0,0],[1,0,0],[2,0,0],[0,1,0]]},
      {"type": "triangle", "vertices": [[1e30,0,0],[0,1e30,0],[0,0,1e30]], "transform": {"scale": 1e30}},
      {"type": "triangle", "vertices": [[0,0,0],[1e-6,0,0],[0,1e-6,0]]},
      {"type": "triangle", "vertices": [[0,0,0],[1e6,0,0],[0,1e6,0]]}])")
                                    .str());
  ASSERT_EQ(s.objects.size(), 6u);
  EXPECT_EQ(s.dropped_triangles, 4u);  // collinear, repeated vertex, half the quad, overflow
  const uint32_t expected[6] = {0, 0, 1, 0, 1, 1};
  for (size_t i = 0; i < 6; ++i) EXPECT_EQ(s.objects[i].triangle_count, expected[i]) << i;
  EXPECT_EQ(s.triangles->triangle_count(), 3u);
  EXPECT_FALSE(s.objects[0].closed);
}

TEST(SceneLoadGeometry, BoxIsClosedWithOutwardFlatNormals) {
  const SceneData s = load_text(with_objects(R"([{"type": "box", "min": [-1,0,2], "max": [0,2,5]}])").str());
  const SceneObject& box = s.objects[0];
  EXPECT_EQ(box.triangle_count, 12u);
  EXPECT_TRUE(box.closed);
  EXPECT_TRUE(edges_shared_twice(s, box));
  EXPECT_NEAR(object_volume(s, box), 1.0 * 2.0 * 3.0, 1e-9);
  const glm::dvec3 center(-0.5, 1, 3.5);
  for (size_t t = 0; t < 12; ++t) {
    const glm::dvec3 n = geometric_normal(s, t);
    const glm::dvec3 mid = (corner(s, t, 0) + corner(s, t, 1) + corner(s, t, 2)) / 3.0;
    EXPECT_GT(glm::dot(n, mid - center), 0.0) << t;                             // outward
    EXPECT_NEAR(std::fabs(n.x) + std::fabs(n.y) + std::fabs(n.z), 1.0, 1e-12);  // axis-aligned
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(glm::length(glm::dvec3(s.triangles->normals[3 * t + static_cast<size_t>(k)]) - n), 0.0, 1e-6);
    }
  }
}

TEST(SceneLoadGeometry, SphereIsClosedWithOutwardSmoothNormals) {
  for (int segments : {3, 7, 32, 65}) {
    const std::string objects =
        R"([{"type": "sphere", "center": [1,2,3], "radius": 2, "segments": )" + std::to_string(segments) + "}]";
    const SceneData s = load_text(with_objects(objects).str());
    const SceneObject& o = s.objects[0];
    const int rings = std::max(2, segments / 2);
    EXPECT_EQ(o.triangle_count, static_cast<uint32_t>(2 * segments * (rings - 1))) << segments;
    EXPECT_TRUE(o.closed) << segments;
    EXPECT_TRUE(edges_shared_twice(s, o)) << segments;
    const double v = object_volume(s, o), ball = 4.0 / 3.0 * M_PI * 8.0;
    EXPECT_GT(v, 0.0);
    EXPECT_LT(v, ball);  // inscribed polyhedron
    if (segments >= 32) EXPECT_GT(v, 0.97 * ball) << segments;
    const glm::dvec3 c(1, 2, 3);
    for (size_t t = 0; t < o.triangle_count; ++t) {
      const glm::dvec3 g = geometric_normal(s, t);
      for (int k = 0; k < 3; ++k) {
        const glm::dvec3 p = corner(s, t, k);
        const glm::dvec3 n(s.triangles->normals[3 * t + static_cast<size_t>(k)]);
        EXPECT_NEAR(glm::length(p - c), 2.0, 1e-5);
        EXPECT_NEAR(glm::length(n - glm::normalize(p - c)), 0.0, 1e-5);
        EXPECT_GT(glm::dot(n, g), 0.0);  // smooth and geometric normals agree on outside
      }
    }
  }
  // The default is 32 segments.
  EXPECT_EQ(load_text(SceneText().str()).objects[0].triangle_count, 2u * 32 * 15);
}

TEST(SceneLoadGeometry, TransformScalesThenRotatesXYZThenTranslates) {
  // (1,2,3) scaled by (2,3,4) is (2,6,12); 90 degrees about x: (2,-12,6); about y: (6,-12,-2);
  // about z: (12,6,-2); translated by (10,20,30): (22,26,28).
  const SceneData s = load_text(with_objects(R"([{"type": "triangle", "vertices": [[1,2,3],[2,2,3],[1,3,3]],
      "transform": {"scale": [2,3,4], "rotate_deg": [90,90,90], "translate": [10,20,30]}}])")
                                    .str());
  ASSERT_EQ(s.triangles->triangle_count(), 1u);
  const glm::dvec3 p = corner(s, 0, 0);
  EXPECT_NEAR(p.x, 22, 1e-5);
  EXPECT_NEAR(p.y, 26, 1e-5);
  EXPECT_NEAR(p.z, 28, 1e-5);
  // The triangle's normal +z goes through the same rotations: z -> -y -> -y -> +x.
  const glm::dvec3 n(s.triangles->normals[0]);
  EXPECT_NEAR(glm::length(n - glm::dvec3(1, 0, 0)), 0.0, 1e-6);
  EXPECT_NEAR(glm::length(geometric_normal(s, 0) - glm::dvec3(1, 0, 0)), 0.0, 1e-6);
}

TEST(SceneLoadGeometry, MirroringTransformKeepsNormalsOutward) {
  const SceneData s = load_text(with_objects(R"([
      {"type": "box", "min": [0,0,0], "max": [1,2,3], "transform": {"scale": [-1,1,1]}},
      {"type": "triangle", "vertices": [[0,0,0],[1,0,0],[0,1,0]], "transform": {"scale": [1,1,-2]}},
      {"type": "sphere", "center": [0,0,0], "radius": 1, "transform": {"scale": [2,-1,1]}}])")
                                    .str());
  EXPECT_TRUE(s.objects[0].closed);
  EXPECT_NEAR(object_volume(s, s.objects[0]), 6.0, 1e-9);
  // The triangle faced +z; mirrored in z, the surface it becomes still faces the side its
  // normal maps to: the inverse transpose of diag(1,1,-2) takes +z to -z.
  EXPECT_NEAR(glm::length(geometric_normal(s, s.objects[1].first_triangle) - glm::dvec3(0, 0, -1)), 0.0, 1e-6);
  // Ellipsoid x/2, -y, z: normals by the inverse transpose, n ~ (p.x/4, p.y, p.z).
  const SceneObject& e = s.objects[2];
  EXPECT_TRUE(e.closed);
  EXPECT_GT(object_volume(s, e), 0.0);
  for (size_t t = e.first_triangle; t < e.first_triangle + e.triangle_count; ++t) {
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 p = corner(s, t, k);
      const glm::dvec3 n(s.triangles->normals[3 * t + static_cast<size_t>(k)]);
      EXPECT_NEAR(glm::length(n - glm::normalize(glm::dvec3(p.x / 4, p.y, p.z))), 0.0, 1e-5);
    }
  }
}

TEST(SceneLoadGeometry, QuarterTurnsKeepBoxesAxisAligned) {
  const SceneData s = load_text(with_objects(R"([{"type": "box", "min": [0,0,0], "max": [1,2,3],
      "transform": {"rotate_deg": [0,90,0]}}])")
                                    .str());
  const Bounds b = s.bounds();
  EXPECT_EQ(b.lo, glm::dvec3(0, 0, -1));
  EXPECT_EQ(b.hi, glm::dvec3(3, 2, 0));
}

// ---- Meshes ----------------------------------------------------------------------------

TEST(SceneLoadMesh, MtlMaterialsAreUsedWithoutObjectMaterial) {
  const std::string dir = std::string(ABCUBE_SOURCE_DIR) + "/scenes";
  const SceneData s = load_text(with_objects(R"([{"type": "mesh", "file": "meshes/octahedron.obj"}])").str(), dir);
  const SceneObject& o = s.objects[0];
  EXPECT_EQ(o.triangle_count, 8u);
  EXPECT_TRUE(o.closed);
  EXPECT_NEAR(object_volume(s, o), 4.0 / 3.0, 1e-6);  // octahedron with unit "radius"
  std::map<std::string, const Material*> by_name;
  for (const Material& m : s.materials) by_name[m.name] = &m;
  ASSERT_TRUE(by_name.count("meshes/octahedron.obj:red"));
  ASSERT_TRUE(by_name.count("meshes/octahedron.obj:blue"));
  const Material& red = *by_name["meshes/octahedron.obj:red"];
  EXPECT_NEAR(red.color.r, 0.8, 1e-6);
  EXPECT_NEAR(red.color.g, 0.1, 1e-6);
  EXPECT_NEAR(red.specular, 0.5, 1e-6);
  EXPECT_NEAR(red.shininess, 64, 1e-6);
  const Material& blue = *by_name["meshes/octahedron.obj:blue"];
  EXPECT_NEAR(blue.specular, 0.3, 1e-6);  // mean of Ks 0.2 0.3 0.4
  EXPECT_NEAR(blue.opacity, 0.5, 1e-6);
  EXPECT_NEAR(blue.ior, 1.33, 1e-6);
  // Upper faces red, lower faces blue.
  for (uint32_t t = o.first_triangle; t < o.first_triangle + o.triangle_count; ++t) {
    const glm::dvec3 mid = (corner(s, t, 0) + corner(s, t, 1) + corner(s, t, 2)) / 3.0;
    EXPECT_EQ(s.materials[s.triangles->material_id[t]].name,
              mid.y > 0 ? "meshes/octahedron.obj:red" : "meshes/octahedron.obj:blue");
  }
  // An object material overrides the MTL, which then adds no materials.
  const SceneData named =
      load_text(with_objects(R"([{"type": "mesh", "file": "meshes/octahedron.obj", "material": "m"}])").str(), dir);
  EXPECT_EQ(named.materials.size(), 2u);
  for (uint32_t id : named.triangles->material_id) EXPECT_EQ(named.materials[id].name, "m");
}

TEST(SceneLoadMesh, MeshWithoutMaterialsGetsTheDefault) {
  TempDir dir;
  dir.write("cube.obj", CUBE_OBJ);
  const SceneData s = load_text(with_objects(R"([{"type": "mesh", "file": "cube.obj"}])").str(), dir.path().string());
  const Material& m = s.materials[s.objects[0].material];
  EXPECT_EQ(m.name, "(default)");
  EXPECT_DOUBLE_EQ(m.color.r, 0.8);
  EXPECT_TRUE(s.objects[0].closed);
  EXPECT_NEAR(object_volume(s, s.objects[0]), 1.0, 1e-9);
}

TEST(SceneLoadMesh, ObjNormalsPolygonsAndWinding) {
  TempDir dir;
  // A square pyramid whose base is one quad and whose faces all wind inward, with
  // vertex normals: the loader keeps the normals and turns the closed mesh outward.
  dir.write("pyramid.obj", R"(v 0 0 0
v 1 0 0
v 1 0 1
v 0 0 1
v 0.5 1 0.5
vn 0 1 0
f 1//1 4//1 3//1 2//1
f 1//1 2//1 5//1
f 2//1 3//1 5//1
f 3//1 4//1 5//1
f 4//1 1//1 5//1
)");
  // An L-shaped hexagon (concave): ear clipping must cover exactly its area, 3 units.
  dir.write("ell.obj", "v 0 0 0\nv 2 0 0\nv 2 0 1\nv 1 0 1\nv 1 0 2\nv 0 0 2\nf 6 5 4 3 2 1\n");
  const SceneData s = load_text(with_objects(R"([{"type": "mesh", "file": "pyramid.obj"},
      {"type": "mesh", "file": "ell.obj", "transform": {"translate": [5, 0, 0]}}])")
                                    .str(),
                                dir.path().string());
  const SceneObject& pyramid = s.objects[0];
  EXPECT_EQ(pyramid.triangle_count, 6u);
  EXPECT_TRUE(pyramid.closed);
  EXPECT_NEAR(object_volume(s, pyramid), 1.0 / 3.0, 1e-6);  // flipped to outward
  // The vn (0,1,0) is kept where it lies on the outer side (the slopes) and turned with
  // the base, which now faces down.
  for (uint32_t t = pyramid.first_triangle; t < pyramid.first_triangle + pyramid.triangle_count; ++t) {
    const glm::dvec3 g = geometric_normal(s, t);
    for (int k = 0; k < 3; ++k) {
      const glm::vec3 n = s.triangles->normals[3 * t + static_cast<size_t>(k)];
      EXPECT_EQ(n, glm::vec3(0, g.y > 0 ? 1 : -1, 0)) << t;
    }
  }
  const SceneObject& ell = s.objects[1];
  EXPECT_EQ(ell.triangle_count, 4u);
  EXPECT_FALSE(ell.closed);
  double area = 0;
  for (uint32_t t = ell.first_triangle; t < ell.first_triangle + ell.triangle_count; ++t) {
    const glm::dvec3 g = glm::cross(corner(s, t, 1) - corner(s, t, 0), corner(s, t, 2) - corner(s, t, 0));
    EXPECT_GT(g.y, 0.0);  // every piece keeps the polygon's winding (6 5 4 ... faces +y)
    area += 0.5 * glm::length(g);
  }
  EXPECT_NEAR(area, 3.0, 1e-9);
}

// Forgiving OBJ (issue 15 part 3): a missing MTL file or material is one warning and the
// default material, as Assimp, Blender and three.js load it; no warning when the object
// names its own material (the MTL is not used).
TEST(SceneLoadMesh, MissingMtlOrMaterialIsAWarningAndTheDefault) {
  TempDir dir;
  dir.write("lost.obj", "mtllib lost.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl paint\nf 1 2 3\n");
  dir.write("m.mtl", "newmtl red\nKd 1 0 0\n");
  dir.write("some.obj",
            "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nusemtl red\nf 1 2 3\n"
            "usemtl blue\nf 2 4 3\nusemtl green\nf 2 4 3\nusemtl blue\nf 2 4 3\n");
  const SceneData s = load_text(with_objects(R"([{"type": "mesh", "file": "lost.obj"},
      {"type": "mesh", "file": "some.obj"}])")
                                    .str(),
                                dir.path().string());
  ASSERT_EQ(s.warnings.size(), 2u);
  EXPECT_EQ(s.warnings[0],
            "scene.json: objects[0].file: warning: mesh \"lost.obj\": mtllib: material file \"lost.mtl\" "
            "not found (and 1 more); the default material is used")
      << s.warnings[0];
  EXPECT_EQ(s.warnings[1],
            "scene.json: objects[1].file: warning: mesh \"some.obj\": usemtl: material \"blue\" "
            "not found (and 1 more); the default material is used")
      << s.warnings[1];
  ASSERT_EQ(s.triangles->triangle_count(), 5u);
  for (size_t t = 0; t < 5; ++t) {
    const Material& m = s.materials[s.triangles->material_id[t]];
    EXPECT_EQ(m.name, t == 1 ? "some.obj:red" : "(default)") << t;
  }
  const SceneData own = load_text(with_objects(R"([{"type": "mesh", "file": "lost.obj", "material": "white"}])").str(),
                                  dir.path().string());
  EXPECT_TRUE(own.warnings.empty());
}

TEST(SceneLoadMesh, BadObjIndicesAreErrors) {
  TempDir dir;
  dir.write("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n");
  const std::string m = load_error(with_objects(R"([{"type": "mesh", "file": "bad.obj", "material": "white"}])").str(),
                                   dir.path().string());
  EXPECT_NE(m.find("scene.json: objects[0].file: "), std::string::npos) << m;
}

// ---- Input text in messages: cut short and escaped (issue 16) ---------------------------

// True when `m` holds no control byte (a terminal would act on ESC, BEL, CSI, ...).
bool no_control_bytes(const std::string& m) {
  return std::none_of(m.begin(), m.end(), [](char c) {
    const unsigned char u = static_cast<unsigned char>(c);
    return u < 0x20 || u == 0x7F;
  });
}

// A missing material's name reaches the warning escaped, and cut when long.
std::string only_warning(const std::string& obj_text) {
  TempDir dir;
  dir.write("m.obj", obj_text);
  const SceneData s = load_text(with_objects(R"([{"type": "mesh", "file": "m.obj"}])").str(), dir.path().string());
  return s.warnings.size() == 1 ? s.warnings[0] : "(" + std::to_string(s.warnings.size()) + " warnings)";
}

TEST(SceneLoadMessages, UsemtlNameWithEscapesIsEscaped) {
  const std::string m = only_warning("v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl \x1b]0;pwned\x07\x1b[31mred\nf 1 2 3\n");
  EXPECT_TRUE(no_control_bytes(m)) << m;
  EXPECT_NE(m.find("scene.json: objects[0].file: warning: mesh "), std::string::npos) << m;
  EXPECT_NE(m.find("usemtl: material \"\\e]0;pwned\\x07\\e[31mred\" not found"), std::string::npos) << m;
}

TEST(SceneLoadMessages, LongUsemtlNameIsCut) {
  const std::string m = only_warning("v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl " + std::string(200000, 'm') + "\nf 1 2 3\n");
  EXPECT_LT(m.size(), 300u) << m.substr(0, 300);
  EXPECT_NE(m.find("\"... (200000 bytes) not found"), std::string::npos) << m.substr(0, 300);
}

TEST(SceneLoadMessages, MtlMaterialNameAndMeshPathAreEscaped) {
  TempDir dir;
  dir.write("m.mtl", "newmtl \x1b[2Jpaint\nKd -1 0 0\n");
  dir.write("m\x1b[1m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl \x1b[2Jpaint\nf 1 2 3\n");
  const std::string m =
      load_error(with_objects(R"([{"type": "mesh", "file": "m\u001b[1m.obj"}])").str(), dir.path().string());
  EXPECT_TRUE(no_control_bytes(m)) << m;
  EXPECT_NE(m.find("m\\e[1m.obj\": material \"\\e[2Jpaint\": Kd must be finite and >= 0"), std::string::npos) << m;
}

TEST(SceneLoadMessages, HugeKeysAndValuesAreCut) {
  const std::string big(5 << 20, 'k');
  SceneText s;
  s.extra = ",\n\"" + big + "\": 1";
  std::string m = load_error(s.str());
  EXPECT_EQ(m, "scene.json: [\"" + std::string(QUOTE_MAX_CHARS, 'k') +
                   "\"... (5242880 bytes)]: unknown field "
                   "(known here: version, camera, background, ambient, lights, materials, objects, render)");
  // A value of megabytes after "got".
  m = load_error(with_objects(R"([{"type": ")" + big + R"("}])").str());
  EXPECT_LT(m.size(), 300u) << m.substr(0, 300);
  EXPECT_NE(m.find("objects[0].type: must be one of"), std::string::npos) << m;
  m = load_error(with_objects(R"([{"type": "sphere", "center": [)" + std::string(1 << 20, '1') + R"(, 0]}])").str());
  EXPECT_LT(m.size(), 300u) << m.substr(0, 300);
  // A string left open: nlohmann's "last read" token is the whole rest of the file.
  m = load_error("{\"version\": 1, \"x\": \"" + big);
  EXPECT_LT(m.size(), 300u) << m.substr(0, 300);
  EXPECT_EQ(m.rfind("scene.json:1:", 0), 0u) << m.substr(0, 300);
  EXPECT_NE(m.find("(5242881 bytes)"), std::string::npos) << m.substr(0, 300);
}

// An OBJ without triangles loads (it is an object with nothing to draw) with one warning
// naming the object's file field; so does one whose faces all have zero area.
TEST(SceneLoadMesh, MeshWithoutTrianglesLoadsWithAWarning) {
  TempDir dir;
  dir.write("empty.obj", "");
  dir.write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\n");
  dir.write("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 3 2 1\n");
  dir.write("cube.obj", CUBE_OBJ);
  const SceneData s = load_text(with_objects(R"([{"type": "mesh", "file": "cube.obj"},
      {"type": "mesh", "file": "empty.obj", "material": "white"}, {"type": "mesh", "file": "points.obj"},
      {"type": "mesh", "file": "flat.obj"}])")
                                    .str(),
                                dir.path().string());
  ASSERT_EQ(s.objects.size(), 4u);
  EXPECT_EQ(s.objects[1].triangle_count, 0u);
  EXPECT_EQ(s.triangles->triangle_count(), 12u);
  const std::vector<std::string> expected = {
      "scene.json: objects[1].file: warning: mesh \"empty.obj\" has no triangles",
      "scene.json: objects[2].file: warning: mesh \"points.obj\" has no triangles",
      "scene.json: objects[3].file: warning: mesh \"flat.obj\" has no triangles of nonzero area (2 dropped)"};
  EXPECT_EQ(s.warnings, expected);
  EXPECT_TRUE(load_text(SceneText().str()).warnings.empty());
}

// So does a primitive whose triangles all have zero area (found by tests/fuzz: it loaded
// with nothing to draw and no word).
TEST(SceneLoadMesh, FlatPrimitiveLoadsWithAWarning) {
  const SceneData s = load_text(with_objects(R"([{"type": "sphere", "center": [0, 0, 0], "radius": 1},
      {"type": "quad", "vertices": [[0, 0, 0], [1, 0, 0], [1, 0, 0], [0, 0, 0]]}])")
                                    .str());
  ASSERT_EQ(s.objects.size(), 2u);
  EXPECT_EQ(s.objects[1].triangle_count, 0u);
  const std::vector<std::string> expected = {
      "scene.json: objects[1]: warning: quad has no triangles of nonzero area (2 dropped)"};
  EXPECT_EQ(s.warnings, expected);
}

// ---- Tessellation helpers --------------------------------------------------------------

TEST(Tessellate, ClosedSurfaceNeedsConsistentOrientation) {
  SceneData s = load_text(with_objects(R"([{"type": "box", "min": [0,0,0], "max": [1,1,1]}])").str());
  EXPECT_TRUE(is_closed_surface(*s.triangles, 0, 12));
  EXPECT_FALSE(is_closed_surface(*s.triangles, 0, 11));                         // a hole
  std::swap(s.triangles.edit().positions[1], s.triangles.edit().positions[2]);  // one face turned over
  EXPECT_FALSE(is_closed_surface(*s.triangles, 0, 12));
}

// ---- Memory estimate -------------------------------------------------------------------

TEST(SceneLoadMemory, EstimateAndBudget) {
  SceneText text;
  text.render = R"({"cube_resolution": 100})";
  const SceneData s = load_text(text.str());
  const uint64_t bytes = estimate_render_bytes(s);
  // 64x48 pixels, 6 faces of 100x100 texels, 960 triangles at no less than the peak
  // bytes a triangle measured by bench/memory.py (168, bench/results/memory.txt).
  EXPECT_GT(bytes, 64u * 48 * 12 + 6u * 100 * 100 * 4 + 960u * 168);
  EXPECT_LT(bytes, uint64_t{64} << 20);
  EXPECT_NO_THROW(check_render_size(s, bytes, true));
  for (const bool capped : {true, false}) {
    try {
      check_render_size(s, bytes - 1, capped);
      FAIL() << "no error";
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind("scene.json: render: estimated ", 0), 0u) << m;
      EXPECT_NE(m.find("for 64x48, cube 100 and 960 triangles"), std::string::npos) << m;
      EXPECT_NE(m.find(capped ? "above --max-memory " : "of memory available"), std::string::npos) << m;
    }
  }
  // The gpu method counts the GL's copy of the soup too, at its largest (positions and
  // normals 72 bytes a triangle, the soup's ids 8, each vertex's ids 24: a GL that neither
  // pins the soup nor reads ids per triangle) and what llvmpipe holds while drawing (about 90).
  SceneData gpu = s;
  gpu.render.method = Method::gpu;
  // and a cube shadow map of N x N floats per shadow-casting light (the scene has one),
  // and its shadow volumes (two at most, opaque and translucent blockers): a cap's code on
  // the CPU and in the GL and 8 bytes of runs a triangle each; the side pairing's bucket byte
  // a corner, and its edges of 32 bytes (3 a triangle, at most 2^20 of them).
  ASSERT_EQ(gpu.lights.size(), 1u);
  const uint64_t volume = 2 * (2 + 8);
  const uint64_t pairing = 960u * 3 * 32;
  EXPECT_EQ(estimate_render_bytes(gpu), bytes + 960u * (104 + 90 + volume + 3) + pairing + 6u * 100 * 100 * 4);
  gpu.lights.push_back(gpu.lights.front());
  EXPECT_EQ(estimate_render_bytes(gpu), bytes + 960u * (104 + 90 + 2 * volume + 3) + pairing + 2 * 6u * 100 * 100 * 4);
  gpu.lights.back().cast_shadows = false;
  EXPECT_EQ(estimate_render_bytes(gpu), bytes + 960u * (104 + 90 + volume + 3) + pairing + 6u * 100 * 100 * 4);
  gpu.lights.front().cast_shadows = false;  // no shadows: no volumes, no maps
  EXPECT_EQ(estimate_render_bytes(gpu), bytes + 960u * (104 + 90));
  // A huge cube map is refused by its estimate, not by an allocation failure.
  text.render = R"({"cube_resolution": 16384})";
  EXPECT_GT(estimate_render_bytes(load_text(text.str())), uint64_t{6} * 16384 * 16384 * 32);
}

// ---- The repository's scenes -----------------------------------------------------------

TEST(RepositoryScenes, AllLoad) {
  const fs::path root = fs::path(ABCUBE_SOURCE_DIR) / "scenes";
  int count = 0;
  for (const fs::path& dir : {root, root / "bench"}) {
    for (const auto& entry : fs::directory_iterator(dir)) {
      if (entry.path().extension() != ".json") continue;
      SCOPED_TRACE(entry.path().string());
      SceneData s;
      EXPECT_NO_THROW(s = load_scene(entry.path().string()));
      EXPECT_GT(s.triangles->triangle_count(), 0u);
      EXPECT_FALSE(s.lights.empty());
      EXPECT_EQ(s.dropped_triangles, 0u);
      ++count;
    }
  }
  EXPECT_GE(count, 5);
  const SceneData bench = load_scene((root / "bench/spheres_terrain.json").string());
  EXPECT_GE(bench.triangles->triangle_count(), 100000u);
}

// Exact ray-triangle intersection (Moller-Trumbore 1997); returns the distance or -1.
double hit_triangle(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& a, const glm::dvec3& b,
                    const glm::dvec3& c) {
  const glm::dvec3 e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
  const double det = glm::dot(e1, p);
  if (std::fabs(det) < 1e-12) return -1;
  const glm::dvec3 s = o - a, q = glm::cross(s, e1);
  const double u = glm::dot(s, p) / det, v = glm::dot(d, q) / det;
  if (u < 0 || v < 0 || u + v > 1) return -1;
  const double t = glm::dot(e2, q) / det;
  return t > 1e-9 ? t : -1;
}

// hidden_point.json (thesis fig. 11.3) does what scenes/README.md says: some points of the
// green triangle are hidden from the camera by the red one, yet seen in the mirror.
TEST(RepositoryScenes, HiddenPointSeenOnlyInTheMirror) {
  const SceneData s = load_scene(std::string(ABCUBE_SOURCE_DIR) + "/scenes/hidden_point.json");
  ASSERT_EQ(s.objects.size(), 3u);  // mirror, red, green: one triangle each
  auto tri = [&](size_t i, int k) { return corner(s, i, k); };
  const glm::dvec3 eye = s.camera.position;
  int seen_in_mirror = 0, hidden_but_reflected = 0;
  const int n = 60;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; i + j <= n; ++j) {
      // A point on the mirror, and the camera ray reflected there.
      const glm::dvec3 m =
          tri(0, 0) + (tri(0, 1) - tri(0, 0)) * (i / double(n)) + (tri(0, 2) - tri(0, 0)) * (j / double(n));
      const glm::dvec3 d = glm::normalize(m - eye);
      const glm::dvec3 normal = geometric_normal(s, 0);
      const glm::dvec3 r = d - 2.0 * glm::dot(d, normal) * normal;
      const double to_red = hit_triangle(m, r, tri(1, 0), tri(1, 1), tri(1, 2));
      const double to_green = hit_triangle(m, r, tri(2, 0), tri(2, 1), tri(2, 2));
      if (to_green < 0 || (to_red > 0 && to_red < to_green)) continue;
      ++seen_in_mirror;
      const glm::dvec3 g = m + to_green * r;
      const double along = glm::length(g - eye);
      const double blocked = hit_triangle(eye, (g - eye) / along, tri(1, 0), tri(1, 1), tri(1, 2));
      if (blocked > 0 && blocked < along) ++hidden_but_reflected;
    }
  }
  EXPECT_GT(seen_in_mirror, 50);
  EXPECT_GT(hidden_but_reflected, seen_in_mirror / 5) << seen_in_mirror;
}

// ---- Load limits (LoadLimits: a root folder, a triangle cap) -----------------------------

// The message of the InputError that loading the scene file `path` under `limits` raises.
std::string limited_load_error(const std::string& path, const LoadLimits& limits) {
  return input_error([&] { load_scene(path, limits); }, path);
}

// A scene file in `root`/scenes/ whose one object is the mesh `file`.
std::string mesh_scene(const TempDir& dir, const std::string& file) {
  return dir.write("root/scenes/scene.json",
                   with_objects(R"([{"type": "mesh", "file": ")" + file + R"(", "material": "white"}])").str());
}

TEST(SceneLoadLimits, MeshInsideTheRootIsAccepted) {
  TempDir dir;
  dir.write("root/meshes/cube.obj", CUBE_OBJ);
  const std::string scene = mesh_scene(dir, "../meshes/cube.obj");
  LoadLimits limits;
  limits.root = (dir.path() / "root").string();
  const SceneData s = load_scene(scene, limits);
  EXPECT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.triangles->triangle_count(), 12u);
}

TEST(SceneLoadLimits, MeshOutsideTheRootIsRefusedWithItsField) {
  TempDir dir;
  dir.write("outside/cube.obj", CUBE_OBJ);
  const std::string scene = mesh_scene(dir, "../../outside/cube.obj");
  LoadLimits limits;
  limits.root = (dir.path() / "root").string();
  const std::string root = fs::canonical(limits.root).string();
  EXPECT_EQ(limited_load_error(scene, limits),
            scene + ": objects[0].file: \"../../outside/cube.obj\" resolves outside --root " + root);
  // Without a root the same scene loads.
  EXPECT_EQ(load_scene(scene).triangles->triangle_count(), 12u);
}

TEST(SceneLoadLimits, SymlinkEscapingTheRootIsRefused) {
  TempDir dir;
  dir.write("outside/cube.obj", CUBE_OBJ);
  fs::create_directories(dir.path() / "root" / "meshes");
  fs::create_symlink(dir.path() / "outside" / "cube.obj", dir.path() / "root" / "meshes" / "link.obj");
  const std::string scene = mesh_scene(dir, "../meshes/link.obj");
  LoadLimits limits;
  limits.root = (dir.path() / "root").string();
  EXPECT_NE(limited_load_error(scene, limits).find("objects[0].file: \"../meshes/link.obj\" resolves outside --root"),
            std::string::npos);
}

TEST(SceneLoadLimits, MtllibOutsideTheRootIsRefusedBeforeItIsRead) {
  TempDir dir;
  dir.write("outside/secret.mtl", "newmtl red\nKd 1 0 0\n");
  dir.write("root/meshes/cube.obj", "mtllib ../../outside/secret.mtl\nusemtl red\n" + std::string(CUBE_OBJ));
  // No "material": the OBJ's own MTL materials are used.
  const std::string scene =
      dir.write("root/scenes/scene.json", with_objects(R"([{"type": "mesh", "file": "../meshes/cube.obj"}])").str());
  LoadLimits limits;
  limits.root = (dir.path() / "root").string();
  const std::string m = limited_load_error(scene, limits);
  EXPECT_NE(m.find(scene + ": objects[0].file: mtllib \"../../outside/secret.mtl\""), std::string::npos) << m;
  EXPECT_NE(m.find("resolves outside --root"), std::string::npos) << m;
  // Without a root the MTL material is read.
  const SceneData s = load_scene(scene);
  EXPECT_EQ(s.materials[s.objects[0].material].color, glm::dvec3(1, 0, 0));
}

// Textures under --root (docs/models-and-textures.md): a scene material's texture, an MTL map_Kd
// and a symbolic link inside the root that points out of it; refused before the image is
// read (the file outside holds no image: its content would show in a decode error).
std::string textured_scene(const TempDir& dir, const std::string& texture) {
  SceneText t;
  t.materials = R"({"white": {"color": [0.8, 0.8, 0.8], "texture": ")" + texture + R"("}})";
  return dir.write("root/scenes/scene.json", t.str());
}

TEST(SceneLoadLimits, TextureOutsideTheRootIsRefusedWithItsField) {
  TempDir dir;
  dir.write("outside/secret.png", "SECRET CONTENT");
  const std::string scene = textured_scene(dir, "../../outside/secret.png");
  LoadLimits limits;
  limits.root = (dir.path() / "root").string();
  const std::string root = fs::canonical(limits.root).string();
  const std::string m = limited_load_error(scene, limits);
  EXPECT_EQ(m, scene + ": materials.white.texture: \"../../outside/secret.png\" resolves outside --root " + root);
  // Without a root it is read (and is no image): the content never shows in the message.
  const std::string open = limited_load_error(scene, LoadLimits{});
  EXPECT_NE(open.find("materials.white.texture: cannot decode texture"), std::string::npos) << open;
  EXPECT_EQ(open.find("SECRET"), std::string::npos) << open;
}

TEST(SceneLoadLimits, MtlMapKdOutsideTheRootIsRefusedWithItsLine) {
  TempDir dir;
  dir.write("outside/secret.png", "SECRET CONTENT");
  const std::string mtl = dir.write("root/meshes/cube.mtl", "newmtl red\nKd 1 0 0\nmap_Kd ../../outside/secret.png\n");
  dir.write("root/meshes/cube.obj", "mtllib cube.mtl\nusemtl red\n" + std::string(CUBE_OBJ));
  const std::string scene =
      dir.write("root/scenes/scene.json", with_objects(R"([{"type": "mesh", "file": "../meshes/cube.obj"}])").str());
  LoadLimits limits;
  limits.root = (dir.path() / "root").string();
  const std::string m = limited_load_error(scene, limits);
  EXPECT_EQ(m, scene + ": objects[0].file: \"" + fs::path(mtl).lexically_normal().string() +
                   "\":3: map_Kd \"../../outside/secret.png\" resolves outside --root " +
                   fs::canonical(limits.root).string());
}

TEST(SceneLoadLimits, TextureSymlinkEscapingTheRootIsRefused) {
  TempDir dir;
  dir.write("outside/secret.png", "SECRET CONTENT");
  fs::create_directories(dir.path() / "root" / "textures");
  fs::create_symlink(dir.path() / "outside" / "secret.png", dir.path() / "root" / "textures" / "link.png");
  const std::string scene = textured_scene(dir, "../textures/link.png");
  LoadLimits limits;
  limits.root = (dir.path() / "root").string();
  const std::string m = limited_load_error(scene, limits);
  EXPECT_NE(m.find("materials.white.texture: \"../textures/link.png\" resolves outside --root"), std::string::npos)
      << m;
  EXPECT_EQ(m.find("SECRET"), std::string::npos) << m;
}

TEST(SceneLoadLimits, SceneFileOutsideTheRootIsRefused) {
  TempDir dir;
  const std::string scene = dir.write("elsewhere/scene.json", SceneText().str());
  fs::create_directories(dir.path() / "root");
  LoadLimits limits;
  limits.root = (dir.path() / "root").string();
  EXPECT_NE(limited_load_error(scene, limits).find("resolves outside --root"), std::string::npos);
}

TEST(SceneLoadLimits, TriangleCapNamesTheCountAndTheCap) {
  // Two spheres of 32 segments (sphere_triangle_count each) against a cap between one and two.
  const size_t one = sphere_triangle_count(32);
  const std::string text = with_objects(R"([{"type": "sphere", "center": [0,0,0], "radius": 1},
      {"type": "sphere", "center": [3,0,0], "radius": 1}])")
                               .str();
  LoadLimits limits;
  limits.max_triangles = one + 1;
  EXPECT_EQ(input_error([&] { load_scene_text(text, "scene.json", ".", limits); }, text),
            "scene.json: objects[1].segments: the scene would have " + std::to_string(2 * one) +
                " triangles, over the cap of " + std::to_string(one + 1) + " (max_triangles)");
  limits.max_triangles = 2 * one;
  EXPECT_EQ(load_scene_text(text, "scene.json", ".", limits).triangles->triangle_count(), 2 * one);
  // A mesh is counted from its faces before its triangles are made.
  TempDir dir;
  dir.write("cube.obj", CUBE_OBJ);
  limits.max_triangles = 11;
  const std::string mesh = with_objects(R"([{"type": "mesh", "file": "cube.obj", "material": "white"}])").str();
  EXPECT_EQ(input_error([&] { load_scene_text(mesh, "scene.json", dir.path().string(), limits); }, mesh),
            "scene.json: objects[0].file: the scene would have 12 triangles, over the cap of 11 (max_triangles)");
}

// ---- glTF 2.0 (issue 15 part 1) ---------------------------------------------------------

// The bytes of little-endian floats and unsigned shorts, as a .bin file holds them.
template <class T>
std::string bytes_of(const std::vector<T>& v) {
  return std::string(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

// A glTF of one quad (4 vertices, 6 indices of UNSIGNED_SHORT) at z = 0 in [0, 1]^2, its
// buffer "quad.bin" written beside it. `node` is the one node's JSON; `material`,
// `extra` (top-level members, with a leading comma) and `primitive_extra` (with a comma)
// complete it.
struct QuadGltf {
  std::string node = R"({"mesh": 0})";
  std::string scene_nodes = "[0]";
  std::string materials = "[]";
  std::string primitive_extra;
  std::string extra;
  std::string buffer_uri = "quad.bin";
  std::vector<uint16_t> indices = {0, 1, 2, 0, 2, 3};
  std::string str() const {
    return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": )" + scene_nodes + R"(}], "nodes": [)" +
           node + R"(], "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 2}, "indices": 1)" +
           primitive_extra + R"(}]}], "materials": )" + materials + R"(,
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
                    {"bufferView": 1, "componentType": 5123, "count": )" +
           std::to_string(indices.size()) +
           R"(, "type": "SCALAR"},
                    {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"}],
      "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": )" +
           std::to_string(2 * indices.size()) + R"(},
                      {"buffer": 0, "byteOffset": )" +
           std::to_string(48 + 2 * indices.size()) + R"(, "byteLength": 32}],
      "buffers": [{"uri": ")" +
           buffer_uri + R"(", "byteLength": )" + std::to_string(48 + 2 * indices.size() + 32) + "}]" + extra + "}";
  }
  std::string bin() const {
    return bytes_of(std::vector<float>{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}) + bytes_of(indices) +
           bytes_of(std::vector<float>{0, 0, 1, 0, 1, 1, 0, 1});
  }
  void write(const TempDir& dir, const std::string& name = "quad.gltf") const {
    dir.write(name, str());
    dir.write((fs::path(name).parent_path() / "quad.bin").string(), bin());
  }
};

std::string gltf_scene(const std::string& object_extra = "") {
  return with_objects(R"([{"type": "gltf", "file": "quad.gltf")" + object_extra + "}]").str();
}

TEST(SceneLoadGltf, NodeTransformsAndTexcoordsReachTheSoup) {
  TempDir dir;
  QuadGltf g;
  // Scale 2, then a quarter turn about z, then a shift: (1, 0, 0) -> (0, 2, 0) + (5, 0, 0).
  g.node =
      R"({"children": [1], "translation": [5, 0, 0]}, {"mesh": 0, "rotation": [0, 0, 0.7071067811865476, 0.7071067811865476], "scale": [2, 2, 2]})";
  g.write(dir);
  const SceneData s = load_text(gltf_scene(), dir.path().string());
  ASSERT_EQ(s.triangles->triangle_count(), 2u);
  EXPECT_NEAR(glm::distance(corner(s, 0, 1), glm::dvec3(5, 2, 0)), 0.0, 1e-6);
  EXPECT_NEAR(glm::distance(corner(s, 0, 2), glm::dvec3(3, 2, 0)), 0.0, 1e-6);
  EXPECT_TRUE(s.triangles->uvs.empty());             // untextured: uvs are not kept
  EXPECT_NEAR(geometric_normal(s, 0).z, 1.0, 1e-9);  // counter-clockwise seen from +z
  EXPECT_EQ(s.materials[s.triangles->material_id[0]].name, "(default)");
  EXPECT_TRUE(s.warnings.empty());
}

TEST(SceneLoadGltf, MaterialsAreMapped) {
  TempDir dir;
  QuadGltf g;
  g.materials = R"([{"name": "glass", "pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.4, 0.6, 0.5],
      "metallicFactor": 0.5, "roughnessFactor": 0.2}, "alphaMode": "BLEND",
      "extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.8}, "KHR_materials_ior": {"ior": 1.33}}}])";
  g.primitive_extra = R"(, "material": 0)";
  g.write(dir);
  const SceneData s = load_text(gltf_scene(), dir.path().string());
  const Material& m = s.materials[s.triangles->material_id[0]];
  EXPECT_EQ(m.name, "quad.gltf:glass");
  EXPECT_EQ(m.color, glm::dvec3(0.2, 0.4, 0.6));
  EXPECT_DOUBLE_EQ(m.opacity, 0.5);
  EXPECT_DOUBLE_EQ(m.transmit, 0.8 * 0.5);       // transmission x (1 - metallic)
  EXPECT_DOUBLE_EQ(m.reflect, 0.5 * (1 - 0.2));  // metallic x (1 - roughness)
  EXPECT_DOUBLE_EQ(m.diffuse, 1 - m.reflect - m.transmit);
  EXPECT_DOUBLE_EQ(m.ior, 1.33);
  // The object's own material replaces the file's.
  const SceneData own = load_text(gltf_scene(R"(, "material": "white")"), dir.path().string());
  EXPECT_EQ(own.materials[own.triangles->material_id[0]].name, "white");
}

TEST(SceneLoadGltf, BadIndicesAndTypesNameTheirPlace) {
  TempDir dir;
  QuadGltf g;
  g.indices = {0, 1, 2, 0, 2, 99};
  g.write(dir);
  EXPECT_EQ(load_error(gltf_scene(), dir.path().string()),
            "scene.json: objects[0].file: \"quad.gltf\": meshes[0].primitives[0].indices: index 99 out of range (4 "
            "vertices)");
  QuadGltf t;
  t.node = R"({"mesh": "zero"})";
  t.write(dir);
  EXPECT_EQ(load_error(gltf_scene(), dir.path().string()),
            "scene.json: objects[0].file: \"quad.gltf\": nodes[0].mesh: must be an integer >= 0, got \"zero\"");
  QuadGltf cycle;
  cycle.node = R"({"mesh": 0, "children": [0]})";
  cycle.write(dir);
  EXPECT_NE(load_error(gltf_scene(), dir.path().string()).find("nodes[0]: is its own ancestor"), std::string::npos);
  QuadGltf draco;
  draco.extra =
      R"(, "extensionsRequired": ["KHR_draco_mesh_compression"], "extensionsUsed": ["KHR_draco_mesh_compression"])";
  draco.write(dir);
  EXPECT_NE(load_error(gltf_scene(), dir.path().string())
                .find("extensionsRequired[0]: \"KHR_draco_mesh_compression\" is not supported"),
            std::string::npos);
  dir.write("quad.gltf", R"({"asset": {"version": "1.0"}, "meshes": {}})");
  EXPECT_NE(load_error(gltf_scene(), dir.path().string()).find("asset.version: only glTF 2.0 is read, got \"1.0\""),
            std::string::npos);
}

TEST(SceneLoadGltf, UnsupportedPartsWarnOnce) {
  TempDir dir;
  QuadGltf g;
  g.node = R"({"mesh": 0, "skin": 0, "extensions": {"KHR_lights_punctual": {"light": 0}}})";
  g.extra = R"(, "skins": [{"joints": [0]}], "extensionsUsed": ["KHR_lights_punctual"],
      "extensions": {"KHR_lights_punctual": {"lights": [{"type": "spot", "spot": {}}]}})";
  g.write(dir);
  const SceneData s = load_text(gltf_scene(), dir.path().string());
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0],
            "scene.json: objects[0].file: warning: glTF \"quad.gltf\": not rendered: "
            "KHR_lights_punctual spot lights; skins (meshes drawn unskinned)");
  EXPECT_EQ(s.lights.size(), 1u);  // the scene's own only
}

TEST(SceneLoadGltf, PointLightsAndCameraFromTheFile) {
  TempDir dir;
  QuadGltf g;
  // The light 2 above the quad's centre (0.5, 0.5, 0): 8 cd / 2^2 = 2. The camera at z = 3
  // looking down -z (a node without rotation), yfov 0.5 rad.
  g.node = R"({"mesh": 0}, {"translation": [0.5, 0.5, 2], "extensions": {"KHR_lights_punctual": {"light": 0}}},
             {"translation": [0.5, 0.5, 3], "camera": 0})";
  g.extra =
      R"(, "extensionsUsed": ["KHR_lights_punctual"], "cameras": [{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}}],
      "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "color": [1, 0.5, 0.25], "intensity": 8}]}})";
  g.scene_nodes = "[0, 1, 2]";
  g.write(dir);
  SceneText scene = with_objects(R"([{"type": "gltf", "file": "quad.gltf", "use_camera": true,
                                     "transform": {"translate": [10, 0, 0]}}])");
  scene.lights = "[]";
  const SceneData s = load_text(scene.str(), dir.path().string());
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].position, glm::dvec3(10.5, 0.5, 2));
  EXPECT_EQ(s.lights[0].color, glm::dvec3(2, 1, 0.5));
  EXPECT_EQ(s.camera.position, glm::dvec3(10.5, 0.5, 3));
  EXPECT_EQ(s.camera.look_at, glm::dvec3(10.5, 0.5, 2));
  EXPECT_NEAR(s.camera.fov_y_deg, 0.5 * 180 / 3.14159265358979323846, 1e-12);
  EXPECT_EQ(s.camera.width, 64);  // the image size stays the scene's
}

TEST(SceneLoadGltf, GlbImagesAreKeptEncoded) {
  TempDir dir;
  QuadGltf g;
  g.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}])";
  g.primitive_extra = R"(, "material": 0)";
  // A 1 x 1 PNG.
  const std::string png(
      "\x89\x50\x4e\x47\x0d\x0a\x1a\x0a\x00\x00\x00\x0d\x49\x48\x44\x52\x00\x00\x00\x01\x00\x00\x00\x01\x08\x06"
      "\x00\x00\x00\x1f\x15\xc4\x89\x00\x00\x00\x0d\x49\x44\x41\x54\x78\xda\x63\x64\x60\xf8\x5f\x0f\x00\x02"
      "\x87\x01\x80\xeb\x47\xba\x92\x00\x00\x00\x00\x49\x45\x4e\x44\xae\x42\x60\x82",
      70);
  g.buffer_uri = "";
  std::string json = g.str();
  // One buffer, the GLB's BIN chunk, with the image's bytes after the geometry.
  const std::string bin = g.bin() + png + std::string((4 - png.size() % 4) % 4, '\0');
  json.replace(json.find("\"uri\": \"\", "), 11, "");
  json.replace(json.find("\"byteLength\": 92}]"), 18, "\"byteLength\": " + std::to_string(bin.size()) + "}]");
  json.replace(json.rfind('}'), 1,
               R"(, "textures": [{"source": 0}], "images": [{"bufferView": 3, "mimeType": "image/png"}]})");
  json.replace(
      json.find("\"byteLength\": 32}]"), 18,
      "\"byteLength\": 32}, {\"buffer\": 0, \"byteOffset\": 92, \"byteLength\": " + std::to_string(png.size()) + "}]");
  json += std::string((4 - json.size() % 4) % 4, ' ');
  const auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  const std::string glb = "glTF" + u32(2) + u32(static_cast<uint32_t>(12 + 8 + json.size() + 8 + bin.size())) +
                          u32(static_cast<uint32_t>(json.size())) + "JSON" + json +
                          u32(static_cast<uint32_t>(bin.size())) + std::string("BIN\0", 4) + bin;
  dir.write("quad.glb", glb);
  const SceneData s = load_text(with_objects(R"([{"type": "gltf", "file": "quad.glb"}])").str(), dir.path().string());
  ASSERT_EQ(s.embedded_images.size(), 1u);
  EXPECT_EQ(s.embedded_images[0].mime_type, "image/png");
  EXPECT_EQ(std::string(s.embedded_images[0].bytes->begin(), s.embedded_images[0].bytes->end()), png);
  EXPECT_EQ(s.materials[s.triangles->material_id[0]].texture, "#embedded/0");
  ASSERT_EQ(s.triangles->uvs.size(), 6u);
  EXPECT_EQ(s.triangles->uvs[1], glm::vec2(1, 1));  // glTF (1, 0): v runs down, stored 1 - v
  EXPECT_EQ(s.triangles->uvs[2], glm::vec2(1, 0));
}

// Issue 18: what a glTF names must resolve inside --root (symbolic links followed); the
// message names the field and the URI, none of the file's content. data: URIs need no file.
TEST(SceneLoadLimits, GltfBuffersAndImagesOutsideTheRootAreRefused) {
  TempDir dir;
  QuadGltf g;
  g.buffer_uri = "../../outside/quad.bin";
  dir.write("outside/quad.bin", g.bin());
  dir.write("root/models/quad.gltf", g.str());
  const std::string scene =
      dir.write("root/scenes/scene.json", with_objects(R"([{"type": "gltf", "file": "../models/quad.gltf"}])").str());
  LoadLimits limits;
  limits.root = (dir.path() / "root").string();
  const std::string root = fs::canonical(limits.root).string();
  EXPECT_EQ(limited_load_error(scene, limits), scene +
                                                   ": objects[0].file: \"../models/quad.gltf\": buffers[0].uri "
                                                   "\"../../outside/quad.bin\" resolves outside --root " +
                                                   root);
  // The same through a symbolic link inside the root.
  g.buffer_uri = "link.bin";
  dir.write("root/models/quad.gltf", g.str());
  fs::create_symlink(dir.path() / "outside" / "quad.bin", dir.path() / "root" / "models" / "link.bin");
  EXPECT_NE(limited_load_error(scene, limits).find("buffers[0].uri \"link.bin\" resolves outside --root"),
            std::string::npos);
  // An image: refused the same way; a data: URI image is fine.
  g.buffer_uri = "quad.bin";
  dir.write("root/models/quad.bin", g.bin());
  dir.write("outside/x.png", "secret");
  for (const std::string& uri :
       {std::string("../../outside/x.png"), std::string("data:image/png;base64,iVBORw0KGgo=")}) {
    std::string json = g.str();
    json.replace(json.rfind('}'), 1, R"(, "images": [{"uri": "x.png"}, {"uri": ")" + uri + R"("}]})");
    dir.write("root/models/quad.gltf", json);
    if (uri.rfind("data:", 0) == 0) {
      EXPECT_EQ(load_scene(scene, limits).triangles->triangle_count(), 2u);
    } else {
      const std::string m = limited_load_error(scene, limits);
      EXPECT_NE(m.find(": images[1].uri \"../../outside/x.png\" resolves outside --root " + root), std::string::npos)
          << m;
      EXPECT_EQ(m.find("secret"), std::string::npos) << m;
    }
  }
  // A buffer that is no regular file (no root: /dev/zero is outside any), and one over the
  // mesh cap.
  fs::create_symlink("/dev/zero", dir.path() / "root" / "models" / "zero.bin");
  g.buffer_uri = "zero.bin";
  dir.write("root/models/quad.gltf", g.str());
  std::string m = limited_load_error(scene, LoadLimits{});
  EXPECT_NE(m.find("buffers[0].uri \"zero.bin\": not a regular file"), std::string::npos) << m;
  g.buffer_uri = "big.bin";
  dir.write("root/models/big.bin", g.bin() + std::string(4000, '\0'));
  dir.write("root/models/quad.gltf", g.str());
  limits.max_mesh_bytes = 2000;
  m = limited_load_error(scene, limits);
  EXPECT_NE(m.find("buffers[0].uri \"big.bin\": is "), std::string::npos) << m;
  EXPECT_NE(m.find("over the cap of"), std::string::npos) << m;
}

// ---- Framing (issue 15 part 4) ---------------------------------------------------------

// The pixel a point projects to (x right, y down), through the camera's own frame.
glm::dvec2 project(const Camera& c, const glm::dvec3& p) {
  const glm::dvec3 f = glm::normalize(c.look_at - c.position);
  const glm::dvec3 r = glm::normalize(glm::cross(f, c.up));
  const glm::dvec3 u = glm::cross(r, f);
  const glm::dvec3 q = p - c.position;
  const double t = std::tan(c.fov_y_deg * 3.14159265358979323846 / 360.0);
  const double aspect = static_cast<double>(c.width) / c.height;
  const double x = glm::dot(q, r) / (glm::dot(q, f) * t * aspect), y = glm::dot(q, u) / (glm::dot(q, f) * t);
  return {(x + 1) * 0.5 * c.width, (1 - y) * 0.5 * c.height};
}

TEST(Framing, TheBoundsFitTheImageFromTheGivenDirection) {
  Bounds b;
  b.extend(glm::dvec3(-1, 0, -3));
  b.extend(glm::dvec3(3, 2, 1));
  for (const glm::dvec3& dir :
       {glm::dvec3(0, -0.35, -1), glm::dvec3(1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(-1, -2, 3)}) {
    Camera c;
    c.width = 320;
    c.height = 200;
    c = frame_camera(b, dir, c);
    EXPECT_EQ(c.look_at, glm::dvec3(1, 1, -1));
    EXPECT_NEAR(glm::length(glm::normalize(c.look_at - c.position) - glm::normalize(dir)), 0.0, 1e-12);
    bool outside = false;
    for (int i = 0; i < 3; ++i) outside = outside || c.position[i] < b.lo[i] || c.position[i] > b.hi[i];
    EXPECT_TRUE(outside) << "camera inside the bounds";
    double widest_x = 0, widest_y = 0;
    for (int k = 0; k < 8; ++k) {
      const glm::dvec3 p(k & 1 ? b.hi.x : b.lo.x, k & 2 ? b.hi.y : b.lo.y, k & 4 ? b.hi.z : b.lo.z);
      const glm::dvec2 px = project(c, p);
      EXPECT_GE(px.x, 0.0);
      EXPECT_LE(px.x, 320.0);
      EXPECT_GE(px.y, 0.0);
      EXPECT_LE(px.y, 200.0);
      widest_x = std::max(widest_x, std::fabs(px.x - 160) / 160);
      widest_y = std::max(widest_y, std::fabs(px.y - 100) / 100);
    }
    // Fitted, not merely inside: one side reaches the 5% margin.
    EXPECT_NEAR(std::max(widest_x, widest_y), 1 / 1.05, 1e-9);
  }
}

TEST(Framing, KnownCameraPosition) {
  // A cube of side 2 at the origin seen along -z with a 90-degree square view: the nearest
  // face (z = 1) has its corners at |x| = |y| = 1, so distance d satisfies 1 = (d - 1) tan(45) / 1.05.
  Bounds b;
  b.extend(glm::dvec3(-1));
  b.extend(glm::dvec3(1));
  Camera c;
  c.fov_y_deg = 90;
  c.width = c.height = 100;
  c = frame_camera(b, glm::dvec3(0, 0, -1), c);
  EXPECT_NEAR(c.position.z, 2.05, 1e-12);
  EXPECT_NEAR(glm::length(glm::dvec2(c.position.x, c.position.y)), 0.0, 1e-12);
  const std::vector<PointLight> lights = frame_lights(b, c);
  ASSERT_EQ(lights.size(), 2u);
  EXPECT_TRUE(lights[0].cast_shadows);
  EXPECT_FALSE(lights[1].cast_shadows);
  EXPECT_GT(lights[0].position.y, 1.0);  // above
  EXPECT_GT(lights[0].position.z, 1.0);  // on the camera's side
}

TEST(Framing, SceneFrameAllPlacesTheCameraAndLights) {
  SceneText s;
  s.camera = R"({"frame": "all", "width": 64, "height": 48})";
  s.lights = "[]";
  const SceneData dark = load_text(s.str());
  EXPECT_TRUE(dark.lights.empty());  // "lights": [] given: none added
  EXPECT_EQ(dark.camera.look_at, glm::dvec3(0.0));
  EXPECT_GT(dark.camera.position.z, 1.0);
  const std::string text = s.str();
  const std::string no_lights = text.substr(0, text.find(",\n\"lights\"")) + text.substr(text.find(",\n\"materials\""));
  EXPECT_EQ(load_text(no_lights).lights.size(), 2u);
  s.camera = R"({"frame": "all", "position": [0, 0, 5]})";
  EXPECT_ERROR(s.str(), "camera.position: must not be given with \"frame\"");
  s.camera = R"({"frame": "some"})";
  EXPECT_ERROR(s.str(), "camera.frame: must be \"all\"");
  s.camera = R"({"frame": "all", "direction": [0, 0, 0]})";
  EXPECT_ERROR(s.str(), "camera.direction: must be nonzero");
}

TEST(SceneLoadGltf, AModelFileIsAFramedLitScene) {
  TempDir dir;
  QuadGltf g;
  g.indices = {0, 1, 2, 0, 2, 99};
  g.write(dir);
  const std::string bad = (dir.path() / "quad.gltf").string();
  EXPECT_EQ(input_error([&] { load_scene(bad); }, bad),
            bad + ": meshes[0].primitives[0].indices: index 99 out of range (4 vertices)");
  g.indices = {0, 1, 2, 0, 2, 3};
  g.write(dir);
  for (const std::string& name : {std::string("quad.gltf"), std::string("cube.OBJ")}) {
    dir.write("cube.OBJ", "mtllib gone.mtl\n" + std::string(CUBE_OBJ));
    const SceneData s = load_scene((dir.path() / name).string());
    EXPECT_EQ(s.camera.width, 640);
    EXPECT_EQ(s.camera.height, 480);
    EXPECT_EQ(s.lights.size(), 2u);
    EXPECT_GT(s.triangles->triangle_count(), 0u);
    const glm::dvec3 centre = name == "quad.gltf" ? glm::dvec3(0.5, 0.5, 0) : glm::dvec3(0.5);
    EXPECT_NEAR(glm::distance(s.camera.look_at, centre), 0.0, 1e-12) << name;
    if (name == "cube.OBJ") {
      ASSERT_EQ(s.warnings.size(), 1u);
      EXPECT_EQ(s.warnings[0], (dir.path() / name).string() +
                                   ": warning: mesh \"cube.OBJ\": mtllib: material file "
                                   "\"gone.mtl\" not found; the default material is used");
    }
  }
}

}  // namespace
}  // namespace abcube
