// A linear-light float image in memory: what a render returns.
#pragma once
#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace abcube {

// Row-major, `channels` floats per pixel, linear colour (not sRGB-encoded). Row 0 is the
// top of a camera image, and t = 0 (texel row j = 0) of a cube face.
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

// Reads an image (the format by extension: PNG and EXR built in, others through
// OpenImageIO, loaded then): linear floats, sRGB-encoded
// files (PNG, JPEG, ...) decoded. Throws InputError naming the file.
Image read_image(const std::string& path);

// Writes an image atomically (a temporary name in the same folder, then rename): a failed
// write leaves no partial file and keeps an old one. 8-bit formats get sRGB-encoded
// values; float formats (EXR, TIFF float) linear ones. The bytes depend on the pixels
// only (no time stamp), so the same render always writes the same file.
void write_image(const std::string& path, const Image& image);

// Removes from `folder` the temporaries of atomic writes (".NAME.tmpPID-HOST.EXT") that
// processes of this host left when they were killed before their rename, their process
// gone, and returns how many. Those of live processes and of other hosts stay.
std::size_t remove_stale_temporaries(const std::string& folder);

// Whether a writer handles this file's extension (PNG and EXR, or one of OpenImageIO's).
bool image_format_supported(const std::string& path);
// The extensions that have a writer ("exr", "png", ...), for messages.
std::vector<std::string> writable_image_extensions();

// The error of `a` against `b` (same size). As displayed: RMSE, PSNR, max abs error and
// the share of pixels whose largest channel differs by more than 1/255, 2/255 and 8/255,
// on sRGB-encoded values clamped to [0, 1] (what a person sees); psnr is +infinity for
// identical images. Linear: the RMSE and max abs error of the stored values themselves
// (HDR values above 1 included, where the displayed figures see 1), and the mean relative
// error |a - b| / max(|b|, 1/255) over every channel. The worst pixel: where the displayed
// difference is largest (the first such pixel in reading order), its channel and both
// images' values there.
struct ImageError {
  double rmse = 0, psnr = 0, max_abs = 0;
  double share_over_1 = 0, share_over_2 = 0, share_over_8 = 0;
  double linear_rmse = 0, linear_max_abs = 0, relative_mean = 0;
  bool hdr = false;  // a channel of either image above 1
  int worst_x = 0, worst_y = 0, worst_channel = 0;
  float worst_a[3] = {0, 0, 0}, worst_b[3] = {0, 0, 0};  // linear values at the worst pixel
};
ImageError image_error(const Image& a, const Image& b);

}  // namespace abcube
