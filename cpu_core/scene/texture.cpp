#include "scene/texture.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagecache.h>
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/texture.h>

#include "base/error.hpp"

namespace abcube {

namespace {

// The sRGB transfer function's inverse (IEC 61966-2-1): encoded value -> linear.
float srgb_to_linear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

// A file name OpenImageIO can pick a reader by, for bytes held in memory.
std::string reader_name(const std::string& name_hint, const std::string& mime_type) {
  if (mime_type == "image/png") return "embedded.png";
  if (mime_type == "image/jpeg") return "embedded.jpg";
  if (mime_type == "image/webp") return "embedded.webp";
  return name_hint.empty() ? "embedded" : name_hint;
}

}  // namespace

bool decode_texture(const unsigned char* bytes, size_t size, const std::string& name_hint, const std::string& mime_type,
                    TextureImage* out, std::string* why) {
  OIIO::Filesystem::IOMemReader reader(bytes, size);
  OIIO::ImageSpec config;
  const void* proxy = &reader;  // a PTR attribute holds the pointer's value
  config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  const std::string name = reader_name(name_hint, mime_type);
  auto in = OIIO::ImageInput::open(name, &config, &reader);
  if (!in) {
    const std::string e = OIIO::geterror();
    *why = e.empty() ? "not an image OpenImageIO can read" : one_line(e);
    return false;
  }
  const OIIO::ImageSpec& spec = in->spec();
  const uint64_t texels =
      static_cast<uint64_t>(std::max(spec.width, 0)) * static_cast<uint64_t>(std::max(spec.height, 0));
  if (spec.width <= 0 || spec.height <= 0 || spec.depth != 1 || spec.nchannels <= 0) {
    *why = "has no pixels (" + std::to_string(spec.width) + " x " + std::to_string(spec.height) + ")";
    return false;
  }
  if (texels > MAX_TEXTURE_TEXELS) {
    *why = "is " + std::to_string(spec.width) + " x " + std::to_string(spec.height) + " texels, over the cap of " +
           std::to_string(MAX_TEXTURE_TEXELS) + " (4096 x 4096)";
    return false;
  }
  const int channels = spec.nchannels;
  std::vector<float> pixels(texels * static_cast<uint64_t>(channels));
  if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, pixels.data())) {
    const std::string e = in->geterror();
    *why = e.empty() ? "cannot decode its pixels" : one_line(e);
    return false;
  }
  // Integer images are sRGB-encoded unless they say they are linear; float images are linear.
  const std::string space = spec.get_string_attribute("oiio:ColorSpace");
  const bool is_float = spec.format.basetype == OIIO::TypeDesc::FLOAT || spec.format.basetype == OIIO::TypeDesc::HALF ||
                        spec.format.basetype == OIIO::TypeDesc::DOUBLE;
  const bool srgb = !is_float && !OIIO::Strutil::iequals(space, "linear");
  out->name = name_hint;
  out->width = spec.width;
  out->height = spec.height;
  out->rgb.resize(3 * texels);
  for (uint64_t t = 0; t < texels; ++t) {
    const float* p = &pixels[t * static_cast<uint64_t>(channels)];
    for (int c = 0; c < 3; ++c) {
      const float v = channels >= 3 ? p[c] : p[0];  // grey (and grey + alpha): all three
      out->rgb[3 * t + static_cast<uint64_t>(c)] = srgb ? srgb_to_linear(v) : (std::isfinite(v) ? v : 0.0f);
    }
  }
  return true;
}

// The TextureSystem and what it reads: each image re-encoded as a float OpenEXR file in
// memory (linear: the TextureSystem has no colour conversion of its own, and filtering must
// happen on linear values, as GL's sRGB textures do), opened through a memory proxy.
struct TextureSet::Sampler {
  OIIO::ImageCache* cache = nullptr;
  OIIO::TextureSystem* system = nullptr;
  std::vector<std::vector<unsigned char>> files;
  std::vector<std::unique_ptr<OIIO::Filesystem::IOMemReader>> readers;
  std::vector<OIIO::TextureSystem::TextureHandle*> handles;

  ~Sampler() {
    if (system) OIIO::TextureSystem::destroy(system);
    if (cache) OIIO::ImageCache::destroy(cache, true);
  }
};

namespace {

// A unique name per TextureSet and image: one cache per set, but the names must never
// meet an actual file.
std::string memory_name(const void* set, size_t image) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "abcube-texture-%p-%zu.exr", set, image);
  return buf;
}

std::vector<unsigned char> encode_exr(const TextureImage& image, const std::string& name) {
  std::vector<unsigned char> bytes;
  OIIO::Filesystem::IOVecOutput writer(bytes);
  OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::FLOAT);
  spec.attribute("compression", "none");
  const void* proxy = &writer;
  spec.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  auto out = OIIO::ImageOutput::create(name);
  ABCUBE_CHECK(
      out && out->open(name, spec) && out->write_image(OIIO::TypeDesc::FLOAT, image.rgb.data()) && out->close(),
      "encoding texture " + image.name + " for the TextureSystem: " + (out ? out->geterror() : OIIO::geterror()));
  return bytes;
}

}  // namespace

TextureSet::TextureSet(std::vector<TextureImage> images, std::vector<int> material_image)
    : images_(std::move(images)), material_image_(std::move(material_image)), sampler_(std::make_unique<Sampler>()) {
  Sampler& s = *sampler_;
  s.cache = OIIO::ImageCache::create(false);
  s.cache->attribute("max_memory_MB", 64.0f);
  s.cache->attribute("automip", 1);    // MIP levels made in memory from the one level
  s.cache->attribute("autotile", 64);  // and read in tiles, so the bound holds
  s.cache->attribute("max_open_files", 4096);
  s.system = OIIO::TextureSystem::create(false, s.cache);
  for (size_t i = 0; i < images_.size(); ++i) {
    const std::string name = memory_name(this, i);
    s.files.push_back(encode_exr(images_[i], name));
    s.readers.push_back(std::make_unique<OIIO::Filesystem::IOMemReader>(s.files.back().data(), s.files.back().size()));
    OIIO::ImageSpec config;
    const void* proxy = s.readers.back().get();
    config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
    const OIIO::ustring uname(name);
    ABCUBE_CHECK(s.cache->add_file(uname, nullptr, &config), "texture " + images_[i].name + ": " + s.cache->geterror());
    s.handles.push_back(s.system->get_texture_handle(uname));
    ABCUBE_CHECK(s.handles.back() && s.system->good(s.handles.back()),
                 "texture " + images_[i].name + ": " + s.system->geterror());
  }
}

TextureSet::~TextureSet() = default;

glm::dvec3 TextureSet::sample(int image, const glm::dvec2& uv) const {
  OIIO::TextureOpt opt;
  opt.swrap = opt.twrap = OIIO::TextureOpt::WrapPeriodic;
  opt.mipmode = OIIO::TextureOpt::MipModeTrilinear;
  opt.interpmode = OIIO::TextureOpt::InterpBilinear;
  // OpenImageIO's t runs down the image from its top row; v runs up.
  const float s = static_cast<float>(uv.x), t = static_cast<float>(1.0 - uv.y);
  float rgb[3] = {0, 0, 0};
  OIIO::TextureSystem* ts = sampler_->system;
  ts->texture(sampler_->handles[static_cast<size_t>(image)], ts->get_perthread_info(), opt, s, t, 0, 0, 0, 0, 3, rgb);
  return glm::dvec3(rgb[0], rgb[1], rgb[2]);
}

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
