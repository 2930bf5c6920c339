#include "scene/radiance.hpp"

#include <algorithm>
#include <cstdio>
#include <vector>

#include "base/error.hpp"
#include "scene/texture.hpp"

namespace abcube {

namespace {

double largest(const glm::dvec3& v) { return std::max(v.x, std::max(v.y, v.z)); }

// The largest texel of material m's texture, at least 1 (1 when it has none).
double texture_scale(const SceneData& scene, uint32_t m) {
  if (!scene.textures) return 1.0;
  const int image = scene.textures->image_of(m);
  if (image < 0) return 1.0;
  const std::vector<float>& rgb = scene.textures->images()[static_cast<size_t>(image)].rgb;
  double top = 1.0;
  for (const float x : rgb) top = std::max(top, static_cast<double>(x));
  return top;
}

// 1 + k + ... + k^d.
double series(double k, int d) {
  double sum = 1.0, term = 1.0;
  for (int i = 0; i < d; ++i) sum += term *= k;
  return sum;
}

std::string number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", x);
  return text;
}

}  // namespace

double radiance_bound(const SceneData& scene, int max_depth) {
  double lights = 0.0;
  for (const PointLight& l : scene.lights) lights += largest(l.color);
  double m_local = largest(scene.background), k = 0.0;
  for (uint32_t i = 0; i < scene.materials.size(); ++i) {
    const Material& m = scene.materials[i];
    const double c = largest(m.color) * texture_scale(scene, i);
    m_local = std::max(m_local, m.ambient * c * largest(scene.ambient) + lights * (m.diffuse * c + m.specular));
    k = std::max(k, m.reflect + m.transmit);
  }
  return m_local * series(k, max_depth);
}

void check_radiance(const SceneData& scene, int max_depth, const std::string& where) {
  const double bound = radiance_bound(scene, max_depth);
  if (bound <= MAX_RADIANCE) return;
  // The largest of the values the bound grows with: the one to lower.
  std::string name = "background";
  double value = largest(scene.background);
  const auto consider = [&](const std::string& n, double v) {
    if (v > value) {
      name = n;
      value = v;
    }
  };
  consider("ambient", largest(scene.ambient));
  for (size_t i = 0; i < scene.lights.size(); ++i)
    consider("lights[" + std::to_string(i) + "].color", largest(scene.lights[i].color));
  for (uint32_t i = 0; i < scene.materials.size(); ++i) {
    consider("material \"" + scene.materials[i].name + "\" color", largest(scene.materials[i].color));
    const double t = texture_scale(scene, i);
    if (t > 1.0) consider("material \"" + scene.materials[i].name + "\" texture's largest texel", t);
  }
  throw InputError(where + name + ": with this scene's lights, colours and max_depth " + std::to_string(max_depth) +
                   ", a pixel could reach " + number(bound) + ", past the " + number(MAX_RADIANCE) +
                   " an image's float keeps finite; must be at most about " + number(value * MAX_RADIANCE / bound) +
                   ", got " + number(value));
}

}  // namespace abcube
