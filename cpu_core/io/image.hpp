// Linear-light float images and cube maps read back from GL or built on the CPU.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace abcube {

// Row-major, `channels` floats per pixel, linear colour. Row 0 is the top of a camera
// image, and t = 0 (texel row j = 0) of a cube face (cube_map.hpp).
struct Image {
  int width = 0, height = 0, channels = 3;
  std::vector<float> data;

  Image() = default;
  Image(int w, int h, int c = 3, float fill = 0.f)
      : width(w), height(h), channels(c), data(static_cast<size_t>(w) * h * c, fill) {}
  float* at(int x, int y) { return &data[(static_cast<size_t>(y) * width + x) * channels]; }
  const float* at(int x, int y) const { return &data[(static_cast<size_t>(y) * width + x) * channels]; }
  glm::vec3 rgb(int x, int y) const {
    const float* p = at(x, y);
    return channels >= 3 ? glm::vec3(p[0], p[1], p[2]) : glm::vec3(p[0]);
  }
  void set_rgb(int x, int y, const glm::vec3& c) {
    float* p = at(x, y);
    for (int k = 0; k < std::min(channels, 3); ++k) p[k] = c[k];
  }
};

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
