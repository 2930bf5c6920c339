#include "scene/scene_data.hpp"

#include <algorithm>
#include <cmath>

namespace abcube {

namespace {
constexpr const char* METHOD_NAMES[] = {"abuffer", "zbuffer", "envmap", "raytrace", "gpu"};
}

const char* method_name(Method m) { return METHOD_NAMES[static_cast<int>(m)]; }

bool parse_method(const std::string& s, Method* out) {
  for (int i = 0; i < 5; ++i) {
    if (s == METHOD_NAMES[i]) {
      *out = static_cast<Method>(i);
      return true;
    }
  }
  return false;
}

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
