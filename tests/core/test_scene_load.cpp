// Scene loading (cpu_core/scene/scene_load.cpp, scene_json.cpp, tessellate.cpp) against the
// scene format: the format's own example, one test per class of bad input (each message must
// name its place), known answers for the tessellated primitives and the transform, the memory
// estimate and the repository's scenes.
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

}  // namespace
}  // namespace abcube
