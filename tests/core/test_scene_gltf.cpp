// glTF 2.0 objects (cpu_core/scene/scene_gltf*.cpp): transforms, texture coordinates,
// materials, bad indices and types, warnings, lights and cameras, embedded images, root limits,
// a model file given as the scene.
#include "scene_load_fixtures.hpp"

namespace abcube {
namespace {

using namespace scene_test;

// ---- glTF 2.0 ----------------------------------------------------------------------------

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

std::string u32_bytes(uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); }

// A binary glTF container: the header, a JSON chunk (padded with spaces to 4 bytes) and,
// when `bin` is not empty, a BIN chunk, each chunk's length as the layout requires.
std::string glb(std::string json, const std::string& bin) {
  json += std::string((4 - json.size() % 4) % 4, ' ');
  std::string chunks = u32_bytes(static_cast<uint32_t>(json.size())) + "JSON" + json;
  if (!bin.empty()) chunks += u32_bytes(static_cast<uint32_t>(bin.size())) + std::string("BIN\0", 4) + bin;
  return "glTF" + u32_bytes(2) + u32_bytes(static_cast<uint32_t>(12 + chunks.size())) + chunks;
}

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
  dir.write("quad.glb", glb(json, bin));
  const SceneData s = load_text(with_objects(R"([{"type": "gltf", "file": "quad.glb"}])").str(), dir.path().string());
  ASSERT_EQ(s.embedded_images.size(), 1u);
  EXPECT_EQ(s.embedded_images[0].mime_type, "image/png");
  EXPECT_EQ(std::string(s.embedded_images[0].bytes->begin(), s.embedded_images[0].bytes->end()), png);
  EXPECT_EQ(s.materials[s.triangles->material_id[0]].texture, "#embedded/0");
  ASSERT_EQ(s.triangles->uvs.size(), 6u);
  EXPECT_EQ(s.triangles->uvs[1], glm::vec2(1, 1));  // glTF (1, 0): v runs down, stored 1 - v
  EXPECT_EQ(s.triangles->uvs[2], glm::vec2(1, 0));
}

// A .glb's chunks must lie inside its header's length before tinygltf reads them: a BIN
// chunk whose length runs past the file would have it copy bytes from beyond the end.
// An image's buffer view must lie inside its buffer (glTF 5.11). tinygltf hands an image's
// buffer view to the image reader without that check: found by fuzz_gltf as a read past the
// buffer.
TEST(SceneLoadGltf, ImageBufferViewsLieInsideTheirBuffers) {
  TempDir dir;
  const auto error_for = [&](const std::string& view, const std::string& image) {
    QuadGltf g;
    g.extra = R"(, "images": [)" + image + "]";
    std::string json = g.str();
    const std::string last_view = R"("byteLength": 32}])";
    const size_t at = json.find(last_view);
    EXPECT_NE(at, std::string::npos);
    json.replace(at, last_view.size(), R"("byteLength": 32}, )" + view + "]");
    dir.write("quad.gltf", json);
    dir.write("quad.bin", g.bin());
    return load_error(gltf_scene(), dir.path().string());
  };
  const std::string prefix = "scene.json: objects[0].file: \"quad.gltf\": images[0].bufferView: ";
  const std::string png = R"({"bufferView": 3, "mimeType": "image/png"})";
  EXPECT_EQ(error_for(R"({"buffer": 0, "byteLength": 4000})", png),
            prefix + "bufferViews[3] (byteOffset 0 + byteLength 4000) passes the end of buffers[0] (byteLength 92)");
  EXPECT_EQ(error_for(R"({"buffer": 0, "byteOffset": 90, "byteLength": 4})", png),
            prefix + "bufferViews[3] (byteOffset 90 + byteLength 4) passes the end of buffers[0] (byteLength 92)");
  EXPECT_EQ(error_for(R"({"buffer": 0, "byteOffset": 18446744073709551615, "byteLength": 4})", png),
            prefix +
                "bufferViews[3] (byteOffset 18446744073709551615 + byteLength 4) passes the end of buffers[0] "
                "(byteLength 92)");
  EXPECT_EQ(error_for(R"({"buffer": 1, "byteLength": 4})", png),
            prefix + "bufferViews[3] names no buffer (the file has 1)");
  EXPECT_EQ(error_for(R"({"buffer": 0, "byteLength": 4})", R"({"bufferView": 7, "mimeType": "image/png"})"),
            prefix + "7 names no buffer view (the file has 4)");
}

TEST(SceneLoadGltf, GlbContainerLayoutIsChecked) {
  TempDir dir;
  QuadGltf g;
  g.buffer_uri = "";
  std::string json = g.str();
  json.replace(json.find("\"uri\": \"\", "), 11, "");
  const std::string good = glb(json, g.bin());
  const std::string scene = with_objects(R"([{"type": "gltf", "file": "quad.glb"}])").str();
  dir.write("quad.glb", good);
  EXPECT_EQ(load_text(scene, dir.path().string()).triangles->triangle_count(), 2u);

  const auto error_for = [&](const std::string& bytes) {
    dir.write("quad.glb", bytes);
    return load_error(scene, dir.path().string());
  };
  const std::string prefix = "scene.json: objects[0].file: \"quad.glb\": not a valid binary glTF: ";
  const size_t bin_header = 12 + 8 + (json.size() + 3) / 4 * 4;
  std::string overlong = good;  // the BIN chunk claims its own 8-byte header as data too
  overlong.replace(bin_header, 4, u32_bytes(static_cast<uint32_t>(good.size() - bin_header)));
  EXPECT_EQ(error_for(overlong), prefix + "chunk 1 claims " + std::to_string(good.size() - bin_header) + " bytes, " +
                                     std::to_string(good.size() - bin_header - 8) + " remain");
  std::string long_header = good;
  long_header.replace(8, 4, u32_bytes(static_cast<uint32_t>(good.size() + 4)));
  EXPECT_EQ(error_for(long_header), prefix + "the header says " + std::to_string(good.size() + 4) +
                                        " bytes, the file has " + std::to_string(good.size()));
  std::string not_json = good;
  not_json.replace(16, 4, "JSOX");
  EXPECT_EQ(error_for(not_json), prefix + "the first chunk is not JSON");
  EXPECT_EQ(error_for(good.substr(0, 10)), prefix + "shorter than its 12-byte header");
  std::string torn = good.substr(0, bin_header + 4);  // the header's length cut to match
  torn.replace(8, 4, u32_bytes(static_cast<uint32_t>(torn.size())));
  EXPECT_EQ(error_for(torn), prefix + "chunk 1 has no room for its 8-byte header");
  std::string empty = good.substr(0, 12);
  empty.replace(8, 4, u32_bytes(12));
  EXPECT_EQ(error_for(empty), prefix + "no JSON chunk");
  std::string version_one = good;
  version_one.replace(4, 4, u32_bytes(1));
  EXPECT_EQ(error_for(version_one),
            "scene.json: objects[0].file: \"quad.glb\": binary glTF version 1: only glTF 2.0 is read");
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
