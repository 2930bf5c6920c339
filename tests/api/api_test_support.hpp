// Shared by the API tests: repository scenes at small sizes, image equality.
#pragma once
#include <string>

#include <gtest/gtest.h>

#include <abcube/renderer.hpp>

namespace abcube::test {

inline std::string scene_path(const std::string& name) { return std::string(ABCUBE_SOURCE_DIR) + "/scenes/" + name; }

// Render options at a small camera override (the rest is the scene's camera).
inline RenderOptions small_options(const std::string& method, int width, int height, int cube_res) {
  RenderOptions o;
  o.method = method;
  o.cube_resolution = cube_res;
  o.camera.width = width;
  o.camera.height = height;
  return o;
}

// Exact float equality of two images (size, channels and every value).
inline ::testing::AssertionResult images_equal(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height || a.channels != b.channels) {
    return ::testing::AssertionFailure() << "sizes differ: " << a.width << "x" << a.height << "x" << a.channels
                                         << " against " << b.width << "x" << b.height << "x" << b.channels;
  }
  for (size_t k = 0; k < a.data.size(); ++k) {
    if (a.data[k] != b.data[k]) {
      return ::testing::AssertionFailure() << "value " << k << " differs: " << a.data[k] << " against " << b.data[k];
    }
  }
  return ::testing::AssertionSuccess();
}

}  // namespace abcube::test
