// Linear-light float images and cube maps read back from GL or built on the CPU.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <abcube/image.hpp>

namespace abcube {

// Image (row-major floats, linear colour): <abcube/image.hpp>.

// Six N x N faces in GL face order; each face an Image as above.
struct CubeImage {
  int n = 0;
  std::array<Image, 6> faces;
  CubeImage() = default;
  CubeImage(int size, int channels, float fill = 0.f) : n(size) {
    for (Image& f : faces) f = Image(size, size, channels, fill);
  }
};

// One channel of integer ids (object ids from the GL prepass), same layout as CubeImage.
struct CubeIds {
  int n = 0;
  std::array<std::vector<uint32_t>, 6> faces;
};

}  // namespace abcube
