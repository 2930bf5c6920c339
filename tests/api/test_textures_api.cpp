// Base-colour textures through the library (docs/models-and-textures.md): the tracer and the
// A-buffer map methods show the same texture, and every image is the same for any
// thread count.
#include <gtest/gtest.h>

#include <abcube/image.hpp>
#include <abcube/renderer.hpp>

#include "api_test_support.hpp"

namespace abcube::test {
namespace {

TEST(TexturesApi, TracerAndABufferAgreeOnATexturedScene) {
  const Scene scene = Scene::load(scene_path("textured.json"));
  Renderer renderer(RendererOptions{"none", -1, 2});
  const Image traced = renderer.render(scene, small_options("raytrace", 96, 72, 128)).image;
  const Image abuffer = renderer.render(scene, small_options("abuffer", 96, 72, 128)).image;
  EXPECT_GE(image_error(abuffer, traced).psnr, 40.0);
  // The texture is seen: without it (one colour per material) the image is far from it.
  const Scene plain = Scene::from_json(R"({"version": 1, "camera": {"position": [0, 2.6, 5.5], "look_at": [0, 0.5, 0],
      "fov_y": 45, "width": 96, "height": 72}, "background": [0.03, 0.03, 0.05], "ambient": [0.15, 0.15, 0.15],
      "lights": [{"type": "point", "position": [-3, 5, 3], "color": [0.9, 0.85, 0.8]}],
      "materials": {"floor": {"color": [1, 1, 1]}},
      "objects": [{"type": "quad", "vertices": [[-4, 0, 4], [4, 0, 4], [4, 0, -4], [-4, 0, -4]], "material": "floor"}]})",
                                       "plain.json");
  EXPECT_LT(image_error(renderer.render(plain, small_options("raytrace", 96, 72, 128)).image, traced).psnr, 25.0);
}

TEST(TexturesApi, ImagesIdenticalForAnyThreadCount) {
  const Scene scene = Scene::load(scene_path("textured.json"));
  for (const char* method : {"raytrace", "abuffer", "zbuffer", "envmap"}) {
    Renderer one(RendererOptions{"none", -1, 1}), three(RendererOptions{"none", -1, 3});
    const RenderOptions o = small_options(method, 40, 30, 64);
    EXPECT_TRUE(images_equal(one.render(scene, o).image, three.render(scene, o).image)) << method;
  }
}

}  // namespace
}  // namespace abcube::test
