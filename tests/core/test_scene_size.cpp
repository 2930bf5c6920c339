// The memory estimate of a render (cpu_core/scene/scene_size.cpp) and its budget.
#include "scene_load_fixtures.hpp"

namespace abcube {
namespace {

using namespace scene_test;

// ---- Memory estimate -------------------------------------------------------------------

TEST(SceneLoadMemory, EstimateAndBudget) {
  SceneText text;
  text.render = R"({"cube_resolution": 100})";
  const SceneData s = load_text(text.str());
  const uint64_t bytes = estimate_render_bytes(s, false);
  // 64x48 pixels, 6 faces of 100x100 texels, 960 triangles at no less than the peak
  // bytes a triangle measured by bench/memory.py (168, bench/results/memory.txt).
  EXPECT_GT(bytes, 64u * 48 * 12 + 6u * 100 * 100 * 4 + 960u * 168);
  EXPECT_LT(bytes, uint64_t{64} << 20);
  EXPECT_NO_THROW(check_render_size(s, false, bytes, true));
  for (const bool capped : {true, false}) {
    try {
      check_render_size(s, false, bytes - 1, capped);
      FAIL() << "no error";
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind("scene.json: render: estimated ", 0), 0u) << m;
      EXPECT_NE(m.find("for 64x48, cube 100 and 960 triangles"), std::string::npos) << m;
      EXPECT_NE(m.find(capped ? "above --max-memory " : "of memory available"), std::string::npos) << m;
    }
  }
  // A method that draws with GL counts the GL's copy of the soup too, at its largest (positions and
  // normals 72 bytes a triangle, the soup's ids 8, each vertex's ids 24: a GL that neither
  // pins the soup nor reads ids per triangle) and what llvmpipe holds while drawing (about 90).
  SceneData gpu = s;
  // and a cube shadow map of N x N floats per shadow-casting light (the scene has one),
  // and its shadow volumes (two at most, opaque and translucent blockers): a cap's code on
  // the CPU and in the GL and 8 bytes of runs a triangle each; the side pairing's bucket byte
  // a corner, and its edges of 32 bytes (3 a triangle, at most 2^20 of them).
  ASSERT_EQ(gpu.lights.size(), 1u);
  const uint64_t volume = 2 * (2 + 8);
  const uint64_t pairing = 960u * 3 * 32;
  EXPECT_EQ(estimate_render_bytes(gpu, true), bytes + 960u * (104 + 90 + volume + 3) + pairing + 6u * 100 * 100 * 4);
  gpu.lights.push_back(gpu.lights.front());
  EXPECT_EQ(estimate_render_bytes(gpu, true),
            bytes + 960u * (104 + 90 + 2 * volume + 3) + pairing + 2 * 6u * 100 * 100 * 4);
  gpu.lights.back().cast_shadows = false;
  EXPECT_EQ(estimate_render_bytes(gpu, true), bytes + 960u * (104 + 90 + volume + 3) + pairing + 6u * 100 * 100 * 4);
  gpu.lights.front().cast_shadows = false;  // no shadows: no volumes, no maps
  EXPECT_EQ(estimate_render_bytes(gpu, true), bytes + 960u * (104 + 90));
  // A huge cube map is refused by its estimate, not by an allocation failure.
  text.render = R"({"cube_resolution": 16384})";
  EXPECT_GT(estimate_render_bytes(load_text(text.str()), false), uint64_t{6} * 16384 * 16384 * 32);
}

}  // namespace
}  // namespace abcube
