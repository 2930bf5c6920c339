// Errors through the public API: each is the exception its kind promises (error.hpp),
// with a message naming the place, never an exit or an abort.
#include <string>

#include <gtest/gtest.h>

#include <abcube/renderer.hpp>

#include "api_test_support.hpp"
#include "base/error.hpp"
#include "tiny_scene.hpp"

namespace abcube::test {
namespace {

// The message of the InputError `fn` throws ("" when it throws none).
template <class Fn>
std::string input_error_of(Fn&& fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ErrorsApi, BadSceneValueNamesItsFieldPath) {
  std::string json = tiny_scene_json(8, 8, 16);
  const std::string radius = "\"radius\": 0.5";
  ASSERT_NE(json.find(radius), std::string::npos);
  json.replace(json.find(radius), radius.size(), "\"radius\": -1");
  const std::string message = input_error_of([&] { Scene::from_json(json, "bad.json"); });
  EXPECT_NE(message.find("objects[2].radius"), std::string::npos) << message;
  EXPECT_NE(message.find("bad.json"), std::string::npos) << message;
}

TEST(ErrorsApi, CameraOverrideFovOutOfRange) {
  const Scene scene = Scene::from_json(tiny_scene_json(8, 8, 16));
  Renderer renderer(RendererOptions{"none", -1, 1});
  RenderOptions o;
  o.camera.fov_y = 200;
  const std::string message = input_error_of([&] { renderer.render(scene, o); });
  EXPECT_NE(message.find("fov_y"), std::string::npos) << message;
}

TEST(ErrorsApi, UnknownMethod) {
  const Scene scene = Scene::from_json(tiny_scene_json(8, 8, 16));
  Renderer renderer(RendererOptions{"none", -1, 1});
  RenderOptions o;
  o.method = "photon";
  const std::string message = input_error_of([&] { renderer.render(scene, o); });
  EXPECT_NE(message.find("photon"), std::string::npos) << message;
}

// A render far longer than its limit stops with RenderTimeout (the cornell box at its own
// 512x512 size, exact tracer at 32 samples per pixel: seconds of work against 1 ns).
TEST(ErrorsApi, TimeoutStopsALongRender) {
  const Scene scene = Scene::load(scene_path("cornell.json"));
  Renderer renderer(RendererOptions{"none", -1, 0});
  RenderOptions o;
  o.method = "raytrace";
  o.timeout_s = 1e-9;
  EXPECT_THROW(renderer.render(scene, o), RenderTimeout);
  // The Renderer is still usable after a timeout.
  const RenderResult r = renderer.render(scene, small_options("raytrace", 8, 8, 16));
  EXPECT_EQ(r.image.width, 8);
}

TEST(ErrorsApi, GpuWithoutGlIsInputError) {
  const Scene scene = Scene::from_json(tiny_scene_json(8, 8, 16));
  Renderer renderer(RendererOptions{"none", -1, 1});
  RenderOptions o;
  o.method = "gpu";
  const std::string message = input_error_of([&] { renderer.render(scene, o); });
  EXPECT_NE(message.find("gpu"), std::string::npos) << message;
}

// A failed internal check throws InternalError naming the check (a host program survives it).
TEST(ErrorsApi, InternalCheckThrowsInsteadOfAborting) {
  const int operand = 3;
  try {
    ABCUBE_CHECK(operand == 4, "operand is " + std::to_string(operand));
    FAIL() << "ABCUBE_CHECK(false) returned";
  } catch (const InternalError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("operand == 4"), std::string::npos) << message;
    EXPECT_NE(message.find("operand is 3"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace abcube::test
