#include "scene/scene_data.hpp"

#include <algorithm>
#include <cmath>

namespace abcube {

Bounds SceneData::bounds() const {
  Bounds b;
  for (const glm::vec3& p : triangles->positions) b.extend(glm::dvec3(p));
  return b;
}

double max_distance_from(const SceneData& scene, const glm::dvec3& p) {
  double d = 0;
  for (const glm::vec3& v : scene.triangles->positions) d = std::max(d, glm::length(glm::dvec3(v) - p));
  return d;
}

}  // namespace abcube
