// --target-db (render/target_db.hpp): the pilots' sample, the plan the stats report being
// the plan rendered, the target reached against the exact tracer, and the options that
// contradict it refused.
#include <limits>
#include <set>
#include <utility>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <abcube/renderer.hpp>

#include "api_test_support.hpp"
#include "render/target_db.hpp"

namespace abcube::test {
namespace {

using nlohmann::json;

// One pixel in every b x b block, the partial blocks at the right and bottom edges too,
// and the same pixels every time.
TEST(TargetDb, PilotPixelsAreOnePerBlock) {
  for (const auto& [w, h] : {std::pair{640, 480}, std::pair{97, 61}, std::pair{1, 1}, std::pair{3000, 7}}) {
    int block = 0;
    const std::vector<uint8_t> only = pilot_pixels(w, h, &block);
    ASSERT_EQ(only.size(), static_cast<size_t>(w) * static_cast<size_t>(h));
    EXPECT_GE(block, 2);
    EXPECT_LE(block, 8);
    std::vector<int> per_block(static_cast<size_t>((w + block - 1) / block) *
                               static_cast<size_t>((h + block - 1) / block));
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        if (only[static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x)]) {
          ++per_block[static_cast<size_t>(y / block) * static_cast<size_t>((w + block - 1) / block) +
                      static_cast<size_t>(x / block)];
        }
      }
    }
    for (const int n : per_block) ASSERT_EQ(n, 1) << w << "x" << h << " block " << block;
    int again = 0;
    EXPECT_EQ(pilot_pixels(w, h, &again), only);
  }
  int block = 0;
  pilot_pixels(640, 480, &block);
  EXPECT_EQ(block, 8);  // about 4096 pixels of 307200
  pilot_pixels(64, 48, &block);
  EXPECT_EQ(block, 2);  // at least one pixel in four
}

TEST(TargetDb, LadderClimbsToTheScenesOwnN) {
  EXPECT_EQ(target_ladder(512), (std::vector<int>{64, 96, 128, 192, 256, 384, 512, 768, 1024}));
  EXPECT_EQ(target_ladder(2000).back(), 2000);
  EXPECT_EQ(target_ladder(1536).back(), 1536);
}

// abuffer on cornell.json at width x height with --target-db `target`, stats kept.
RenderOptions target_options(int width, int height, double target) {
  RenderOptions o = small_options("abuffer", width, height, 0);
  o.target_db = target;
  o.stats = true;
  return o;
}

// `scene` rendered so, measured against the exact tracer (stats.psnr_db).
RenderResult render_measured(const Scene& scene, int width, int height, double target) {
  RenderOptions o = target_options(width, height, target);
  o.reference = true;
  return Renderer().render(scene, o);
}

// The N and the shading points the stats report give, rendered directly, the very image
// --target-db rendered; that image reaches the target against the exact tracer; every
// pilot is in the stats.
TEST(TargetDb, TheChosenPlanIsTheImageAndReachesTheTarget) {
  const Scene scene = Scene::load(scene_path("cornell.json"));
  const RenderResult r = render_measured(scene, 96, 72, 36);
  const json s = json::parse(r.stats.json);
  ASSERT_TRUE(s.contains("target_db")) << r.stats.json;
  const json& t = s["target_db"];
  EXPECT_EQ(t["target"].get<double>(), 36.0);
  EXPECT_TRUE(t["reached"].get<bool>()) << t.dump(1);
  const int n = t["cube_resolution"].get<int>();
  EXPECT_EQ(s["size"]["cube_resolution"].get<int>(), n);
  EXPECT_EQ(t["scene_cube_resolution"].get<int>(), scene.cube_resolution());
  ASSERT_GE(t["pilots"].size(), 1u);
  std::set<int> tried;
  for (const json& p : t["pilots"]) tried.insert(p["cube_resolution"].get<int>());
  EXPECT_TRUE(tried.count(n)) << "the chosen N was not piloted";
  EXPECT_GE(t["predicted_psnr_db_low"].get<double>(), 36.0);
  ASSERT_TRUE(r.stats.psnr_db.has_value());
  EXPECT_GE(*r.stats.psnr_db, 36.0) << "predicted " << t["predicted_psnr_db"] << ", low " << t["predicted_psnr_db_low"];

  RenderOptions direct = small_options("abuffer", 96, 72, n);
  direct.shading_points = t["shading_points"].get<std::string>();
  direct.shadow_edges = t["shadow_edges"].get<std::string>();
  direct.secondary_edges = t["secondary_edges"].get<std::string>();
  EXPECT_TRUE(images_equal(Renderer().render(scene, direct).image, r.image));
}

// One shading point a fragment is piloted first, at the ladder's smallest N: where it
// reaches the target, that is the choice, and no quarters pilot is paid for.
TEST(TargetDb, OnePointReachingAtTheSmallestNIsChosenWithoutQuartersPilots) {
  const Scene scene = Scene::load(scene_path("cornell.json"));
  const RenderResult r = render_measured(scene, 96, 72, 30);
  const json t = json::parse(r.stats.json)["target_db"];
  ASSERT_TRUE(t["reached"].get<bool>()) << t.dump(1);
  const int smallest = target_ladder(scene.cube_resolution()).front();
  ASSERT_GE(t["pilots"].size(), 1u);
  EXPECT_EQ(t["pilots"][0]["cube_resolution"].get<int>(), smallest);
  EXPECT_EQ(t["pilots"][0]["shading_points"], "one");
  EXPECT_EQ(t["shading_points"], "one");
  for (const json& p : t["pilots"]) EXPECT_EQ(p["shading_points"], "one") << t.dump(1);
  ASSERT_TRUE(r.stats.psnr_db.has_value());
  EXPECT_GE(*r.stats.psnr_db, 30.0);
}

// A target no N reaches stops where the error stops improving, keeps the best N found,
// and says so.
TEST(TargetDb, AnUnreachableTargetKeepsTheBestAndSaysSo) {
  const Scene scene = Scene::load(scene_path("cornell.json"));
  Renderer renderer;
  const json t = json::parse(renderer.render(scene, target_options(48, 36, 99)).stats.json)["target_db"];
  EXPECT_FALSE(t["reached"].get<bool>()) << t.dump(1);
  EXPECT_EQ(t["shading_points"], "quarters");
  double best = -1;
  int best_n = 0;
  for (const json& p : t["pilots"]) {
    if (p["psnr_db_low"].get<double>() > best) {
      best = p["psnr_db_low"].get<double>();
      best_n = p["cube_resolution"].get<int>();
    }
  }
  EXPECT_EQ(t["cube_resolution"].get<int>(), best_n);
  EXPECT_LT(t["pilots"].size(), target_ladder(scene.cube_resolution()).size() + 1) << "climbed past the stall";
}

// THE COST MODEL (target_db.cpp): on default.json, whose spheres are finer than the texels
// of the smallest N reaching the target, the choice moves up the ladder; every move is to a
// pilot that reaches the target and that the model says shades for less than the one
// before, and the image still reaches the target against the exact tracer.
TEST(TargetDb, FinerMeshesThanTheTexelsMoveNUpWhereItShadesForLess) {
  const RenderResult r = render_measured(Scene::load(scene_path("default.json")), 512, 384, 40);
  const json t = json::parse(r.stats.json)["target_db"];
  ASSERT_TRUE(t["reached"].get<bool>()) << t.dump(1);
  int smallest = 0;  // the smallest N whose pilot reached the target
  for (const json& p : t["pilots"]) {
    if (p["psnr_db_low"].get<double>() >= 40.0 && (smallest == 0 || p["cube_resolution"].get<int>() < smallest))
      smallest = p["cube_resolution"].get<int>();
  }
  const int chosen = t["cube_resolution"].get<int>();
  EXPECT_GT(chosen, smallest) << t.dump(1);
  EXPECT_NE(t["why"].get<std::string>().find("cost model"), std::string::npos) << t["why"];
  double previous = std::numeric_limits<double>::infinity();
  for (const json& p : t["pilots"]) {
    const int n = p["cube_resolution"].get<int>();
    if (n < smallest || p["shading_points"] != t["shading_points"]) continue;
    if (n > smallest) EXPECT_GE(p["psnr_db_low"].get<double>(), 40.0) << "moved to a pilot short of the target";
    EXPECT_LT(p["model_shading_ms"].get<double>(), previous) << "N = " << n;
    previous = p["model_shading_ms"].get<double>();
  }
  ASSERT_TRUE(r.stats.psnr_db.has_value());
  EXPECT_GE(*r.stats.psnr_db, 40.0);
}

// raytrace --target-db: the rung the stats report, rendered with --samples, is the very
// image; it reaches the target against the 32 samples; a rung below the chosen one was
// predicted short of it; a target only 32 samples reach gives the reference itself.
TEST(TargetDb, TheTracersRungIsTheImageAndReachesTheTarget) {
  const Scene scene = Scene::load(scene_path("cornell.json"));
  Renderer renderer;
  RenderOptions o = small_options("raytrace", 96, 72, 0);
  o.target_db = 38;
  o.reference = true;
  const RenderResult r = renderer.render(scene, o);
  const json t = json::parse(r.stats.json)["target_db"];
  const int samples = t["samples"].get<int>();
  EXPECT_LT(samples, 32) << t.dump(1);
  ASSERT_EQ(t["rungs"].size(), 5u);
  for (const json& rung : t["rungs"]) {
    if (rung["samples"].get<int>() < samples) EXPECT_LT(rung["psnr_db_low"].get<double>(), 38.0) << t.dump(1);
  }
  ASSERT_TRUE(r.stats.psnr_db.has_value());
  EXPECT_GE(*r.stats.psnr_db, 38.0);
  RenderOptions direct = small_options("raytrace", 96, 72, 0);
  direct.samples = samples;
  EXPECT_TRUE(images_equal(renderer.render(scene, direct).image, r.image));

  o.target_db = 99;  // no lower rung predicted there: the 32 samples
  o.reference = false;
  const RenderResult all = renderer.render(scene, o);
  EXPECT_EQ(json::parse(all.stats.json)["target_db"]["samples"].get<int>(), 32);
  EXPECT_TRUE(images_equal(all.image, renderer.render(scene, small_options("raytrace", 96, 72, 0)).image));
}

// Each rung is the image at that many samples: nearer the 32 samples' as it grows, and the
// pilot's rung images are the bits a render at that rung gives the same pixels.
TEST(TargetDb, EveryRungOfTheLadderRenders) {
  const Scene scene = Scene::load(scene_path("cornell.json"));
  Renderer renderer;
  RenderOptions o = small_options("raytrace", 64, 48, 0);
  o.reference = true;
  double previous = 0;
  for (int s : {1, 2, 4, 8, 16}) {
    o.samples = s;
    const RenderResult r = renderer.render(scene, o);
    ASSERT_TRUE(r.stats.psnr_db.has_value());
    EXPECT_GT(*r.stats.psnr_db, previous) << s;
    previous = *r.stats.psnr_db;
    EXPECT_EQ(json::parse(r.stats.json)["counts"]["camera_samples_per_pixel"].get<int>(), s);
  }
  for (int bad : {3, -1, 33, 64}) {
    o.samples = bad;
    EXPECT_THROW(renderer.render(scene, o), InputError) << bad;
  }
  o.samples = 4;
  o.target_db = 40;
  try {
    renderer.render(scene, o);
    FAIL() << "--target-db with --samples rendered";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "target_db: chooses the tracer's samples, and so does samples (--samples): give one");
  }
}

TEST(TargetDb, OptionsThatAlsoSetNAreRefused) {
  const Scene scene = Scene::load(scene_path("cornell.json"));
  Renderer renderer;
  RenderOptions o = small_options("abuffer", 16, 12, 64);
  o.target_db = 40;
  try {
    renderer.render(scene, o);
    FAIL() << "--target-db with --cube-res rendered";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "target_db: chooses the cube map's N, and so does cube_res (--cube-res): give one");
  }
  o.cube_resolution = 0;
  o.target_db = 0.5;
  EXPECT_THROW(renderer.render(scene, o), InputError);  // below the range of a PSNR in dB
}

}  // namespace
}  // namespace abcube::test
