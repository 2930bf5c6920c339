#include "shading/shading_plan.hpp"

#include <stdexcept>

namespace abcube {

namespace {

bool at_samples(const std::string& value, const char* option) {
  if (value == "samples") return true;
  if (value == "points") return false;
  throw std::invalid_argument(std::string(option) + ": samples or points, not " + value);
}

const char* samples_or_points(bool at_samples) { return at_samples ? "samples" : "points"; }

}  // namespace

ShadingPlan::ShadingPlan(ShadingPoints points, bool shadow_edges, bool secondary_edges, bool texture_samples)
    : points_(points),
      shadow_edges_(shadow_edges && points == ShadingPoints::quarters),
      secondary_edges_(secondary_edges && points != ShadingPoints::one),
      texture_samples_(texture_samples) {}

ShadingPlan ShadingPlan::from_names(const std::string& points, const std::string& shadow_edges,
                                    const std::string& secondary_edges, const std::string& texture_lookups) {
  ShadingPoints p = ShadingPoints::quarters;
  if (points == "one") {
    p = ShadingPoints::one;
  } else if (points == "sparse") {
    p = ShadingPoints::sparse;
  } else if (points != "quarters") {
    throw std::invalid_argument("shading_points: quarters, sparse or one, not " + points);
  }
  return ShadingPlan(p, at_samples(shadow_edges, "shadow_edges"), at_samples(secondary_edges, "secondary_edges"),
                     at_samples(texture_lookups, "texture_lookups"));
}

ShadingPlan ShadingPlan::with_points(ShadingPoints points) const {
  return ShadingPlan(points, shadow_edges_, secondary_edges_, texture_samples_);
}

ShadingPlan ShadingPlan::without_edges() const { return ShadingPlan(points_, false, false, texture_samples_); }

std::vector<ShadingPlan> ShadingPlan::cheaper() const {
  std::vector<ShadingPlan> plans;
  if (points_ == ShadingPoints::one) return plans;
  plans.push_back(with_points(ShadingPoints::one));
  if (points_ == ShadingPoints::sparse) return plans;
  plans.push_back(with_points(ShadingPoints::sparse));
  if (shadow_edges_ && secondary_edges_) plans.push_back(without_edges());
  if (secondary_edges_) plans.push_back(ShadingPlan(points_, shadow_edges_, false, texture_samples_));
  return plans;
}

const char* ShadingPlan::points_name() const {
  switch (points_) {
    case ShadingPoints::one: return "one";
    case ShadingPoints::sparse: return "sparse";
    case ShadingPoints::quarters: break;
  }
  return "quarters";
}

std::vector<std::pair<const char*, const char*>> ShadingPlan::settings() const {
  return {{"shading_points", points_name()},
          {"shadow_edges", samples_or_points(shadow_edges_)},
          {"secondary_edges", samples_or_points(secondary_edges_)},
          {"texture_lookups", samples_or_points(texture_samples_)}};
}

}  // namespace abcube
