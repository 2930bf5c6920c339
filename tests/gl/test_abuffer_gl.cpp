// The cube A-buffer built by GL compute shaders (host/gl/gl_abuffer.hpp) against the CPU
// core's (raster/abuffer.hpp): the same lists, fragment for fragment and bit for bit (masks,
// triangles and facing, depths rounded outward, encoded normals), on the repository's scenes
// and the hard cases kept as regressions, and the same cap, merge switch and budget refusal.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "base/error.hpp"
#include "gl/gl_abuffer.hpp"
#include "gl_test_support.hpp"
#include "raster/abuffer.hpp"
#include "raster/abuffer_compare.hpp"
#include "scene/scene_load.hpp"

namespace abcube {
namespace {

// Every list and fragment identical (compare_lists), else each class of difference with its
// count and first example.
void expect_same_lists(const CubeABuffer& cpu, const CubeABuffer& gpu, const std::string& what) {
  const ListComparison c = compare_lists(cpu, gpu);
  for (int k = 0; k < LIST_DIFFERENCE_CLASSES; ++k) {
    EXPECT_EQ(c.count[static_cast<size_t>(k)], 0u)
        << what << ": " << list_difference_name(static_cast<ListDifference>(k)) << ", first at "
        << c.example[static_cast<size_t>(k)];
  }
  EXPECT_EQ(c.lists_identical, c.lists) << what;
  EXPECT_EQ(c.fragments_identical, c.fragments) << what;
  EXPECT_GT(c.fragments, 0u) << what;
}

// The counters both builds keep alike.
void expect_same_stats(const ABufferStats& cs, const ABufferStats& gs, const std::string& what) {
  EXPECT_EQ(cs.raw_fragments, gs.raw_fragments) << what;
  EXPECT_EQ(cs.fragments, gs.fragments) << what;
  EXPECT_EQ(cs.max_list_length, gs.max_list_length) << what;
  EXPECT_EQ(cs.triangle_views, gs.triangle_views) << what;
  EXPECT_EQ(cs.triangles_clipped, gs.triangles_clipped) << what;
  EXPECT_EQ(cs.triangles_culled, gs.triangles_culled) << what;
  EXPECT_EQ(cs.triangles_degenerate, gs.triangles_degenerate) << what;
  EXPECT_EQ(cs.triangles_edge_on, gs.triangles_edge_on) << what;
}

// Every repository scene and kept hard case, from its camera and from a point off it, at two
// resolutions: near-clipped triangles (camera_inside, a light on a surface), coplanar ties,
// nested glass, thin features, kilometre scales. One builder serves every build.
TEST(AbufferGl, ListsAreTheCpuCoresOnEveryKeptScene) {
  test::test_context();
  const GlABufferBuilder builder;
  const std::vector<std::string> files = test::scene_files();
  ASSERT_GE(files.size(), test::checked_build() ? 5u : 15u);
  for (const std::string& file : files) {
    const SceneData scene = load_scene(file);
    for (const auto& [centre, n] : test::cube_views(scene)) {
      ABufferStats cs, gs;
      const CubeABuffer cpu = build_cube_abuffer(scene, centre, n, {}, &cs);
      const CubeABuffer gpu = builder.cube(scene, centre, n, {}, &gs);
      const std::string what = std::filesystem::path(file).filename().string() + " at N = " + std::to_string(n);
      expect_same_lists(cpu, gpu, what);
      expect_same_stats(cs, gs, what);
    }
  }
}

// The camera's A-buffer at `width` x `height`: every list the CPU core's, bit for bit.
void expect_camera_lists(const GlABufferBuilder& builder, SceneData scene, int width, int height,
                         const std::string& what) {
  scene.camera.width = width;
  scene.camera.height = height;
  ABufferStats cs, gs;
  const ABuffer cpu = build_camera_abuffer(scene, {}, &cs);
  const ABuffer gpu = builder.camera(scene, {}, &gs);
  const ListComparison c = compare_lists(cpu, gpu);
  EXPECT_TRUE(c.within_bounds() && c.of(ListDifference::depth_close) == 0 && c.of(ListDifference::normal_close) == 0)
      << what << ": " << c.lists - c.lists_identical << " lists differ";
  EXPECT_EQ(c.lists, static_cast<uint64_t>(width) * static_cast<uint64_t>(height)) << what;
  EXPECT_EQ(c.lists_identical, c.lists) << what;
  expect_same_stats(cs, gs, what);
}

// The camera's A-buffer on the same scenes and on the repository's models (a hundred
// thousand triangles, lists of hundreds of fragments: longer than the GPU finishes, so the
// CPU's finish takes them), at an odd size whose rows are not the cube's squares; and
// cornell larger, where a wall's pixels span many tiles of the count and fill passes, the
// last ones cut.
TEST(AbufferGl, CameraListsAreTheCpuCoresOnEveryKeptScene) {
  test::test_context();
  const GlABufferBuilder builder;
  std::vector<std::string> files = test::scene_files();
  for (const auto& e : std::filesystem::directory_iterator(std::string(ABCUBE_SOURCE_DIR) + "/scenes/models")) {
    if (e.path().extension() == ".json") files.push_back(e.path().string());
  }
  for (const std::string& file : files) {
    expect_camera_lists(builder, load_scene(file), 61, 37, std::filesystem::path(file).filename().string());
  }
  const SceneData cornell = load_scene(std::string(ABCUBE_SOURCE_DIR) + "/scenes/cornell.json");
  expect_camera_lists(builder, cornell, 257, 193, "cornell at 257 x 193");
}

// The options that change the lists: no merging, and a cap on the layers (the dropped
// fragments counted alike).
TEST(AbufferGl, CapAndMergeSwitchAsTheCpuCore) {
  test::test_context();
  const SceneData scene = load_scene(std::string(ABCUBE_SOURCE_DIR) + "/scenes/cornell.json");
  ABufferOptions unmerged;
  unmerged.merge = false;
  ABufferOptions capped;
  capped.max_layers = 2;
  for (const ABufferOptions& o : {unmerged, capped}) {
    ABufferStats cs, gs;
    const CubeABuffer cpu = build_cube_abuffer(scene, scene.camera.position, 32, o, &cs);
    const CubeABuffer gpu = build_cube_abuffer_gl(scene, scene.camera.position, 32, o, &gs);
    expect_same_lists(cpu, gpu, o.merge ? "capped" : "unmerged");
    EXPECT_EQ(cs.dropped_by_cap, gs.dropped_by_cap);
    EXPECT_EQ(cs.fragments, gs.fragments);
  }
  EXPECT_GT(build_cube_abuffer_gl(scene, scene.camera.position, 32, unmerged).faces[0].fragments.size(),
            build_cube_abuffer_gl(scene, scene.camera.position, 32).faces[0].fragments.size());
}

// Above --max-memory the build is refused before the fragments are allocated, naming its
// need; bad arguments are refused as the CPU core refuses them.
TEST(AbufferGl, RefusesAboveTheBudgetAndBadArguments) {
  test::test_context();
  const SceneData scene = load_scene(std::string(ABCUBE_SOURCE_DIR) + "/scenes/cornell.json");
  ABufferOptions small;
  small.max_memory_bytes = 1 << 20;
  try {
    build_cube_abuffer_gl(scene, scene.camera.position, 256, small);
    FAIL() << "a 256 cube under 1 MiB was built";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cube A-buffer (GPU) needs"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--max-memory 1 MiB"), std::string::npos) << e.what();
  }
  SceneData wide = scene;
  wide.camera.width = 1024;
  wide.camera.height = 768;
  try {
    GlABufferBuilder().camera(wide, small);
    FAIL() << "a 1024 x 768 camera A-buffer under 1 MiB was built";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("camera A-buffer (GPU) needs"), std::string::npos) << e.what();
  }
  EXPECT_THROW(build_cube_abuffer_gl(scene, scene.camera.position, 0), InputError);
  EXPECT_THROW(build_cube_abuffer_gl(scene, glm::dvec3(NAN, 0, 0), 8), InputError);
}

}  // namespace
}  // namespace abcube
