// What many renders in one process hold: resident memory and file descriptors stop
// growing after warm-up (bench_soak measures the same over 10000 renders).
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <abcube/renderer.hpp>

#include "process_usage.hpp"
#include "tiny_scene.hpp"

namespace abcube::test {
namespace {

// 300 renders through one Renderer, every method cycled (gpu where GL works): from render
// 50 to 300 the resident memory grows by at most 8 MB and no descriptor stays open.
TEST(ResourcesApi, ThreeHundredRendersHoldNoMore) {
  const std::string json = tiny_scene_json(32, 24, 32);
  Scene scene = Scene::from_json(json, "tiny");
  Renderer renderer;
  std::vector<std::string> methods{"abuffer", "zbuffer", "envmap", "raytrace"};
  RenderOptions gpu;
  gpu.method = "gpu";
  try {
    renderer.render(scene, gpu);
    methods.push_back("gpu");
  } catch (const RuntimeFailure& e) {
    std::printf("no GL here (%s): gpu left out\n", e.what());
  }
  uint64_t rss_at_50 = 0;
  int fds_at_50 = 0;
  for (int i = 0; i < 300; ++i) {
    if (i == 50) {
      rss_at_50 = resident_bytes();
      fds_at_50 = open_descriptors();
    }
    if (i % 100 == 99) scene = Scene::from_json(json, "tiny");  // scenes come and go too
    RenderOptions o;
    o.method = methods[static_cast<size_t>(i) % methods.size()];
    o.camera.position = std::array<double, 3>{0.01 * i, 1.2, 3.0};
    const RenderResult r = renderer.render(scene, o);
    ASSERT_EQ(r.image.width, 32) << "render " << i;
  }
  const uint64_t rss = resident_bytes();
  const int fds = open_descriptors();
  ASSERT_GT(rss_at_50, 0u) << "no /proc/self/status";
  const double growth_mb = (static_cast<double>(rss) - static_cast<double>(rss_at_50)) / (1024.0 * 1024.0);
  std::printf("RSS %+.2f MB, descriptors %+d from render 50 to 300\n", growth_mb, fds - fds_at_50);
#if defined(__SANITIZE_ADDRESS__)
  // AddressSanitizer keeps freed blocks in quarantine (256 MB) to catch their later use,
  // so the resident memory says nothing here; LeakSanitizer checks for leaks at exit instead.
  std::printf("AddressSanitizer build: RSS growth not checked\n");
#else
  EXPECT_LE(growth_mb, 8.0);
#endif
  EXPECT_EQ(fds, fds_at_50);
}

}  // namespace
}  // namespace abcube::test
