// libabcube_oiio.so: the image module (io/image_module.hpp) over OpenImageIO. Built as a
// module of its own and loaded by the core on first need; it depends on nothing of abcube
// but headers.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagecache.h>
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/texture.h>

#include "io/image_module.hpp"

namespace abcube {

namespace {

std::string one_line_of(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

// The sampler: OpenImageIO's TextureSystem over each image re-encoded as a float OpenEXR
// file in memory (linear: the TextureSystem has no colour conversion of its own, and
// filtering must happen on linear values, as GL's sRGB textures do), opened through a
// memory proxy. Its own cache, bounded to 64 MiB; thread-safe.
class OiioSampler : public TextureSampler {
 public:
  explicit OiioSampler(const std::vector<TexturePixels>& images) {
    cache_ = OIIO::ImageCache::create(false);
    cache_->attribute("max_memory_MB", 64.0f);
    cache_->attribute("automip", 1);    // MIP levels made in memory from the one level
    cache_->attribute("autotile", 64);  // and read in tiles, so the bound holds
    cache_->attribute("max_open_files", 4096);
    system_ = OIIO::TextureSystem::create(false, cache_);
    for (size_t i = 0; i < images.size(); ++i) {
      // A unique name per sampler and image: the names must never meet an actual file.
      char buf[64];
      std::snprintf(buf, sizeof buf, "abcube-texture-%p-%zu.exr", static_cast<const void*>(this), i);
      const std::string name = buf;
      files_.push_back(encode_exr(images[i], name));
      readers_.push_back(std::make_unique<OIIO::Filesystem::IOMemReader>(files_.back().data(), files_.back().size()));
      OIIO::ImageSpec config;
      const void* proxy = readers_.back().get();
      config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
      const OIIO::ustring uname(name);
      if (!cache_->add_file(uname, nullptr, &config)) throw std::runtime_error("texture cache: " + cache_->geterror());
      handles_.push_back(system_->get_texture_handle(uname));
      if (!handles_.back() || !system_->good(handles_.back())) {
        throw std::runtime_error("texture system: " + system_->geterror());
      }
    }
  }
  ~OiioSampler() override {
    if (system_) OIIO::TextureSystem::destroy(system_);
    if (cache_) OIIO::ImageCache::destroy(cache_, true);
  }

  glm::dvec3 sample(int image, const glm::dvec2& uv) const override {
    OIIO::TextureOpt opt;
    opt.swrap = opt.twrap = OIIO::TextureOpt::WrapPeriodic;
    opt.mipmode = OIIO::TextureOpt::MipModeTrilinear;
    opt.interpmode = OIIO::TextureOpt::InterpBilinear;
    // OpenImageIO's t runs down the image from its top row; v runs up.
    const float s = static_cast<float>(uv.x), t = static_cast<float>(1.0 - uv.y);
    float rgb[3] = {0, 0, 0};
    system_->texture(handles_[static_cast<size_t>(image)], system_->get_perthread_info(), opt, s, t, 0, 0, 0, 0, 3,
                     rgb);
    return glm::dvec3(rgb[0], rgb[1], rgb[2]);
  }

 private:
  static std::vector<unsigned char> encode_exr(const TexturePixels& image, const std::string& name) {
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput writer(bytes);
    OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::FLOAT);
    spec.attribute("compression", "none");
    const void* proxy = &writer;
    spec.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
    auto out = OIIO::ImageOutput::create(name);
    if (!(out && out->open(name, spec) && out->write_image(OIIO::TypeDesc::FLOAT, image.rgb) && out->close())) {
      throw std::runtime_error("encoding a texture for the TextureSystem: " +
                               (out ? out->geterror() : OIIO::geterror()));
    }
    return bytes;
  }

  OIIO::ImageCache* cache_ = nullptr;
  OIIO::TextureSystem* system_ = nullptr;
  std::vector<std::vector<unsigned char>> files_;
  std::vector<std::unique_ptr<OIIO::Filesystem::IOMemReader>> readers_;
  std::vector<OIIO::TextureSystem::TextureHandle*> handles_;
};

// A file name OpenImageIO can pick a reader by, for bytes held in memory: the name's own
// extension, or the format the bytes' signature names.
std::string reader_name(const std::string& path, const unsigned char* bytes, size_t size) {
  if (bytes && size >= 3 && bytes[0] == 0xff && bytes[1] == 0xd8 && bytes[2] == 0xff) return "embedded.jpg";
  if (bytes && size >= 12 && std::equal(bytes, bytes + 4, "RIFF") && std::equal(bytes + 8, bytes + 12, "WEBP")) {
    return "embedded.webp";
  }
  return path;
}

class OiioModule : public ImageModule {
 public:
  bool can_write(const std::string& path) const override { return static_cast<bool>(OIIO::ImageOutput::create(path)); }

  std::vector<std::string> writable_extensions() const override {
    // "tiff:tif,tiff;openexr:exr;...": every format OpenImageIO knows, readers included.
    std::vector<std::string> out;
    const std::string list = OIIO::get_string_attribute("extension_list");
    for (size_t start = 0; start < list.size();) {
      size_t end = list.find(';', start);
      if (end == std::string::npos) end = list.size();
      const std::string format = list.substr(start, end - start);
      start = end + 1;
      const size_t colon = format.find(':');
      if (colon == std::string::npos) continue;
      const std::string exts = format.substr(colon + 1);
      for (size_t a = 0; a <= exts.size();) {
        size_t b = exts.find(',', a);
        if (b == std::string::npos) b = exts.size();
        const std::string ext = exts.substr(a, b - a);
        a = b + 1;
        if (!ext.empty() && std::find(out.begin(), out.end(), ext) == out.end() && can_write("x." + ext)) {
          out.push_back(ext);
        }
      }
    }
    std::sort(out.begin(), out.end());
    return out;
  }

  std::string write(const std::string& path, const std::string& file, const Image& image, bool linear) const override {
    auto out = OIIO::ImageOutput::create(path);
    if (!out) return "no image writer for this file extension";
    OIIO::ImageSpec spec(image.width, image.height, image.channels,
                         linear ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", linear ? "linear" : "sRGB");
    // The bytes depend on the pixels only: OpenEXR and TIFF otherwise stamp the time.
    spec.attribute("DateTime", "");
    const std::string format = out->format_name();
    // OIIO 2.4's SGI writer leaves its 80-byte image name uninitialized (bytes of our heap
    // in the file) unless it is given a nonempty one.
    if (format == "sgi") spec.attribute("ImageDescription", "abcube");
    // DPX records the name it is opened with: it is opened with the final name and writes
    // through a proxy to the temporary file, so that its bytes do not hold the temporary's
    // name (and the process id in it). Only DPX: OIIO 2.4's TIFF writer makes broken
    // files through a file proxy.
    std::unique_ptr<OIIO::Filesystem::IOFile> proxy;
    if (format == "dpx") {
      proxy = std::make_unique<OIIO::Filesystem::IOFile>(file, OIIO::Filesystem::IOProxy::Write);
      if (!proxy->opened() || !out->set_ioproxy(proxy.get())) proxy.reset();
    }
    bool ok = (proxy || format != "dpx") && out->open(proxy ? path : file, spec) &&
              out->write_image(OIIO::TypeDesc::FLOAT, image.data.data());
    ok = out->close() && ok;
    if (proxy) {
      ok = ok && std::fflush(proxy->handle()) == 0 && !std::ferror(proxy->handle());
      proxy->close();
    }
    if (ok) return "";
    const std::string why = out->geterror();
    return why.empty() ? "write failed" : one_line_of(why);
  }

  std::string read(const std::string& path, const unsigned char* bytes, size_t size, uint64_t max_pixels, Image* out,
                   bool* encoded) const override {
    std::unique_ptr<OIIO::Filesystem::IOMemReader> reader;
    OIIO::ImageSpec config;
    std::unique_ptr<OIIO::ImageInput> in;
    if (bytes) {
      reader = std::make_unique<OIIO::Filesystem::IOMemReader>(bytes, size);
      const void* proxy = reader.get();  // a PTR attribute holds the pointer's value
      config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
      in = OIIO::ImageInput::open(reader_name(path, bytes, size), &config, reader.get());
    } else {
      in = OIIO::ImageInput::open(path);
    }
    if (!in) {
      const std::string e = OIIO::geterror();
      return e.empty() ? "not an image OpenImageIO can read" : one_line_of(e);
    }
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.depth != 1 || spec.nchannels <= 0) {
      return "has no pixels (" + std::to_string(spec.width) + " x " + std::to_string(spec.height) + ")";
    }
    const uint64_t pixels = static_cast<uint64_t>(spec.width) * static_cast<uint64_t>(spec.height);
    if (max_pixels > 0 && pixels > max_pixels) {
      return "is " + std::to_string(spec.width) + " x " + std::to_string(spec.height) + " pixels, over the cap of " +
             std::to_string(max_pixels);
    }
    std::vector<float> all(pixels * static_cast<uint64_t>(spec.nchannels));
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data())) {
      const std::string e = in->geterror();
      return e.empty() ? "cannot decode its pixels" : one_line_of(e);
    }
    // Integer images are sRGB-encoded unless they say they are linear; float images are linear.
    const OIIO::TypeDesc::BASETYPE base = static_cast<OIIO::TypeDesc::BASETYPE>(spec.format.basetype);
    const bool is_float =
        base == OIIO::TypeDesc::FLOAT || base == OIIO::TypeDesc::HALF || base == OIIO::TypeDesc::DOUBLE;
    *encoded = !is_float && !OIIO::Strutil::iequals(spec.get_string_attribute("oiio:ColorSpace"), "linear");
    const int channels = std::min(spec.nchannels, 4);
    *out = Image(spec.width, spec.height, channels);
    for (uint64_t p = 0; p < pixels; ++p) {
      for (int c = 0; c < channels; ++c) {
        out->data[p * static_cast<uint64_t>(channels) + static_cast<uint64_t>(c)] =
            all[p * static_cast<uint64_t>(spec.nchannels) + static_cast<uint64_t>(c)];
      }
    }
    in->close();
    return "";
  }

  std::unique_ptr<TextureSampler> sampler(const std::vector<TexturePixels>& images) const override {
    return std::make_unique<OiioSampler>(images);
  }
};

}  // namespace

}  // namespace abcube

extern "C" __attribute__((visibility("default"))) abcube::ImageModule* abcube_image_module() {
  static abcube::OiioModule module;
  return &module;
}
