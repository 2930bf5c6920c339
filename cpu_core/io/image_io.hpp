// Reading and writing images, chosen by the file's extension: PNG and EXR built in
// (io/image_codecs.hpp), every other format through the image module (io/image_module.hpp).
#pragma once
#include <string>

#include "io/image.hpp"

namespace abcube {

// write_image, read_image and image_format_supported: <abcube/image.hpp> (included by
// io/image.hpp). write_image throws InputError for an extension no writer handles,
// RuntimeFailure for I/O errors.

// Writes bytes to `path` atomically (temporary + rename). Throws RuntimeFailure.
void write_text_atomic(const std::string& path, const std::string& text);

float srgb_encode(float linear);
float srgb_decode(float encoded);

}  // namespace abcube
