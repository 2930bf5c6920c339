#include "io/image_io.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>

#include "base/error.hpp"
#include "base/temporary_file.hpp"
#include "io/image_codecs.hpp"
#include "io/image_module.hpp"

namespace abcube {

namespace fs = std::filesystem;

float srgb_encode(float x) {
  x = std::clamp(x, 0.f, 1.f);
  return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.f / 2.4f) - 0.055f;
}

float srgb_decode(float x) { return x <= 0.04045f ? x / 12.92f : std::pow((x + 0.055f) / 1.055f, 2.4f); }

namespace {

bool is_float_format(const std::string& path) {
  const std::string e = lower_extension(path);
  return e == ".exr" || e == ".hdr" || e == ".pfm";
}

}  // namespace

bool image_format_supported(const std::string& path) {
  return codec_of_path(path) != Codec::none || image_module("writing " + quote_path(path)).can_write(path);
}

std::vector<std::string> writable_image_extensions() {
  return image_module("listing the image formats").writable_extensions();
}

void write_image(const std::string& path, const Image& image) {
  const Codec codec = codec_of_path(path);
  if (codec == Codec::none && !image_module("writing " + quote_path(path)).can_write(path)) {
    throw InputError(path + ": no image writer for this file extension (" + join(writable_image_extensions(), ", ") +
                     ")");
  }
  const bool linear = is_float_format(path);
  Image encoded;  // 8-bit formats: the values sRGB-encoded; float formats take `image` as it is
  if (!linear) {
    encoded = image;
    for (size_t k = 0; k < encoded.data.size(); ++k) {
      const bool alpha = image.channels == 4 && k % 4 == 3;
      encoded.data[k] = alpha ? std::clamp(encoded.data[k], 0.f, 1.f) : srgb_encode(encoded.data[k]);
    }
  }
  const Image& pixels = linear ? image : encoded;
  TemporaryFile temporary(path);
  const std::string why =
      codec != Codec::none ? encode_image(codec, temporary.path(), pixels)
                           : image_module("writing " + quote_path(path)).write(path, temporary.path(), pixels, linear);
  if (!why.empty()) throw RuntimeFailure(path + ": cannot write image: " + one_line(why));
  temporary.commit();
}

Image read_image(const std::string& path) {
  DecodedImage decoded;
  const Codec codec = codec_of_path(path);
  std::string why =
      codec != Codec::none
          ? decode_image(codec, path, nullptr, 0, 0, &decoded)
          : image_module("reading " + quote_path(path)).read(path, nullptr, 0, 0, &decoded.image, &decoded.encoded);
  if (!why.empty()) throw InputError(path + ": cannot read image: " + one_line(why));
  Image& img = decoded.image;
  if (decoded.encoded) {
    for (size_t k = 0; k < img.data.size(); ++k) {
      if (k % static_cast<size_t>(img.channels) < 3) img.data[k] = srgb_decode(img.data[k]);
    }
  }
  return std::move(decoded.image);
}

void write_text_atomic(const std::string& path, const std::string& text) {
  TemporaryFile temporary(path);
  {
    std::ofstream f(temporary.path(), std::ios::binary | std::ios::trunc);
    if (!f) throw RuntimeFailure(path + ": cannot write: " + std::strerror(errno));
    f << text;
    f.close();
    if (!f) throw RuntimeFailure(path + ": cannot write: " + std::strerror(errno));
  }
  temporary.commit();
}

}  // namespace abcube
