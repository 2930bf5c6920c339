// The built-in PNG and EXR codecs (io/image_codecs.hpp): round trips of 1 to 4 channels,
// files and memory alike, the caps, and broken bytes refused with a reason.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "io/image_codecs.hpp"

namespace abcube {
namespace {

namespace fs = std::filesystem;

// A width x height image of `channels` values in [0, 1], each different.
Image ramp(int width, int height, int channels) {
  Image img(width, height, channels);
  for (size_t k = 0; k < img.data.size(); ++k) img.data[k] = static_cast<float>((k * 37) % 256) / 255.0f;
  return img;
}

std::vector<unsigned char> file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class ImageCodecs : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("abcube_codecs_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  // Writes `img` as `file` in `codec`, then decodes it from the file and from its bytes in
  // memory (whose codec the magic must name).
  void round_trip(Codec codec, const std::string& file, const Image& img, DecodedImage* from_file,
                  DecodedImage* from_memory) {
    ASSERT_EQ(encode_image(codec, file, img), "");
    ASSERT_EQ(decode_image(codec, file, nullptr, 0, 0, from_file), "");
    const std::vector<unsigned char> bytes = file_bytes(file);
    EXPECT_EQ(codec_of_bytes(bytes.data(), bytes.size()), codec);
    ASSERT_EQ(decode_image(codec, file, bytes.data(), bytes.size(), 0, from_memory), "");
  }
  fs::path dir_;
};

TEST_F(ImageCodecs, PngRoundTripsEveryChannelCountFromFileAndMemory) {
  for (int c = 1; c <= 4; ++c) {
    const Image img = ramp(7, 5, c);
    const std::string file = path("c" + std::to_string(c) + ".png");
    DecodedImage from_file, from_memory;
    ASSERT_NO_FATAL_FAILURE(round_trip(Codec::png, file, img, &from_file, &from_memory));
    EXPECT_TRUE(from_file.encoded);
    ASSERT_EQ(from_file.image.channels, c);
    ASSERT_EQ(from_file.image.width, 7);
    ASSERT_EQ(from_file.image.height, 5);
    EXPECT_EQ(from_file.image.data, from_memory.image.data);
    for (size_t k = 0; k < img.data.size(); ++k) {
      ASSERT_FLOAT_EQ(from_file.image.data[k], img.data[k]) << "channel count " << c << ", value " << k;
    }
  }
}

TEST_F(ImageCodecs, ExrRoundTripsFloatsExactly) {
  for (int c = 1; c <= 4; ++c) {
    Image img = ramp(6, 3, c);
    img.data[0] = 7.25f;  // HDR values stay
    img.data[1] = -0.5f;
    const std::string file = path("c" + std::to_string(c) + ".exr");
    DecodedImage from_file, from_memory;
    ASSERT_NO_FATAL_FAILURE(round_trip(Codec::exr, file, img, &from_file, &from_memory));
    EXPECT_FALSE(from_file.encoded);
    ASSERT_EQ(from_file.image.channels, c);
    EXPECT_EQ(from_file.image.data, img.data);
    EXPECT_EQ(from_memory.image.data, img.data);
  }
}

TEST_F(ImageCodecs, CapsAndBrokenBytesAreRefusedWithAReason) {
  const std::string file = path("big.png");
  ASSERT_EQ(encode_image(Codec::png, file, ramp(40, 30, 3)), "");
  DecodedImage out;
  EXPECT_EQ(decode_image(Codec::png, file, nullptr, 0, 1199, &out), "is 40 x 30 pixels, over the cap of 1199");
  EXPECT_EQ(decode_image(Codec::png, file, nullptr, 0, 1200, &out), "");
  std::vector<unsigned char> bytes = file_bytes(file);
  bytes.resize(bytes.size() / 2);
  EXPECT_NE(decode_image(Codec::png, file, bytes.data(), bytes.size(), 0, &out), "");
  const std::string text = "not an image";
  const auto* t = reinterpret_cast<const unsigned char*>(text.data());
  EXPECT_EQ(codec_of_bytes(t, text.size()), Codec::none);
  EXPECT_NE(decode_image(Codec::png, "t.png", t, text.size(), 0, &out), "");
  EXPECT_NE(decode_image(Codec::exr, "t.exr", t, text.size(), 0, &out), "");
  EXPECT_NE(decode_image(Codec::png, path("absent.png"), nullptr, 0, 0, &out), "");
  EXPECT_EQ(codec_of_path("A.PNG"), Codec::png);
  EXPECT_EQ(codec_of_path("a.Exr"), Codec::exr);
  EXPECT_EQ(codec_of_path("a.tif"), Codec::none);
}

}  // namespace
}  // namespace abcube
