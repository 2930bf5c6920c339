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

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include "base/error.hpp"
#include "base/temporary_file.hpp"

namespace abcube {

namespace fs = std::filesystem;

float srgb_encode(float x) {
  x = std::clamp(x, 0.f, 1.f);
  return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.f / 2.4f) - 0.055f;
}

float srgb_decode(float x) { return x <= 0.04045f ? x / 12.92f : std::pow((x + 0.055f) / 1.055f, 2.4f); }

namespace {

std::string lower_extension(const std::string& path) {
  std::string e = fs::path(path).extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e;
}

bool is_float_format(const std::string& path) {
  const std::string e = lower_extension(path);
  return e == ".exr" || e == ".hdr" || e == ".pfm";
}

}  // namespace

bool image_format_supported(const std::string& path) {
  auto out = OIIO::ImageOutput::create(path);
  return static_cast<bool>(out);
}

std::vector<std::string> writable_image_extensions() {
  // "tiff:tif,tiff;openexr:exr;...": every format OpenImageIO knows, readers included.
  std::vector<std::string> out;
  std::string list = OIIO::get_string_attribute("extension_list");
  for (size_t start = 0; start < list.size();) {
    size_t end = list.find(';', start);
    if (end == std::string::npos) end = list.size();
    const std::string format = list.substr(start, end - start);
    start = end + 1;
    const size_t colon = format.find(':');
    if (colon == std::string::npos) continue;
    std::string exts = format.substr(colon + 1);
    for (size_t a = 0; a <= exts.size();) {
      size_t b = exts.find(',', a);
      if (b == std::string::npos) b = exts.size();
      const std::string ext = exts.substr(a, b - a);
      a = b + 1;
      if (!ext.empty() && std::find(out.begin(), out.end(), ext) == out.end() && image_format_supported("x." + ext)) {
        out.push_back(ext);
      }
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

void write_image(const std::string& path, const Image& image) {
  auto out = OIIO::ImageOutput::create(path);
  if (!out) {
    throw InputError(path + ": no image writer for this file extension (" + join(writable_image_extensions(), ", ") +
                     ")");
  }
  const bool linear = is_float_format(path);
  const int channels = image.channels;
  OIIO::ImageSpec spec(image.width, image.height, channels, linear ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
  spec.attribute("oiio:ColorSpace", linear ? "linear" : "sRGB");
  // The bytes depend on the pixels only: OpenEXR and TIFF otherwise stamp the time.
  spec.attribute("DateTime", "");
  const std::string format = out->format_name();
  // OIIO 2.4's SGI writer leaves its 80-byte image name uninitialized (bytes of our heap
  // in the file) unless it is given a nonempty one.
  if (format == "sgi") spec.attribute("ImageDescription", "abcube");
  std::vector<float> pixels(image.data);
  if (!linear) {
    for (size_t k = 0; k < pixels.size(); ++k) {
      const bool alpha = channels == 4 && k % 4 == 3;
      pixels[k] = alpha ? std::clamp(pixels[k], 0.f, 1.f) : srgb_encode(pixels[k]);
    }
  }
  TemporaryFile temporary(path);
  const std::string& tmp = temporary.path();
  // DPX records the name it is opened with: it is opened with the final name and writes
  // through a proxy to the temporary file, so that its bytes do not hold the temporary's
  // name (and the process id in it). Only DPX: OIIO 2.4's TIFF writer makes broken files
  // through a file proxy.
  std::unique_ptr<OIIO::Filesystem::IOFile> proxy;
  if (format == "dpx") {
    proxy = std::make_unique<OIIO::Filesystem::IOFile>(tmp, OIIO::Filesystem::IOProxy::Write);
    if (!proxy->opened() || !out->set_ioproxy(proxy.get())) proxy.reset();
  }
  bool ok = (proxy || format != "dpx") && out->open(proxy ? path : tmp, spec) &&
            out->write_image(OIIO::TypeDesc::FLOAT, pixels.data());
  ok = out->close() && ok;
  if (proxy) {
    ok = ok && std::fflush(proxy->handle()) == 0 && !std::ferror(proxy->handle());
    proxy->close();
  }
  if (!ok) {
    std::string why = out->geterror();
    if (why.empty()) why = "write failed";
    throw RuntimeFailure(path + ": cannot write image: " + why);
  }
  temporary.commit();
}

Image read_image(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    std::string why = OIIO::geterror();
    if (why.empty()) why = "cannot open";
    std::replace(why.begin(), why.end(), '\n', ' ');
    throw InputError(path + ": cannot read image: " + why);
  }
  const OIIO::ImageSpec& spec = in->spec();
  Image img(spec.width, spec.height, std::min(spec.nchannels, 4));
  std::vector<float> all(static_cast<size_t>(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data())) {
    throw InputError(path + ": cannot read image: " + in->geterror());
  }
  const bool encoded = !(spec.format == OIIO::TypeDesc::FLOAT || spec.format == OIIO::TypeDesc::HALF ||
                         spec.format == OIIO::TypeDesc::DOUBLE);
  for (size_t p = 0; p < static_cast<size_t>(spec.width) * spec.height; ++p) {
    for (int c = 0; c < img.channels; ++c) {
      float v = all[p * spec.nchannels + c];
      if (encoded && c < 3) v = srgb_decode(v);
      img.data[p * img.channels + c] = v;
    }
  }
  in->close();
  return img;
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
