// compare_lists (raster/abuffer_compare.hpp), what `abcube crosscheck` reports of the GPU's
// cube A-buffer against the CPU's: a build against itself is identical, and each kind of
// change made to one fragment is put in its class, counted once, with its place named.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>

#include <gtest/gtest.h>

#include "raster/abuffer.hpp"
#include "raster/abuffer_compare.hpp"
#include "scene/scene_load.hpp"

namespace abcube {
namespace {

CubeABuffer cornell_cube() {
  const SceneData scene = load_scene(std::string(ABCUBE_SOURCE_DIR) + "/scenes/cornell.json");
  return build_cube_abuffer(scene, scene.camera.position, 16);
}

// The first fragment of face 0 that has a neighbour behind it in its list, and where.
Fragment* a_fragment(CubeABuffer* cube, std::string* where) {
  ABuffer& b = cube->faces[0];
  for (int y = 0; y < cube->n; ++y) {
    for (int x = 0; x < cube->n; ++x) {
      const size_t p = static_cast<size_t>(y * cube->n + x);
      if (b.offsets[p + 1] - b.offsets[p] >= 2) {
        *where = "face 0 texel (" + std::to_string(x) + ", " + std::to_string(y) + ") fragment 0";
        return &b.fragments[b.offsets[p]];
      }
    }
  }
  return nullptr;
}

TEST(ListCompare, ABuildAgainstItselfIsIdentical) {
  const CubeABuffer cube = cornell_cube();
  const ListComparison c = compare_lists(cube, cube);
  EXPECT_EQ(c.lists, 6u * 16 * 16);
  EXPECT_EQ(c.lists_identical, c.lists);
  EXPECT_GT(c.fragments, c.lists / 2);
  EXPECT_EQ(c.fragments_identical, c.fragments);
  EXPECT_TRUE(c.within_bounds());
}

TEST(ListCompare, EachChangeLandsInItsClassWithItsPlace) {
  const CubeABuffer cpu = cornell_cube();
  struct Case {
    ListDifference expected;
    void (*change)(Fragment*);
  };
  const Case cases[] = {
      {ListDifference::mask, [](Fragment* f) { f->mask ^= 1u; }},
      {ListDifference::triangle, [](Fragment* f) { f->triangle_and_facing ^= Fragment::BACK_FACE_BIT; }},
      {ListDifference::depth, [](Fragment* f) { f->zmax = f->zmax * 1.001f; }},
      {ListDifference::depth_close, [](Fragment* f) { f->zmin = std::nextafter(f->zmin, 0.0f); }},
      {ListDifference::normal, [](Fragment* f) { f->normal += 5; }},
      {ListDifference::normal_close, [](Fragment* f) { f->normal ^= 1u << 16; }},  // one step in y
  };
  for (const Case& k : cases) {
    CubeABuffer gpu = cpu;
    std::string where;
    Fragment* f = a_fragment(&gpu, &where);
    ASSERT_NE(f, nullptr);
    k.change(f);
    const ListComparison c = compare_lists(cpu, gpu);
    const char* name = list_difference_name(k.expected);
    for (int d = 0; d < LIST_DIFFERENCE_CLASSES; ++d) {
      EXPECT_EQ(c.count[static_cast<size_t>(d)], d == static_cast<int>(k.expected) ? 1u : 0u)
          << name << ": class " << list_difference_name(static_cast<ListDifference>(d));
    }
    EXPECT_EQ(c.example[static_cast<size_t>(k.expected)].rfind(where + ": CPU {", 0), 0u)
        << name << ": " << c.example[static_cast<size_t>(k.expected)];
    EXPECT_EQ(c.lists_identical, c.lists - 1) << name;
    const bool allowed = k.expected == ListDifference::depth_close || k.expected == ListDifference::normal_close;
    EXPECT_EQ(c.within_bounds(), allowed) << name;
  }
  // A fragment missing from one list: the list's length, its fragments not compared.
  CubeABuffer gpu = cpu;
  std::string where;
  Fragment* f = a_fragment(&gpu, &where);
  ASSERT_NE(f, nullptr);
  const size_t at = static_cast<size_t>(f - gpu.faces[0].fragments.data());
  gpu.faces[0].fragments.erase(gpu.faces[0].fragments.begin() + static_cast<std::ptrdiff_t>(at));
  const size_t pixel = static_cast<size_t>(
      std::upper_bound(gpu.faces[0].offsets.begin(), gpu.faces[0].offsets.end(), static_cast<uint32_t>(at)) -
      gpu.faces[0].offsets.begin());
  for (size_t p = pixel; p < gpu.faces[0].offsets.size(); ++p) --gpu.faces[0].offsets[p];
  const ListComparison c = compare_lists(cpu, gpu);
  EXPECT_EQ(c.of(ListDifference::length), 1u);
  EXPECT_EQ(c.example[static_cast<size_t>(ListDifference::length)].find(") fragment "), std::string::npos);
  EXPECT_NE(c.example[static_cast<size_t>(ListDifference::length)].find("CPU "), std::string::npos);
  EXPECT_FALSE(c.within_bounds());
}

}  // namespace
}  // namespace abcube
