#include "shading/secondary_edges.hpp"

#include <algorithm>
#include <unordered_map>

#include "base/samples.hpp"

namespace abcube {

namespace {

// SideTrails' index of a samples.hpp SIDE_* bit.
int side_index(uint8_t side) { return __builtin_ctz(side); }

}  // namespace

std::vector<uint8_t> PixelTrails::across(int width, int height, const std::vector<uint8_t>* only) const {
  std::unordered_map<size_t, SideTrails> sides;
  for (const auto& worker : sides_) {
    for (const auto& [pixel, s] : worker) {
      SideTrails& into = sides[pixel];
      for (size_t k = 0; k < into.size(); ++k) into[k].add(s[k]);
    }
  }
  std::vector<uint8_t> out(points_.size(), 0);
  const auto at = [width](int x, int y) { return static_cast<size_t>(y) * static_cast<size_t>(width) + size_t(x); };
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t p = at(x, y);
      if ((only && !(*only)[p]) || points_[p].state != TrailSet::ONE) continue;
      const uint32_t mine = points_[p].trail;
      // q: a 4-neighbour; side: q's side that faces this pixel.
      const auto differs = [&](size_t q, uint8_t side) {
        const TrailSet& t = points_[q];
        if (t.state == TrailSet::ONE) return t.trail != mine;
        const auto found = sides.find(q);
        if (found == sides.end()) return false;
        const TrailSet& s = found->second[static_cast<size_t>(side_index(side))];
        return s.state == TrailSet::SEVERAL || (s.state == TrailSet::ONE && s.trail != mine);
      };
      out[p] = (x > 0 && differs(at(x - 1, y), SIDE_RIGHT)) || (x + 1 < width && differs(at(x + 1, y), SIDE_LEFT)) ||
               (y > 0 && differs(at(x, y - 1), SIDE_BOTTOM)) || (y + 1 < height && differs(at(x, y + 1), SIDE_TOP));
    }
  }
  return out;
}

void PixelTrails::forget_rows(const std::vector<uint8_t>& rows, int width) {
  const auto marked = [&](size_t pixel) { return rows[pixel / static_cast<size_t>(width)] != 0; };
  for (size_t p = 0; p < points_.size(); ++p) {
    if (marked(p)) points_[p] = TrailSet{};
  }
  for (auto& worker : sides_) {
    worker.erase(std::remove_if(worker.begin(), worker.end(), [&](const auto& e) { return marked(e.first); }),
                 worker.end());
  }
}

}  // namespace abcube
