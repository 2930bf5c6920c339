#include "scene/scene_data.hpp"

#include <algorithm>
#include <cmath>

#include "base/enum_names.hpp"

namespace abcube {

namespace {
constexpr EnumName<Method> METHOD_NAMES[] = {{Method::abuffer, "abuffer"}, {Method::zbuffer, "zbuffer"},
                                             {Method::envmap, "envmap"},   {Method::raytrace, "raytrace"},
                                             {Method::gpu, "gpu"},         {Method::hybrid, "hybrid"}};
}

const char* method_name(Method m) { return enum_name(METHOD_NAMES, m); }

bool parse_method(const std::string& s, Method* out) { return parse_enum(METHOD_NAMES, s, out); }

const std::vector<std::string>& method_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const EnumName<Method>& e : METHOD_NAMES) n.emplace_back(e.name);
    return n;
  }();
  return names;
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
