// THE RESOLVE PLAN made on the GPU (host/gl/gl_resolve_plan.hpp) against pack_under_mask
// (cpu_core/shading/resolve.hpp): on the repository's scenes and the hard cases kept as
// regressions, under both rules for intersecting fragments, with their materials as they are
// and made half transparent, the resolve that runs the plan calls the shader with the same
// fragments and masks in the same order, and gives the same image bit for bit. A plan whose
// loops run out leaves its pixels to pack, with the same image again.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/error.hpp"
#include "gl/gl_resolve_plan.hpp"
#include "gl_test_support.hpp"
#include "raster/abuffer.hpp"
#include "scene/scene_load.hpp"
#include "shading/resolve.hpp"

namespace abcube {
namespace {

// Each call the resolve makes, in order (one thread).
struct Call {
  int x, y;
  uint32_t id;
  CoverageMask mask;
  bool operator==(const Call& o) const { return x == o.x && y == o.y && id == o.id && mask == o.mask; }
};

Image resolve_recorded(const ABuffer& camera, const SceneData& scene, const ResolvePlan* plan, bool exact,
                       std::vector<Call>* calls) {
  ResolveOptions ro;
  ro.threads = 1;
  ro.exact_priority = exact;
  ro.plan = plan;
  const PixelShader shade = [&](const Fragment& f, int x, int y) {
    calls->push_back({x, y, f.triangle_and_facing, f.mask});
    return probe_shade(scene, f, x, y);
  };
  return resolve_image(camera, *scene.triangles, shade, scene.background, ro);
}

// The plan's figures, after holding its resolve to pack's.
ResolvePlanStats expect_plan_resolves_as_pack(const GlResolvePlanner& planner, const SceneData& scene,
                                              const ResolvePlanOptions& o, const std::string& what) {
  const ABuffer camera = build_camera_abuffer(scene);
  const bool exact = o.exact_priority;
  ResolvePlanStats stats;
  const ResolvePlan plan = planner.plan(camera, scene, o, &stats);
  std::vector<Call> by_pack, by_plan;
  const Image a = resolve_recorded(camera, scene, nullptr, exact, &by_pack);
  const Image b = resolve_recorded(camera, scene, &plan, exact, &by_plan);
  EXPECT_EQ(a.data.size(), b.data.size()) << what;
  size_t differ = 0;
  for (size_t k = 0; k < a.data.size(); ++k) differ += std::memcmp(&a.data[k], &b.data[k], sizeof(float)) != 0;
  EXPECT_EQ(differ, 0u) << what << ": image values differing";
  EXPECT_EQ(by_pack.size(), by_plan.size()) << what << ": shader calls";
  for (size_t k = 0; k < std::min(by_pack.size(), by_plan.size()); ++k) {
    if (!(by_pack[k] == by_plan[k])) {
      ADD_FAILURE() << what << ": call " << k << " at pixel (" << by_pack[k].x << ", " << by_pack[k].y << ") differs";
      break;
    }
  }
  EXPECT_EQ(stats.pixels, camera.view.pixel_count()) << what;
  if (o.loop_budget >= GPU_RESOLVE_LOOP_BUDGET && !o.only) EXPECT_EQ(stats.planned, stats.pixels) << what;
  return stats;
}

ResolvePlanOptions rule(bool exact, uint32_t loop_budget = GPU_RESOLVE_LOOP_BUDGET) {
  ResolvePlanOptions o;
  o.exact_priority = exact;
  o.loop_budget = loop_budget;
  return o;
}

// The first kept scene at width x height.
SceneData first_scene(int width, int height) {
  SceneData scene = load_scene(test::scene_files().front());
  scene.camera.width = width;
  scene.camera.height = height;
  return scene;
}

TEST(ResolvePlanGl, StepsAreTheCpuResolvesOnEveryKeptScene) {
  test::test_context();
  const GlResolvePlanner planner;
  const std::vector<std::string> files = test::scene_files();
  ASSERT_GE(files.size(), test::checked_build() ? 5u : 15u);
  for (const std::string& file : files) {
    SceneData scene = load_scene(file);
    scene.camera.width = 48;
    scene.camera.height = 36;
    for (const bool exact : {true, false}) {
      const std::string what = file + (exact ? " (exact priority)" : " (Vis estimate)");
      expect_plan_resolves_as_pack(planner, scene, rule(exact), what);
      SceneData half = scene;
      for (size_t m = 0; m < half.materials.size(); ++m) half.materials[m].opacity = m % 2 ? 1.0 : 0.5;
      expect_plan_resolves_as_pack(planner, half, rule(exact), what + ", half transparent");
    }
  }
}

// A budget that runs out at the first pixel of any depth leaves those pixels to pack.
TEST(ResolvePlanGl, PixelsPastTheLoopBudgetAreLeftToPack) {
  test::test_context();
  const GlResolvePlanner planner;
  SceneData scene = first_scene(32, 24);
  for (Material& m : scene.materials) m.opacity = 0.5;
  const ResolvePlanStats stats = expect_plan_resolves_as_pack(planner, scene, rule(true, 6), "budget 6");
  EXPECT_LT(stats.planned, stats.pixels);
  EXPECT_GT(stats.planned, 0u);
}

// Fill dispatches of a few steps each (a pixel's steps never split): the same plan in many
// bands as in one, each band's steps at their place.
TEST(ResolvePlanGl, StepsFilledInManyBandsAreThoseOfOne) {
  test::test_context();
  const GlResolvePlanner planner;
  SceneData scene = first_scene(32, 24);
  for (size_t m = 0; m < scene.materials.size(); ++m) scene.materials[m].opacity = m % 2 ? 1.0 : 0.5;
  for (const uint64_t band : {1u, 7u}) {
    ResolvePlanOptions o = rule(true);
    o.band_steps = band;
    expect_plan_resolves_as_pack(planner, scene, o, "bands of " + std::to_string(band) + " steps");
  }
}

// A plan of the pixels `only` marks (hybrid's CPU part) plans those alone; a resolve of every
// pixel by it gives pack's image, the others resolved by pack.
TEST(ResolvePlanGl, OnlyTheMarkedPixelsArePlanned) {
  test::test_context();
  const GlResolvePlanner planner;
  SceneData scene = first_scene(32, 24);
  for (size_t m = 0; m < scene.materials.size(); ++m) scene.materials[m].opacity = m % 2 ? 1.0 : 0.5;
  std::vector<uint8_t> only(32 * 24, 0);
  for (size_t p = 0; p < only.size(); ++p) only[p] = (p % 32 + p / 32) % 3 == 0;
  ResolvePlanOptions o = rule(true);
  o.only = &only;
  const ResolvePlanStats stats = expect_plan_resolves_as_pack(planner, scene, o, "a third of the pixels");
  EXPECT_EQ(stats.planned, static_cast<uint64_t>(std::count(only.begin(), only.end(), 1)));
  const ABuffer camera = build_camera_abuffer(scene);
  const ResolvePlan plan = planner.plan(camera, scene, o);
  for (size_t p = 0; p < only.size(); ++p) {
    ASSERT_EQ(plan.planned[p] != 0, only[p] != 0) << "pixel " << p;
    if (!only[p]) ASSERT_EQ(plan.offsets[p + 1], plan.offsets[p]) << "pixel " << p;
  }
}

// THE PROBE agrees on this GL; the comparison it makes sees a step over another mask, and a
// weight moved by a ten-thousandth.
TEST(ResolvePlanGl, TheProbeAgreesHereAndSeesAPlanOff) {
  test::test_context();
  const GlResolvePlanner planner;
  double ms = -1;
  EXPECT_EQ(planner.probe(&ms), "");
  EXPECT_GE(ms, 0.0);
  SceneData scene = first_scene(24, 18);
  for (size_t m = 0; m < scene.materials.size(); ++m) scene.materials[m].opacity = m % 2 ? 1.0 : 0.5;
  const ABuffer camera = build_camera_abuffer(scene);
  const ResolvePlan plan = planner.plan(camera, scene);
  EXPECT_EQ(plan_differs_from_pack(camera, scene, plan), "");
  size_t weighted = 0, masked = 0, tried = 0;
  for (size_t k = 0; k < plan.steps.size(); ++k) {
    const ResolveStep& s = plan.steps[k];
    if (s.kind == ResolveStep::add && s.weight[0] > 0.1 && tried < 8) {
      ++tried;
      ResolvePlan off = plan;
      off.steps[k].weight[0] *= 1.0 + 1e-4;
      weighted += !plan_differs_from_pack(camera, scene, off).empty();
      off = plan;
      off.steps[k].mask[0] = s.mask[0] == 0 ? 1u : s.mask[0] & (s.mask[0] - 1);  // the shade over fewer samples
      masked += !plan_differs_from_pack(camera, scene, off).empty();
    }
  }
  ASSERT_EQ(tried, 8u);
  EXPECT_EQ(weighted, tried);
  EXPECT_EQ(masked, tried);
}

// A plan whose steps break their rules (a step of no fragment, a second fragment where only
// add_two takes one, a fragment past the list, a kind of none) is refused, never read.
TEST(ResolvePlanGl, StepsThatBreakTheirRulesAreRefused) {
  test::test_context();
  const GlResolvePlanner planner;
  const SceneData scene = first_scene(16, 12);
  const ABuffer camera = build_camera_abuffer(scene);
  const ResolvePlan good = planner.plan(camera, scene);
  ASSERT_FALSE(good.steps.empty());
  const PixelShader shade = [&](const Fragment& f, int x, int y) { return probe_shade(scene, f, x, y); };
  ResolveOptions ro;
  ro.plan = &good;
  EXPECT_NO_THROW(resolve_image(camera, *scene.triangles, shade, scene.background, ro));
  const auto first_of = [&](uint32_t kind) {
    return std::find_if(good.steps.begin(), good.steps.end(), [&](const ResolveStep& s) { return s.kind == kind; }) -
           good.steps.begin();
  };
  const std::vector<std::function<void(ResolveStep&)>> breaks = {
      [](ResolveStep& s) { s.at[0] = ResolveStep::NONE; },
      [](ResolveStep& s) { s.at[1] = s.at[0]; },
      [](ResolveStep& s) { s.at[0] = 1u << 30; },
      [](ResolveStep& s) { s.kind = 7; },
  };
  for (const uint32_t kind : {ResolveStep::shade, ResolveStep::add}) {
    const size_t at = static_cast<size_t>(first_of(kind));
    ASSERT_LT(at, good.steps.size()) << "no step of kind " << kind;
    for (size_t b = 0; b < breaks.size(); ++b) {
      ResolvePlan bad = good;
      breaks[b](bad.steps[at]);
      ro.plan = &bad;
      EXPECT_THROW(resolve_image(camera, *scene.triangles, shade, scene.background, ro), std::logic_error)
          << "kind " << kind << ", break " << b;
    }
  }
}

TEST(ResolvePlanGl, RefusesAPlanOverItsBudgetAndAPlanOfAnotherBuffer) {
  test::test_context();
  const GlResolvePlanner planner;
  const SceneData scene = first_scene(32, 24);
  const ABuffer camera = build_camera_abuffer(scene);
  ResolvePlanOptions o;
  o.max_bytes = 1024;
  EXPECT_THROW(planner.plan(camera, scene, o), InputError);
  const ResolvePlan plan = planner.plan(camera, scene);
  ResolveOptions ro;
  ro.plan = &plan;
  ro.exact_priority = false;  // planned with exact priority
  const PixelShader shade = [&](const Fragment& f, int x, int y) { return probe_shade(scene, f, x, y); };
  EXPECT_THROW(resolve_image(camera, *scene.triangles, shade, scene.background, ro), InputError);
}

}  // namespace
}  // namespace abcube
