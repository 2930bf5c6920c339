// PNG (libpng) and OpenEXR (the OpenEXR library) read and written here, without
// OpenImageIO: the formats a render writes and reads most, at the cost of a few small
// libraries loaded at start. Every other format goes through the image module
// (io/image_module.hpp).
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>

#include "io/image.hpp"

namespace abcube {

enum class Codec { none, png, exr };

// A file name's extension, dot included, in lower case (".png"; "" for none).
std::string lower_extension(const std::string& path);

// The codec of a file name's extension (.png, .exr, any case), or none.
Codec codec_of_path(const std::string& path);
// The codec of bytes by their signature (PNG's eight bytes, OpenEXR's magic), or none.
Codec codec_of_bytes(const unsigned char* bytes, size_t size);

// A decoded image: the stored values as floats (8-bit / 255, 16-bit / 65535, float as is),
// 1 to 4 channels (grey, grey + alpha, RGB, RGBA); `encoded` when the values are
// sRGB-encoded (integer PNGs, unless their gAMA chunk says linear), false for EXR.
struct DecodedImage {
  Image image;
  bool encoded = false;
};

// Reads the file `path` (bytes == nullptr) or `size` bytes in memory (`path` then names
// them in messages). Returns "" and fills `out`, or why it could not. An image of more
// than `max_pixels` pixels (0: no cap) is refused before its pixels are decoded.
std::string decode_image(Codec codec, const std::string& path, const unsigned char* bytes, size_t size,
                         uint64_t max_pixels, DecodedImage* out);

// Writes `image` to the file `file` (the caller's temporary) in the codec's format: PNG as
// 8 bits per channel of the values given (already sRGB-encoded, in [0, 1]; rounded as
// OpenImageIO rounds, so that the bytes are those it wrote), tagged sRGB; EXR as 32-bit
// floats, ZIP-compressed, channels Y, YA, RGB or RGBA. Returns "" or why it failed.
std::string encode_image(Codec codec, const std::string& file, const Image& image);

}  // namespace abcube
