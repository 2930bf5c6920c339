// Base-colour textures (scene/texture.hpp, docs/models-and-textures.md): decoding and colour space,
// the sampler's known answers (texel centres, wrap, v up), uvs from OBJ vt and the
// primitives, an embedded image, the rule Od = colour * texture in the tracer and the map
// paths, and the errors a missing or corrupt image gives.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include "base/error.hpp"
#include "scene/scene_load.hpp"
#include "scene/scene_load_state.hpp"
#include "scene/texture.hpp"

namespace abcube {
namespace {

namespace fs = std::filesystem;

double srgb_to_linear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

// An 8-bit RGB PNG of `w` x `h` texels, encoded in memory by OpenImageIO.
std::vector<unsigned char> png(int w, int h, const std::vector<unsigned char>& rgb) {
  std::vector<unsigned char> bytes;
  OIIO::Filesystem::IOVecOutput out(bytes);
  const void* proxy = &out;
  OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::UINT8);
  spec.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  auto o = OIIO::ImageOutput::create("t.png");
  EXPECT_TRUE(o && o->open("t.png", spec) && o->write_image(OIIO::TypeDesc::UINT8, rgb.data()) && o->close());
  return bytes;
}

// 4 x 2 texels, each channel a distinct code: texel (i, j) = (40 i + 10, 100 j + 30, 200).
std::vector<unsigned char> test_texels() {
  std::vector<unsigned char> rgb;
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 4; ++i)
      rgb.insert(rgb.end(), {static_cast<unsigned char>(40 * i + 10), static_cast<unsigned char>(100 * j + 30), 200});
  }
  return rgb;
}

class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "abcube_tex_XXXXXX").string();
    path_ = ::mkdtemp(pattern.data()) ? fs::path(pattern) : fs::path();
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  std::string write(const std::string& relative, const std::string& bytes) const {
    const fs::path p = path_ / relative;
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << bytes;
    return p.string();
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::string as_string(const std::vector<unsigned char>& v) { return std::string(v.begin(), v.end()); }

std::string load_error(const std::string& path) {
  try {
    load_scene(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

// A scene with one textured quad facing the camera (+z), filling most of the view.
std::string quad_scene(const std::string& texture) {
  return R"({"version": 1, "camera": {"position": [0, 0, 3], "look_at": [0, 0, 0], "fov_y": 40, "width": 48, "height": 32},
    "ambient": [1, 1, 1], "lights": [{"type": "point", "position": [0.5, 1, 4]}],
    "materials": {"t": {"color": [1, 0.5, 1], "ambient": 0.3, "texture": ")" +
         texture + R"("}},
    "objects": [{"type": "quad", "vertices": [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], "material": "t"}],
    "render": {"cube_resolution": 64, "max_depth": 1}})";
}

TEST(Textures, DecodesSrgbToLinear) {
  const std::vector<unsigned char> bytes = png(4, 2, test_texels());
  TextureImage image;
  std::string why;
  ASSERT_TRUE(decode_texture(bytes.data(), bytes.size(), "t.png", "", &image, &why)) << why;
  ASSERT_EQ(image.width, 4);
  ASSERT_EQ(image.height, 2);
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 4; ++i) {
      const size_t t = 3 * static_cast<size_t>(j * 4 + i);
      EXPECT_NEAR(image.rgb[t], srgb_to_linear((40 * i + 10) / 255.0), 1e-6);
      EXPECT_NEAR(image.rgb[t + 1], srgb_to_linear((100 * j + 30) / 255.0), 1e-6);
      EXPECT_NEAR(image.rgb[t + 2], srgb_to_linear(200 / 255.0), 1e-6);
    }
  }
}

TEST(Textures, CorruptBytesAreRefusedWithAReason) {
  std::vector<unsigned char> bytes = png(4, 2, test_texels());
  bytes.resize(bytes.size() / 2);  // truncated
  TextureImage image;
  std::string why;
  EXPECT_FALSE(decode_texture(bytes.data(), bytes.size(), "t.png", "", &image, &why));
  EXPECT_FALSE(why.empty());
  const std::string text = "not an image at all";
  EXPECT_FALSE(
      decode_texture(reinterpret_cast<const unsigned char*>(text.data()), text.size(), "t.png", "", &image, &why));
}

// Texel centres give the texel (bilinear weights 1), v runs up (row 0 is the top), and
// the wrap is periodic.
TEST(Textures, SamplerKnownAnswers) {
  const std::vector<unsigned char> bytes = png(4, 2, test_texels());
  TextureImage image;
  std::string why;
  ASSERT_TRUE(decode_texture(bytes.data(), bytes.size(), "t.png", "", &image, &why)) << why;
  const std::vector<float> texels = image.rgb;
  const TextureSet set({image}, {0});
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 4; ++i) {
      const glm::dvec2 uv((i + 0.5) / 4, 1.0 - (j + 0.5) / 2);
      const size_t t = 3 * static_cast<size_t>(j * 4 + i);
      for (const glm::dvec2 shift : {glm::dvec2(0, 0), glm::dvec2(1, 0), glm::dvec2(-2, 3)}) {
        const glm::dvec3 c = set.sample(0, uv + shift);
        EXPECT_NEAR(c.r, texels[t], 1e-5) << i << " " << j;
        EXPECT_NEAR(c.g, texels[t + 1], 1e-5) << i << " " << j;
        EXPECT_NEAR(c.b, texels[t + 2], 1e-5) << i << " " << j;
      }
    }
  }
  // Halfway between texels (0, 0) and (1, 0): the mean (bilinear on linear values).
  const glm::dvec3 mid = set.sample(0, {0.25, 0.75});
  EXPECT_NEAR(mid.r, 0.5 * (texels[0] + texels[3]), 1e-5);
  // Across the wrap: halfway between the last and the first column.
  const glm::dvec3 seam = set.sample(0, {0.0, 0.75});
  EXPECT_NEAR(seam.r, 0.5 * (texels[0] + texels[9]), 1e-5);
}

TEST(Textures, PrimitivesCarryUvsOnlyWhenTextured) {
  TempDir dir;
  dir.write("t.png", as_string(png(4, 2, test_texels())));
  const SceneData s = load_scene(dir.write("s.json", quad_scene("t.png")));
  const TriangleSoup& t = *s.triangles;
  ASSERT_EQ(t.uvs.size(), 6u);
  // Each corner's uv is its place on the quad: ((x + 1) / 2, (y + 1) / 2).
  for (size_t c = 0; c < 6; ++c) {
    EXPECT_EQ(t.uvs[c].x, (t.positions[c].x + 1) / 2) << c;
    EXPECT_EQ(t.uvs[c].y, (t.positions[c].y + 1) / 2) << c;
  }
  ASSERT_TRUE(s.textures);
  EXPECT_EQ(s.textures->image_of(0), 0);
  // The same scene without the texture keeps no uvs (no memory, no lookups).
  std::string plain = quad_scene("t.png");
  plain.replace(plain.find(R"(, "texture": "t.png")"), std::string(R"(, "texture": "t.png")").size(), "");
  const SceneData p = load_scene(dir.write("p.json", plain));
  EXPECT_TRUE(p.triangles->uvs.empty());
  EXPECT_FALSE(p.textures);
}

TEST(Textures, ObjVtAndMtlMapKd) {
  const std::string repo = std::string(ABCUBE_SOURCE_DIR) + "/scenes/";
  const SceneData s = load_scene(repo + "textured.json");
  ASSERT_TRUE(s.textures);
  const SceneObject& tile = s.objects.back();
  ASSERT_EQ(tile.type, "mesh");
  const uint32_t m = s.triangles->material_id[tile.first_triangle];
  EXPECT_EQ(s.materials[m].texture, fs::path(repo + "textures/checker.png").lexically_normal().string());
  EXPECT_EQ(s.textures->image_of(m), s.textures->image_of(s.triangles->material_id[0]));  // one image, decoded once
  EXPECT_EQ(s.textures->images().size(), 1u);
  // The first face (4/1 3/2 2/3 1/4, ear-clipped) has vt 1..4 = (0,0) (2,0) (2,2) (0,2) at
  // OBJ vertices 4, 3, 2, 1 = (-1,0,1), (1,0,1), (1,0,-1), (-1,0,-1): u = x + 1, v = 1 - z.
  const TriangleSoup& t = *s.triangles;
  for (size_t c = 3 * tile.first_triangle; c < 3 * (tile.first_triangle + 2); ++c) {
    const double x = (t.positions[c].x - 0.2) / 0.5, z = (t.positions[c].z - 1.6) / 0.5;
    EXPECT_NEAR(t.uvs[c].x, x + 1, 1e-6) << c;
    EXPECT_NEAR(t.uvs[c].y, 1 - z, 1e-6) << c;
  }
}

TEST(Textures, EmbeddedImageIsDecodedFromMemory) {
  const std::vector<unsigned char> bytes = png(4, 2, test_texels());
  TempDir dir;
  dir.write("t.png", as_string(bytes));
  const std::string path = dir.write("s.json", quad_scene("t.png"));
  // What a glTF loader leaves: the material naming "#embedded/0", the bytes in the scene.
  const std::string text = quad_scene("t.png");
  const detail::Source src{path, dir.path().string()};
  SceneData scene = load_scene(path);
  const TextureImage from_file = scene.textures->images()[0];
  scene.textures = nullptr;
  scene.materials[0].texture = "#embedded/0";
  scene.embedded_images.push_back(
      {"box.glb: images[0]", "image/png", std::make_shared<const std::vector<unsigned char>>(bytes)});
  LoadLimits limits;
  detail::LoadState st{src, scene, limits, "", {}, {}, -1, {}};
  detail::load_textures(st);
  ASSERT_TRUE(scene.textures);
  EXPECT_EQ(scene.textures->images()[0].rgb, from_file.rgb);
  // A corrupt embedded image names itself.
  (*const_cast<std::vector<unsigned char>*>(scene.embedded_images[0].bytes.get())).resize(20);
  scene.textures = nullptr;
  try {
    detail::load_textures(st);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot decode texture \"box.glb: images[0]\""), std::string::npos)
        << e.what();
  }
}

TEST(Textures, MissingAndCorruptFilesNameTheField) {
  TempDir dir;
  const std::string missing = dir.write("m.json", quad_scene("nothere.png"));
  EXPECT_NE(load_error(missing).find(missing + ": materials.t.texture: cannot read texture"), std::string::npos)
      << load_error(missing);
  EXPECT_NE(load_error(missing).find("no such file"), std::string::npos) << load_error(missing);
  std::string broken = as_string(png(4, 2, test_texels()));
  broken.resize(broken.size() - 30);
  dir.write("broken.png", broken);
  const std::string corrupt = dir.write("c.json", quad_scene("broken.png"));
  EXPECT_NE(load_error(corrupt).find(corrupt + ": materials.t.texture: cannot decode texture \"" +
                                     (dir.path() / "broken.png").string() + "\""),
            std::string::npos)
      << load_error(corrupt);
  dir.write("text.png", "hello");
  const std::string text = dir.write("x.json", quad_scene("text.png"));
  EXPECT_NE(load_error(text).find("materials.t.texture: cannot decode texture"), std::string::npos) << load_error(text);
  // An MTL map_Kd that is missing names the MTL file and line.
  dir.write("tile.mtl", "newmtl a\nKd 1 1 1\n\nmap_Kd gone.png\n");
  dir.write("tile.obj",
            "mtllib tile.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl a\nf 1/1 2/2 3/3\n");
  const std::string mesh = dir.write(
      "o.json",
      R"({"version": 1, "camera": {"position": [0, 0, 3], "look_at": [0, 0, 0]}, "objects": [{"type": "mesh", "file": "tile.obj"}]})");
  EXPECT_NE(load_error(mesh).find(mesh + ": objects[0].file: \"" + (dir.path() / "tile.mtl").string() +
                                  "\":4: map_Kd cannot read texture"),
            std::string::npos)
      << load_error(mesh);
}

}  // namespace
}  // namespace abcube
