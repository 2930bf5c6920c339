// The Renderer through the public API: per-scene data reused across views, Renderers on
// several threads, Renderers created and destroyed in a row (GL re-creation).
#include <condition_variable>
#include <mutex>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <abcube/renderer.hpp>

#include "api_test_support.hpp"

namespace abcube::test {
namespace {

// Two views of one scene in one process: the first render builds the per-scene data, the
// second reuses it (0 built), and the two cameras give two images.
TEST(RendererApi, SecondViewReusesSceneData) {
  const Scene scene = Scene::load(scene_path("cornell.json"));
  Renderer renderer;
  RenderOptions o = small_options("abuffer", 40, 30, 64);
  const RenderResult first = renderer.render(scene, o);
  o.camera.position = std::array<double, 3>{0.3, 1.2, 2.0};
  const RenderResult second = renderer.render(scene, o);

  const nlohmann::json s1 = nlohmann::json::parse(first.stats.json), s2 = nlohmann::json::parse(second.stats.json);
  EXPECT_GE(s1["scene_data"]["built_by_this_render"].get<int>(), 1) << first.stats.json;
  EXPECT_GE(s1["scene_data"]["mesh_neighbours"]["built"].get<int>(), 1);
  EXPECT_EQ(s2["scene_data"]["built_by_this_render"].get<int>(), 0) << second.stats.json;
  EXPECT_EQ(first.stats.scene_data_built, s1["scene_data"]["built_by_this_render"].get<int>());
  EXPECT_EQ(second.stats.scene_data_built, 0);
  ASSERT_EQ(first.image.width, 40);
  ASSERT_EQ(first.image.height, 30);
  EXPECT_FALSE(images_equal(first.image, second.image)) << "two cameras gave the same image";
  EXPECT_EQ(renderer.renders(), 2u);
}

// The same scene from two Renderers on two threads at once: each image is the one
// rendered alone, to the last bit.
TEST(RendererApi, TwoThreadsGiveTheImagesRenderedAlone) {
  const Scene scene = Scene::load(scene_path("cornell.json"));
  const RenderOptions a_options = small_options("abuffer", 48, 36, 64);
  const RenderOptions r_options = small_options("raytrace", 48, 36, 64);
  Image alone_a, alone_r;
  {
    Renderer renderer;
    alone_a = renderer.render(scene, a_options).image;
    alone_r = renderer.render(scene, r_options).image;
  }
  const Scene fresh = Scene::load(scene_path("cornell.json"));  // per-scene data built during the race
  Image together_a, together_r;
  std::string error_a, error_r;
  auto render_on_thread = [&fresh](const RenderOptions& o, Image* out, std::string* error) {
    try {
      Renderer renderer(RendererOptions{"none", -1, 2});
      *out = renderer.render(fresh, o).image;
    } catch (const std::exception& e) {
      *error = e.what();
    }
  };
  std::thread ta(render_on_thread, a_options, &together_a, &error_a);
  std::thread tr(render_on_thread, r_options, &together_r, &error_r);
  ta.join();
  tr.join();
  ASSERT_EQ(error_a, "");
  ASSERT_EQ(error_r, "");
  EXPECT_TRUE(images_equal(together_a, alone_a));
  EXPECT_TRUE(images_equal(together_r, alone_r));
}

// 100 Renderers created and destroyed in a row, each opening EGL and rendering one gpu
// image: every image equals the first (the re-creation that fails in pyrender).
TEST(RendererApi, HundredEglRenderersInARow) {
  const Scene scene = Scene::load(scene_path("default.json"));
  const RenderOptions o = small_options("gpu", 16, 12, 16);
  Image first;
  try {
    Renderer renderer(RendererOptions{"egl", -1, 0});
    first = renderer.render(scene, o).image;
  } catch (const RuntimeFailure& e) {
    GTEST_SKIP() << "no EGL path works here: " << e.what();
  }
  ASSERT_EQ(first.width, 16);
  double sum = 0;
  for (float v : first.data) sum += v;
  ASSERT_GT(sum, 0.0) << "the first gpu image is black";
  for (int i = 1; i < 100; ++i) {
    Renderer renderer(RendererOptions{"egl", -1, 0});
    const RenderResult r = renderer.render(scene, o);
    ASSERT_TRUE(images_equal(r.image, first)) << "Renderer " << i;
    ASSERT_NE(renderer.gl_path(), "none");
  }
}

// A GL Renderer on one thread keeps working while another thread's GL Renderer, on the same
// EGL display, is created, renders and is destroyed (the display is shared; one Renderer's
// end must not take it down for the other).
TEST(RendererApi, GlRenderersOnTwoThreadsOutliveEachOther) {
  const Scene scene = Scene::load(scene_path("default.json"));
  const RenderOptions o = small_options("gpu", 16, 12, 16);
  Image first, second, other;
  std::string error;
  std::mutex m;
  std::condition_variable cv;
  int stage = 0;  // 1: first rendered; 2: the other thread's Renderer is gone
  std::thread a([&] {
    try {
      Renderer renderer(RendererOptions{"egl", -1, 0});
      first = renderer.render(scene, o).image;
      {
        std::unique_lock<std::mutex> lock(m);
        stage = 1;
        cv.notify_all();
        cv.wait(lock, [&] { return stage == 2; });
      }
      second = renderer.render(scene, o).image;
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(m);
      error = e.what();
      stage = 2;
      cv.notify_all();
    }
  });
  std::thread b([&] {
    {
      std::unique_lock<std::mutex> lock(m);
      cv.wait(lock, [&] { return stage >= 1; });
    }
    try {
      Renderer renderer(RendererOptions{"egl", -1, 0});
      other = renderer.render(scene, o).image;
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(m);
      if (error.empty()) error = e.what();
    }
    std::lock_guard<std::mutex> lock(m);
    stage = 2;
    cv.notify_all();
  });
  a.join();
  b.join();
  if (error.find("no GL path") != std::string::npos || error.find("EGL") != std::string::npos) {
    GTEST_SKIP() << "no EGL path works here: " << error;
  }
  ASSERT_EQ(error, "");
  EXPECT_TRUE(images_equal(first, other));
  EXPECT_TRUE(images_equal(first, second)) << "the first Renderer broke when the other one was destroyed";
}

}  // namespace
}  // namespace abcube::test
