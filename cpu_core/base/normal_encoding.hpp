// The unit normals the A-buffer's fragments carry, in one 32-bit word: the octahedral
// encoding of Cigolle et al. 2014 ("A Survey of Efficient Representations for Independent
// Unit Vectors"), 16 bits per coordinate. decode_octahedral(encode_octahedral(n)) is within
// 1e-4 of n for every unit n (tests/core/test_raster.cpp).
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

namespace abcube {

uint32_t encode_octahedral(const glm::dvec3& unit);
glm::dvec3 decode_octahedral(uint32_t code);

}  // namespace abcube
