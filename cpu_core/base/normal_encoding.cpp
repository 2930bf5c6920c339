#include "base/normal_encoding.hpp"

#include <algorithm>
#include <cmath>

namespace abcube {

uint32_t encode_octahedral(const glm::dvec3& n) {
  // Cigolle et al. 2014, "A Survey of Efficient Representations for Independent Unit
  // Vectors": project on the octahedron, fold the lower half, snorm16 per coordinate.
  const double l1 = std::fabs(n.x) + std::fabs(n.y) + std::fabs(n.z);
  glm::dvec2 p = l1 > 0.0 ? glm::dvec2(n.x, n.y) / l1 : glm::dvec2(0.0);
  if (n.z < 0.0) {
    const glm::dvec2 sign(p.x >= 0.0 ? 1.0 : -1.0, p.y >= 0.0 ? 1.0 : -1.0);
    p = (1.0 - glm::dvec2(std::fabs(p.y), std::fabs(p.x))) * sign;
  }
  const auto snorm16 = [](double v) {
    const double q = std::floor(std::clamp(v, -1.0, 1.0) * 32767.0 + 0.5);  // round to nearest
    return static_cast<uint32_t>(static_cast<uint16_t>(static_cast<int16_t>(q)));
  };
  return snorm16(p.x) | (snorm16(p.y) << 16);
}

glm::dvec3 decode_octahedral(uint32_t code) {
  const double px = static_cast<int16_t>(static_cast<uint16_t>(code & 0xffffu)) / 32767.0;
  const double py = static_cast<int16_t>(static_cast<uint16_t>(code >> 16)) / 32767.0;
  glm::dvec3 n(px, py, 1.0 - std::fabs(px) - std::fabs(py));
  if (n.z < 0.0) {
    const double x = n.x;
    n.x = (1.0 - std::fabs(n.y)) * (x >= 0.0 ? 1.0 : -1.0);
    n.y = (1.0 - std::fabs(x)) * (n.y >= 0.0 ? 1.0 : -1.0);
  }
  return glm::normalize(n);
}

}  // namespace abcube
