// OBJ and MTL meshes (cpu_core/scene/scene_mesh.cpp): materials, normals, polygons, winding,
// bad indices, and the input text that reaches messages.
#include "scene_load_fixtures.hpp"

namespace abcube {
namespace {

using namespace scene_test;

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

// Forgiving OBJ: a missing MTL file or material is one warning and the
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

// ---- Input text in messages: cut short and escaped ---------------------------------------------

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

}  // namespace
}  // namespace abcube
