// THE SHADING PLAN: how many points shade a camera fragment, and which differences inside a
// pixel are refined at its 32 samples (map_shading.hpp: SPARSE, SHADOW EDGES, SECONDARY
// EDGES). One value: it holds only settings that take effect, so that two plans that render
// the same image compare equal, and it names itself as the options and the stats do.
//
// What takes effect where: SHADOW EDGES compare a fragment's quarters, so they need the
// quarters (with one point, or the one point of sparse's first pass, there is nothing to
// compare); SECONDARY EDGES compare them too, and sparse's second pass shades its pixels at
// the quarters, so they hold with the quarters and with sparse. The base colour's lookups
// (samples or the point) hold with any plan.
#pragma once
#include <string>
#include <utility>
#include <vector>

namespace abcube {

// Shading points per camera fragment, cheapest first: one, at the centroid of its covered
// samples; sparse, one and then the quarters in the pixels whose colour differs from a
// neighbour's; the quarters (2 to 4, more where they differ).
enum class ShadingPoints { one, sparse, quarters };

class ShadingPlan {
 public:
  ShadingPlan() = default;  // the quarters, every edge and texture lookup at the samples
  // A setting that would not take effect with `points` is stored as off.
  ShadingPlan(ShadingPoints points, bool shadow_edges, bool secondary_edges, bool texture_samples = true);
  // From the option values: --shading-points quarters | sparse | one, and --shadow-edges,
  // --secondary-edges, --texture-lookups samples | points. Another value: std::invalid_argument.
  static ShadingPlan from_names(const std::string& points, const std::string& shadow_edges,
                                const std::string& secondary_edges, const std::string& texture_lookups);

  ShadingPoints points() const { return points_; }
  // The first pass shades one point a fragment (one and sparse).
  bool one_point() const { return points_ != ShadingPoints::quarters; }
  bool sparse() const { return points_ == ShadingPoints::sparse; }
  bool shadow_edges() const { return shadow_edges_; }
  bool secondary_edges() const { return secondary_edges_; }
  bool texture_samples() const { return texture_samples_; }

  // The plan with other points and this plan's settings, those that take effect with them.
  ShadingPlan with_points(ShadingPoints points) const;
  // The same points with no edge refined at the samples.
  ShadingPlan without_edges() const;
  // The plans a target may settle for below this one, cheapest first: one point; sparse;
  // the quarters with neither edge refined; without SECONDARY EDGES alone. Below sparse,
  // only one point; below one, none.
  std::vector<ShadingPlan> cheaper() const;

  // The option names: "quarters", "sparse", "one"; "samples" or "points" for the others.
  const char* points_name() const;
  // shading_points, shadow_edges, secondary_edges and texture_lookups with their values,
  // as the stats and the options write them.
  std::vector<std::pair<const char*, const char*>> settings() const;

  bool operator==(const ShadingPlan& o) const {
    return points_ == o.points_ && shadow_edges_ == o.shadow_edges_ && secondary_edges_ == o.secondary_edges_ &&
           texture_samples_ == o.texture_samples_;
  }
  bool operator!=(const ShadingPlan& o) const { return !(*this == o); }

 private:
  ShadingPoints points_ = ShadingPoints::quarters;
  bool shadow_edges_ = true;
  bool secondary_edges_ = true;
  bool texture_samples_ = true;
};

}  // namespace abcube
