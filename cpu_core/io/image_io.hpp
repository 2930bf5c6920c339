// Reading and writing images through OpenImageIO, chosen by the file's extension.
#pragma once
#include <string>

#include "io/image.hpp"

namespace abcube {

// Writes atomically: a temporary file in the same folder, then rename, so a failure never
// leaves a truncated file nor destroys an old one. Linear colour in; 8- and 16-bit
// formats are written sRGB-encoded, float formats (EXR, HDR, float TIFF) linear.
// Throws InputError for an extension no writer handles, RuntimeFailure for I/O errors.
void write_image(const std::string& path, const Image& image);

// Reads an image as linear float RGB(A) (sRGB-decoded when the file is 8/16-bit).
// Throws InputError naming the file when it cannot be read.
Image read_image(const std::string& path);

// Writes bytes to `path` atomically (temporary + rename). Throws RuntimeFailure.
void write_text_atomic(const std::string& path, const std::string& text);

// True if OpenImageIO has a writer for this file name's extension.
bool image_format_supported(const std::string& path);

float srgb_encode(float linear);
float srgb_decode(float encoded);

}  // namespace abcube
