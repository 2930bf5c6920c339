#include "scene/texture.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "base/error.hpp"
#include "io/image_codecs.hpp"
#include "io/image_module.hpp"

namespace abcube {

namespace {

// The sRGB transfer function's inverse (IEC 61966-2-1): encoded value -> linear.
float srgb_to_linear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

// A name whose extension picks the module's reader, for bytes held in memory.
std::string reader_name(const std::string& name_hint, const std::string& mime_type) {
  if (mime_type == "image/png") return "embedded.png";
  if (mime_type == "image/jpeg") return "embedded.jpg";
  if (mime_type == "image/webp") return "embedded.webp";
  return name_hint.empty() ? "embedded" : name_hint;
}

}  // namespace

bool decode_texture(const unsigned char* bytes, size_t size, const std::string& name_hint, const std::string& mime_type,
                    TextureImage* out, std::string* why) {
  // PNG and EXR by their own signature, here; every other format through the image module.
  DecodedImage decoded;
  const Codec codec = codec_of_bytes(bytes, size);
  if (codec != Codec::none) {
    *why = decode_image(codec, name_hint, bytes, size, MAX_TEXTURE_TEXELS, &decoded);
  } else {
    *why =
        image_module("decoding texture " + quote(name_hint))
            .read(reader_name(name_hint, mime_type), bytes, size, MAX_TEXTURE_TEXELS, &decoded.image, &decoded.encoded);
  }
  if (!why->empty()) {
    *why = one_line(*why);
    return false;
  }
  const Image& img = decoded.image;
  const uint64_t texels = static_cast<uint64_t>(img.width) * static_cast<uint64_t>(img.height);
  out->name = name_hint;
  out->width = img.width;
  out->height = img.height;
  out->rgb.resize(3 * texels);
  const uint64_t channels = static_cast<uint64_t>(img.channels);
  for (uint64_t t = 0; t < texels; ++t) {
    const float* p = &img.data[t * channels];
    for (uint64_t c = 0; c < 3; ++c) {
      const float v = channels >= 3 ? p[c] : p[0];  // grey (and grey + alpha): all three
      out->rgb[3 * t + c] = decoded.encoded ? srgb_to_linear(v) : (std::isfinite(v) ? std::max(v, 0.0f) : 0.0f);
    }
  }
  return true;
}

TextureSet::TextureSet(std::vector<TextureImage> images, std::vector<int> material_image)
    : images_(std::move(images)), material_image_(std::move(material_image)) {
  std::vector<TexturePixels> pixels;
  for (const TextureImage& i : images_) pixels.push_back({i.width, i.height, i.rgb.data()});
  sampler_ = image_module("textures").sampler(pixels);
}

TextureSet::~TextureSet() = default;

glm::dvec3 TextureSet::sample(int image, const glm::dvec2& uv) const { return sampler_->sample(image, uv); }

glm::dvec2 triangle_uv(const TriangleSoup& soup, uint32_t triangle, const glm::dvec3& w) {
  if (soup.uvs.empty()) return glm::dvec2(0.0);
  const size_t i = 3 * static_cast<size_t>(triangle);
  return w.x * glm::dvec2(soup.uvs[i]) + w.y * glm::dvec2(soup.uvs[i + 1]) + w.z * glm::dvec2(soup.uvs[i + 2]);
}

glm::dvec3 barycentric_weights(const TriangleSoup& soup, uint32_t triangle, const glm::dvec3& p) {
  const size_t i = 3 * static_cast<size_t>(triangle);
  const glm::dvec3 a(soup.positions[i]), b(soup.positions[i + 1]), c(soup.positions[i + 2]);
  const glm::dvec3 n = glm::cross(b - a, c - a);
  const double area2 = glm::dot(n, n);
  if (!(area2 > 0.0)) return glm::dvec3(1.0, 0.0, 0.0);
  // Signed sub-areas of the point's projection on the plane (Ericson 2005, 3.4).
  const double wa = glm::dot(glm::cross(b - p, c - p), n) / area2;
  const double wb = glm::dot(glm::cross(c - p, a - p), n) / area2;
  return {wa, wb, 1.0 - wa - wb};
}

}  // namespace abcube
