// The image module: what OpenImageIO does for abcube beyond PNG and EXR (io/image_codecs.hpp):
// every other file format, and the texture filtering (its TextureSystem). It is a shared
// library of its own (libabcube_oiio.so, built from io/oiio_module/) that a process loads
// on first need, so that one that reads and writes only PNG and EXR never loads
// OpenImageIO and the two hundred and more libraries it pulls in.
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "io/image.hpp"

namespace abcube {

// Filtered lookups in a set of linear RGB images (3 floats a texel, rows from the top):
// trilinear between MIP levels, bilinear within one, wrapping periodically; v runs up.
class TextureSampler {
 public:
  virtual ~TextureSampler() = default;
  virtual glm::dvec3 sample(int image, const glm::dvec2& uv) const = 0;
};

// One texture's texels: width x height x 3 linear floats, rows from the top.
struct TexturePixels {
  int width = 0, height = 0;
  const float* rgb = nullptr;
};

class ImageModule {
 public:
  virtual ~ImageModule() = default;
  // Whether a writer handles `path`'s extension; the extensions written, sorted.
  virtual bool can_write(const std::string& path) const = 0;
  virtual std::vector<std::string> writable_extensions() const = 0;
  // Writes `image` to `file` (the caller's temporary) in the format of `path`'s extension:
  // 8-bit formats get its values as given (sRGB-encoded by the caller), float formats
  // (`linear`) its linear floats. Returns "" or why it failed.
  virtual std::string write(const std::string& path, const std::string& file, const Image& image,
                            bool linear) const = 0;
  // Reads the file `path` (bytes == nullptr) or `size` bytes (`path` names them, and its
  // extension picks the reader when the bytes do not). Returns "" and the stored values as
  // floats, `encoded` when they are sRGB-encoded (integer formats not marked linear), or
  // why it could not. More than `max_pixels` pixels (0: no cap): refused before decoding.
  virtual std::string read(const std::string& path, const unsigned char* bytes, size_t size, uint64_t max_pixels,
                           Image* out, bool* encoded) const = 0;
  // A sampler over `images`; their texels must outlive it.
  virtual std::unique_ptr<TextureSampler> sampler(const std::vector<TexturePixels>& images) const = 0;
};

// The module, loaded on the first call (thread-safe) for `need` ("writing out.tif",
// "textures"): RuntimeFailure naming the need and every place searched when it cannot be.
// Searched: $ABCUBE_IMAGE_MODULE (a file) alone when it is set; else beside the program or
// library that holds this code, lib/abcube and abcube/ in the three folders above it, the
// build tree, then the installed library folder.
const ImageModule& image_module(const std::string& need);

// Whether the module is loaded in this process (for tests and `abcube info`).
bool image_module_loaded();

}  // namespace abcube

// The module's one entry point.
extern "C" abcube::ImageModule* abcube_image_module();
