// SECONDARY EDGES between pixels (map_shading.hpp): an edge of what a mirror or glass shows
// that runs between a pixel's shading points, meeting none of them, is found from the
// trails (PrimaryLights::trail) its neighbours' points and samples found.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace abcube {

// The trails some points found: none, one (`trail`), or several different ones. A trail is
// kept folded to 32 bits (8 bytes a pixel): two neighbours' different trails fold alike
// about once in 4e9.
struct TrailSet {
  enum : uint8_t { NONE, ONE, SEVERAL };
  uint32_t trail = 0;
  uint8_t state = NONE;
  void add(uint64_t full) {
    const auto t = static_cast<uint32_t>(full ^ (full >> 32));
    if (state == NONE) {
      trail = t;
      state = ONE;
    } else if (state == ONE && trail != t) {
      state = SEVERAL;
    }
  }
  void add(const TrailSet& o) {
    if (o.state == SEVERAL) state = SEVERAL;
    if (o.state == ONE) add(uint64_t{o.trail});
  }
};

// The trails of a fragment's samples on each side of its pixel (left, right, top, bottom:
// samples.hpp SIDE_* order), noted where the fragment was shaded at its samples.
using SideTrails = std::array<TrailSet, 4>;

// What the points of each pixel's secondary fragments found, and the sides of the pixels
// whose fragments were shaded at their samples. A resolve worker owns a row at a time: no
// two threads write one pixel's entry; the sides are kept per worker.
class PixelTrails {
 public:
  PixelTrails() = default;
  PixelTrails(size_t pixels, size_t workers) : points_(pixels), sides_(workers) {}
  bool empty() const { return points_.empty(); }

  void note_point(size_t pixel, uint64_t trail) { points_[pixel].add(trail); }
  void note_several(size_t pixel) { points_[pixel].state = TrailSet::SEVERAL; }
  void note_sides(size_t pixel, int worker, const SideTrails& sides) {
    sides_[static_cast<size_t>(worker)].emplace_back(pixel, sides);
  }

  // Per pixel (1: shade its secondary fragments at their samples), those whose points all
  // found one trail where a 4-neighbour's points found another, or where a 4-neighbour's
  // samples on the side the two share found another: an edge between this pixel's points.
  // Pixels outside `only` (when given) get 0.
  std::vector<uint8_t> across(int width, int height, const std::vector<uint8_t>* only) const;
  // Forgets what was noted in the rows `rows` marks (a width-wide image, a byte a row).
  void forget_rows(const std::vector<uint8_t>& rows, int width);

 private:
  std::vector<TrailSet> points_;
  std::vector<std::vector<std::pair<size_t, SideTrails>>> sides_;
};

}  // namespace abcube
