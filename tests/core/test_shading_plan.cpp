// THE SHADING PLAN (shading/shading_plan.hpp): one value a plan, settings that take no
// effect stored as off, names that read back into the same plan, and the cheaper plans in
// their cost order.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "shading/shading_plan.hpp"

namespace abcube {
namespace {

constexpr ShadingPoints ALL_POINTS[] = {ShadingPoints::one, ShadingPoints::sparse, ShadingPoints::quarters};

std::vector<ShadingPlan> every_plan() {
  std::vector<ShadingPlan> plans;
  for (const ShadingPoints p : ALL_POINTS) {
    for (int bits = 0; bits < 8; ++bits) plans.emplace_back(p, (bits & 1) != 0, (bits & 2) != 0, (bits & 4) != 0);
  }
  return plans;
}

// SHADOW EDGES need the quarters; SECONDARY EDGES the quarters or sparse's second pass; the
// texture lookups hold with any points.
TEST(ShadingPlan, SettingsThatTakeNoEffectAreOff) {
  for (const ShadingPlan& plan : every_plan()) {
    const bool quarters = plan.points() == ShadingPoints::quarters;
    if (!quarters) EXPECT_FALSE(plan.shadow_edges()) << plan.points_name();
    if (plan.points() == ShadingPoints::one) EXPECT_FALSE(plan.secondary_edges());
  }
  EXPECT_EQ(ShadingPlan(ShadingPoints::one, true, true), ShadingPlan(ShadingPoints::one, false, false));
  EXPECT_EQ(ShadingPlan(ShadingPoints::sparse, true, true), ShadingPlan(ShadingPoints::sparse, false, true));
  EXPECT_NE(ShadingPlan(ShadingPoints::sparse, false, true), ShadingPlan(ShadingPoints::sparse, false, false));
  EXPECT_NE(ShadingPlan(ShadingPoints::quarters, true, false), ShadingPlan(ShadingPoints::quarters, false, false));
  EXPECT_NE(ShadingPlan(ShadingPoints::one, false, false, true), ShadingPlan(ShadingPoints::one, false, false, false));
  const ShadingPlan asked;  // the default: what --shading-points etc. default to
  EXPECT_STREQ(asked.points_name(), "quarters");
  EXPECT_TRUE(asked.shadow_edges() && asked.secondary_edges() && asked.texture_samples());
}

TEST(ShadingPlan, ItsNamesReadBackIntoTheSamePlan) {
  for (const ShadingPlan& plan : every_plan()) {
    std::string v[4];
    int i = 0;
    for (const auto& [key, value] : plan.settings()) v[i++] = value;
    ASSERT_EQ(i, 4);
    EXPECT_EQ(ShadingPlan::from_names(v[0], v[1], v[2], v[3]), plan) << v[0] << " " << v[1] << " " << v[2];
  }
  EXPECT_THROW(ShadingPlan::from_names("half", "samples", "samples", "samples"), std::invalid_argument);
  EXPECT_THROW(ShadingPlan::from_names("one", "yes", "samples", "samples"), std::invalid_argument);
}

TEST(ShadingPlan, CheaperPlansComeCheapestFirst) {
  const ShadingPlan full(ShadingPoints::quarters, true, true);
  const std::vector<ShadingPlan> below = full.cheaper();
  ASSERT_EQ(below.size(), 4u);
  EXPECT_EQ(below[0], ShadingPlan(ShadingPoints::one, false, false));
  EXPECT_EQ(below[1], ShadingPlan(ShadingPoints::sparse, false, true));
  EXPECT_EQ(below[2], ShadingPlan(ShadingPoints::quarters, false, false));
  EXPECT_EQ(below[3], ShadingPlan(ShadingPoints::quarters, true, false));
  EXPECT_EQ(ShadingPlan(ShadingPoints::quarters, false, false).cheaper().size(), 2u);
  EXPECT_EQ(ShadingPlan(ShadingPoints::sparse, false, true).cheaper(),
            std::vector<ShadingPlan>{ShadingPlan(ShadingPoints::one, false, false)});
  EXPECT_TRUE(ShadingPlan(ShadingPoints::one, false, false).cheaper().empty());
  for (const ShadingPlan& plan : every_plan()) {
    for (const ShadingPlan& c : plan.cheaper()) {
      EXPECT_NE(c, plan);
      EXPECT_EQ(c.texture_samples(), plan.texture_samples());  // a target never changes the lookups
    }
  }
}

}  // namespace
}  // namespace abcube
