// Load limits (LoadLimits, scene_load.hpp): files confined to a root, symbolic links, texture
// and MTL paths, the triangle cap.
#include "scene_load_fixtures.hpp"

namespace abcube {
namespace {

using namespace scene_test;

// ---- Load limits (LoadLimits: a root folder, a triangle cap) -----------------------------

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

// A mesh over the caps is refused from a count of its face lines, before it is parsed: a
// file whose last face is broken gets the cap's message, not the parser's. Polygons count
// n - 2, blanks and comments do not, and "fo" is no face.
TEST(SceneLoadLimits, MeshOverTheCapsIsRefusedBeforeItIsParsed) {
  TempDir dir;
  std::string obj = "# a fan of quads and one hexagon\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 2 0\nv 1 2 0\n";
  for (int k = 0; k < 2500; ++k) obj += "f 1 2 3 4\n  f\t1 2  3\r\nfo 1 2 3\n";
  obj += "f 1 2 3 4 5 6\nf 1 2 999999";  // the last face's index is out of range, no newline
  dir.write("fan.obj", obj);
  const std::string mesh = with_objects(R"([{"type": "mesh", "file": "fan.obj"}])").str();
  LoadLimits limits;
  const auto error = [&] {
    return input_error([&] { load_scene_text(mesh, "scene.json", dir.path().string(), limits); }, mesh);
  };
  const std::string counted = std::to_string(2500 * 3 + 4 + 1);
  EXPECT_NE(error().find(": line 7509: f: corner 3: v index 999999, but the file has 6 v lines"), std::string::npos)
      << "with no cap, the check after parsing: " << error();
  limits.max_triangles = 1000;
  EXPECT_EQ(error(), "scene.json: objects[0].file: the scene would have " + counted +
                         " triangles, over the cap of 1000 (max_triangles)");
  limits.max_triangles = 0;
  limits.max_memory_mib = 1;  // 6168 triangles at SCENE_TRIANGLE_BYTES
  EXPECT_NE(error().find("the scene would have " + counted + " triangles, an estimated"), std::string::npos) << error();
}

}  // namespace
}  // namespace abcube
