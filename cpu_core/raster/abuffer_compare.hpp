// Two builds of one A-buffer (a cube's or the camera's) compared list by list and fragment by fragment (the CPU
// core's against the GPU's, host/gl/gl_abuffer.hpp; `abcube crosscheck`): each difference
// put in one class, the first of its class kept as an example.
#pragma once
#include <array>
#include <cstdint>
#include <string>

#include "raster/abuffer.hpp"

namespace abcube {

// Depths may differ by this share of the distance (a few float steps) and normals by one
// step of each 16-bit code: what a GL whose divisions and square roots round otherwise than
// IEEE 754 may move. Masks, triangles and list lengths must be identical.
constexpr double LIST_DEPTH_REL = 1.0 / (1 << 21);
constexpr int LIST_NORMAL_STEPS = 1;

enum class ListDifference {
  length,       // the pixel's lists differ in length (their fragments are not compared)
  mask,         // a fragment's coverage mask
  triangle,     // the same mask, another triangle or facing
  depth,        // zmin or zmax beyond LIST_DEPTH_REL
  depth_close,  // zmin or zmax within it (allowed)
  normal,       // the normal code beyond LIST_NORMAL_STEPS
  normal_close  // within it (allowed)
};
constexpr int LIST_DIFFERENCE_CLASSES = 7;
const char* list_difference_name(ListDifference d);

struct ListComparison {
  uint64_t lists = 0, lists_identical = 0;
  uint64_t fragments = 0, fragments_identical = 0;  // of the lists of equal length
  std::array<uint64_t, LIST_DIFFERENCE_CLASSES> count{};
  std::array<std::string, LIST_DIFFERENCE_CLASSES> example{};  // face, pixel, fragment, both sides
  double depth_max_rel = 0;
  // Whether only the allowed classes (depth_close, normal_close) occurred.
  bool within_bounds() const;
  uint64_t of(ListDifference d) const { return count[static_cast<size_t>(d)]; }
};

// `a` and `b` must have the same n; a fragment is put in the first class it shows, in the
// order of ListDifference.
ListComparison compare_lists(const CubeABuffer& a, const CubeABuffer& b, const char* a_name = "CPU",
                             const char* b_name = "GPU");
// The camera's A-buffers (`a` and `b` of the same size): the examples name a pixel.
ListComparison compare_lists(const ABuffer& a, const ABuffer& b, const char* a_name = "CPU",
                             const char* b_name = "GPU");

}  // namespace abcube
