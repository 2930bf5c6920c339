// Scene loading (cpu_core/scene/scene_load.cpp, scene_json.cpp) against the scene format:
// the format's own example, and one test per class of bad input (each message must name its
// place).
#include "scene_load_fixtures.hpp"

namespace abcube {
namespace {

using namespace scene_test;

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
  EXPECT_EQ(s.render.method, "abuffer");
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
  s.render = R"({"spp": 4})";
  EXPECT_ERROR(s.str(), "scene.json: render.spp: unknown field");
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
  // The core knows no method: without LoadLimits::methods any name but "" is taken (the
  // host's Scene::load gives its registry's names: tests/cli/scene_errors.sh).
  s.render = R"({"method": ""})";
  EXPECT_ERROR(s.str(), "scene.json: render.method: must be a method's name, got \"\"");
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

// ---- Input files: regular files under their caps ---------------------------------------------

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

}  // namespace
}  // namespace abcube
