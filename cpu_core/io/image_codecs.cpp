#include "io/image_codecs.hpp"

#include <png.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <vector>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>

namespace abcube {

namespace {

// ---- PNG ------------------------------------------------------------------------------
//
// libpng reports errors by longjmp. Between setjmp and a longjmp only what a pointer set
// before setjmp reaches is touched (PngState): no local object changes there, so none is
// left indeterminate.

struct PngState {
  std::string error;
  const unsigned char* bytes = nullptr;  // reading from memory
  size_t size = 0, at = 0;
  std::vector<unsigned char> rows;
  std::vector<png_bytep> row_pointers;
  FILE* file = nullptr;
  ~PngState() {
    if (file) std::fclose(file);
  }
};

void png_error_fn(png_structp png, png_const_charp message) {
  static_cast<PngState*>(png_get_error_ptr(png))->error = message ? message : "libpng error";
  png_longjmp(png, 1);
}
void png_warning_fn(png_structp, png_const_charp) {}

void png_read_memory(png_structp png, png_bytep out, png_size_t n) {
  PngState* s = static_cast<PngState*>(png_get_io_ptr(png));
  if (s->size - s->at < n) png_error(png, "unexpected end of data");
  std::memcpy(out, s->bytes + s->at, n);
  s->at += n;
}

std::string decode_png(const std::string& path, const unsigned char* bytes, size_t size, uint64_t max_pixels,
                       DecodedImage* out) {
  const auto state = std::make_unique<PngState>();
  PngState* s = state.get();
  if (!bytes) {
    s->file = std::fopen(path.c_str(), "rb");
    if (!s->file) return std::strerror(errno);
  } else {
    s->bytes = bytes;
    s->size = size;
  }
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, s, png_error_fn, png_warning_fn);
  if (!png) return "libpng cannot start";
  png_infop info = png_create_info_struct(png);
  png_uint_32 width = 0, height = 0;
  int depth = 0, channels = 0;
  bool linear = false;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return s->error.empty() ? "not a PNG libpng can read" : s->error;
  }
  if (!info) png_error(png, "libpng cannot start");
  if (bytes) {
    png_set_read_fn(png, s, png_read_memory);
  } else {
    png_init_io(png, s->file);
  }
  png_read_info(png, info);
  width = png_get_image_width(png, info);
  height = png_get_image_height(png, info);
  if (max_pixels > 0 && static_cast<uint64_t>(width) * height > max_pixels) {
    png_destroy_read_struct(&png, &info, nullptr);
    return "is " + std::to_string(width) + " x " + std::to_string(height) + " pixels, over the cap of " +
           std::to_string(max_pixels);
  }
  // A gAMA of 1 with no sRGB chunk marks linear values; anything else is sRGB-encoded.
  double gamma = 0;
  linear = png_get_gAMA(png, info, &gamma) && std::fabs(gamma - 1.0) < 1e-3 && !png_get_valid(png, info, PNG_INFO_sRGB);
  png_set_expand(png);  // palette to RGB, grey under 8 bits to 8, tRNS to alpha
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  depth = png_get_bit_depth(png, info);
  channels = png_get_channels(png, info);
  const size_t row_bytes = png_get_rowbytes(png, info);
  s->rows.resize(row_bytes * height);
  s->row_pointers.resize(height);
  for (png_uint_32 y = 0; y < height; ++y) s->row_pointers[y] = s->rows.data() + row_bytes * y;
  png_read_image(png, s->row_pointers.data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);

  out->image = Image(static_cast<int>(width), static_cast<int>(height), channels);
  out->encoded = !linear;
  const size_t values = static_cast<size_t>(width) * height * static_cast<size_t>(channels);
  for (size_t k = 0; k < values; ++k) {
    out->image.data[k] = depth == 16 ? static_cast<float>((s->rows[2 * k] << 8) | s->rows[2 * k + 1]) / 65535.0f
                                     : static_cast<float>(s->rows[k]) / 255.0f;
  }
  return "";
}

std::string encode_png(const std::string& file, const Image& image) {
  if (image.channels < 1 || image.channels > 4)
    return "PNG holds 1 to 4 channels, got " + std::to_string(image.channels);
  const auto state = std::make_unique<PngState>();
  PngState* s = state.get();
  // OpenImageIO's float to 8-bit conversion: v * 255 + 0.5, clamped, truncated.
  s->rows.resize(image.data.size());
  for (size_t k = 0; k < image.data.size(); ++k) {
    s->rows[k] = static_cast<unsigned char>(std::clamp(image.data[k] * 255.0f + 0.5f, 0.0f, 255.0f));
  }
  s->file = std::fopen(file.c_str(), "wb");
  if (!s->file) return std::strerror(errno);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, s, png_error_fn, png_warning_fn);
  if (!png) return "libpng cannot start";
  png_infop info = png_create_info_struct(png);
  static const int COLOR_TYPES[4] = {PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_COLOR_TYPE_RGB,
                                     PNG_COLOR_TYPE_RGB_ALPHA};
  std::vector<png_bytep> row_pointers(static_cast<size_t>(image.height));
  const size_t row_bytes = static_cast<size_t>(image.width) * static_cast<size_t>(image.channels);
  for (size_t y = 0; y < row_pointers.size(); ++y) row_pointers[y] = s->rows.data() + row_bytes * y;
  char key[] = "oiio:ColorSpace", value[] = "sRGB";
  png_text text{};
  text.compression = PNG_TEXT_COMPRESSION_NONE;
  text.key = key;
  text.text = value;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return s->error.empty() ? "libpng could not write it" : s->error;
  }
  if (!info) png_error(png, "libpng cannot start");
  png_init_io(png, s->file);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.width), static_cast<png_uint_32>(image.height), 8,
               COLOR_TYPES[image.channels - 1], PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  // The chunks OpenImageIO writes for an sRGB image, in its order: gAMA, sRGB, cHRM, oFFs,
  // and the colour space as text.
  png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_ABSOLUTE);
  png_set_oFFs(png, info, 0, 0, PNG_OFFSET_PIXEL);
  png_set_text(png, info, &text, 1);
  // OpenImageIO's deflate settings (libpng would choose Z_FILTERED for filtered rows).
  png_set_compression_level(png, 6);
  png_set_compression_strategy(png, Z_DEFAULT_STRATEGY);
  png_write_info(png, info);
  png_write_image(png, row_pointers.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  const bool flushed = std::fflush(s->file) == 0 && !std::ferror(s->file);
  const int closed = std::fclose(s->file);
  s->file = nullptr;
  return flushed && closed == 0 ? "" : std::strerror(errno);
}

// ---- OpenEXR --------------------------------------------------------------------------

// Bytes in memory as an OpenEXR input stream.
class MemoryStream : public Imf::IStream {
 public:
  MemoryStream(const std::string& name, const unsigned char* bytes, size_t size)
      : Imf::IStream(name.c_str()), bytes_(bytes), size_(size) {}
  bool read(char c[], int n) override {
    if (n < 0 || static_cast<size_t>(n) > size_ - at_) throw std::runtime_error("unexpected end of data");
    std::memcpy(c, bytes_ + at_, static_cast<size_t>(n));
    at_ += static_cast<size_t>(n);
    return at_ < size_;
  }
  uint64_t tellg() override { return at_; }
  void seekg(uint64_t pos) override {
    if (pos > size_) throw std::runtime_error("seek past the end of data");
    at_ = static_cast<size_t>(pos);
  }

 private:
  const unsigned char* bytes_;
  size_t size_, at_ = 0;
};

// The channels read, in order: RGB(A) when the file has R, G and B; else Y (and A); else
// its first channel.
std::vector<std::string> exr_channels(const Imf::ChannelList& list) {
  const auto has = [&](const char* n) { return list.findChannel(n) != nullptr; };
  std::vector<std::string> names;
  if (has("R") && has("G") && has("B")) {
    names = {"R", "G", "B"};
  } else if (has("Y")) {
    names = {"Y"};
  } else if (list.begin() != list.end()) {
    names = {list.begin().name()};
  }
  if (!names.empty() && names[0] != "A" && has("A")) names.push_back("A");
  return names;
}

std::string decode_exr(const std::string& path, const unsigned char* bytes, size_t size, uint64_t max_pixels,
                       DecodedImage* out) {
  try {
    std::unique_ptr<MemoryStream> stream;
    std::unique_ptr<Imf::InputFile> in;
    if (bytes) {
      stream = std::make_unique<MemoryStream>(path, bytes, size);
      in = std::make_unique<Imf::InputFile>(*stream, 1);
    } else {
      in = std::make_unique<Imf::InputFile>(path.c_str(), 1);
    }
    const Imath::Box2i window = in->header().dataWindow();
    const int w = window.max.x - window.min.x + 1, h = window.max.y - window.min.y + 1;
    if (w <= 0 || h <= 0) return "has no pixels";
    if (max_pixels > 0 && static_cast<uint64_t>(w) * static_cast<uint64_t>(h) > max_pixels) {
      return "is " + std::to_string(w) + " x " + std::to_string(h) + " pixels, over the cap of " +
             std::to_string(max_pixels);
    }
    const std::vector<std::string> names = exr_channels(in->header().channels());
    if (names.empty()) return "has no channels";
    const int c = static_cast<int>(names.size());
    out->image = Image(w, h, c);
    out->encoded = false;
    const size_t xs = sizeof(float) * static_cast<size_t>(c), ys = xs * static_cast<size_t>(w);
    char* base = reinterpret_cast<char*>(out->image.data.data()) - static_cast<ptrdiff_t>(window.min.x) * xs -
                 static_cast<ptrdiff_t>(window.min.y) * ys;
    Imf::FrameBuffer frame;
    for (int k = 0; k < c; ++k) {
      frame.insert(names[static_cast<size_t>(k)], Imf::Slice(Imf::FLOAT, base + sizeof(float) * k, xs, ys));
    }
    in->setFrameBuffer(frame);
    in->readPixels(window.min.y, window.max.y);
    return "";
  } catch (const std::exception& e) {
    return e.what();
  }
}

std::string encode_exr(const std::string& file, const Image& image) {
  static const std::vector<std::vector<const char*>> NAMES = {{"Y"}, {"Y", "A"}, {"R", "G", "B"}, {"R", "G", "B", "A"}};
  if (image.channels < 1 || image.channels > 4)
    return "abcube writes 1 to 4 channels, got " + std::to_string(image.channels);
  try {
    Imf::Header header(image.width, image.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    const std::vector<const char*>& names = NAMES[static_cast<size_t>(image.channels - 1)];
    for (const char* n : names) header.channels().insert(n, Imf::Channel(Imf::FLOAT));
    Imf::OutputFile outfile(file.c_str(), header, 1);
    const size_t xs = sizeof(float) * static_cast<size_t>(image.channels), ys = xs * static_cast<size_t>(image.width);
    char* base = const_cast<char*>(reinterpret_cast<const char*>(image.data.data()));
    Imf::FrameBuffer frame;
    for (size_t k = 0; k < names.size(); ++k)
      frame.insert(names[k], Imf::Slice(Imf::FLOAT, base + sizeof(float) * k, xs, ys));
    outfile.setFrameBuffer(frame);
    outfile.writePixels(image.height);
    return "";
  } catch (const std::exception& e) {
    return e.what();
  }
}

}  // namespace

std::string lower_extension(const std::string& path) {
  std::string e = std::filesystem::path(path).extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e;
}

Codec codec_of_path(const std::string& path) {
  const std::string e = lower_extension(path);
  return e == ".png" ? Codec::png : e == ".exr" ? Codec::exr : Codec::none;
}

Codec codec_of_bytes(const unsigned char* bytes, size_t size) {
  static const unsigned char PNG_SIGNATURE[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  static const unsigned char EXR_MAGIC[4] = {0x76, 0x2f, 0x31, 0x01};
  if (size >= 8 && std::memcmp(bytes, PNG_SIGNATURE, 8) == 0) return Codec::png;
  if (size >= 4 && std::memcmp(bytes, EXR_MAGIC, 4) == 0) return Codec::exr;
  return Codec::none;
}

std::string decode_image(Codec codec, const std::string& path, const unsigned char* bytes, size_t size,
                         uint64_t max_pixels, DecodedImage* out) {
  switch (codec) {
    case Codec::png: return decode_png(path, bytes, size, max_pixels, out);
    case Codec::exr: return decode_exr(path, bytes, size, max_pixels, out);
    case Codec::none: break;
  }
  return "no built-in reader for it";
}

std::string encode_image(Codec codec, const std::string& file, const Image& image) {
  switch (codec) {
    case Codec::png: return encode_png(file, image);
    case Codec::exr: return encode_exr(file, image);
    case Codec::none: break;
  }
  return "no built-in writer for it";
}

}  // namespace abcube
