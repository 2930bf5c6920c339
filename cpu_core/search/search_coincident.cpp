// coincident_crossings (search.hpp): the surfaces crossed together with a search's answer,
// for the crossing sets of NESTED DIELECTRICS (media.hpp).
#include <algorithm>
#include <vector>

#include "search/search_internal.hpp"

namespace abcube {

void coincident_crossings(const SearchContext& ctx, const glm::dvec3& w, const glm::dvec3& d, uint32_t hit,
                          double l_hit, double tolerance, const std::function<void(uint32_t, double)>& visit) {
  const CubeABuffer& cube = ctx.cube();
  const glm::dvec3 x = w - cube.centre + l_hit * d;  // relative to the centre
  const double dist = glm::length(x);
  if (!(dist > 0.0)) return;
  const double texel = texel_size_at(x, cube.n);
  std::vector<uint32_t> seen{hit};
  const auto take = [&](uint32_t tri, double l) {
    if (std::find(seen.begin(), seen.end(), tri) != seen.end()) return;
    seen.push_back(tri);
    if (std::abs(l - l_hit) <= tolerance) visit(tri, l);
  };
  const CubeTexel t = direction_to_texel(x, cube.n);
  const ABuffer& face = cube.faces[static_cast<size_t>(t.face)];
  const double reach = texel + tolerance;
  for (int j = std::max(t.j - 1, 0); j <= std::min(t.j + 1, cube.n - 1); ++j) {
    for (int i = std::max(t.i - 1, 0); i <= std::min(t.i + 1, cube.n - 1); ++i) {
      for (const Fragment& f : face.list(i, j)) {
        if (f.zmax < dist - reach || f.zmin > dist + reach) continue;
        if (std::find(seen.begin(), seen.end(), f.triangle()) != seen.end()) continue;
        uint32_t crossed = 0;
        double l = 0;
        if (mesh_crossing(ctx, w, d, f.triangle(), l_hit, texel, &crossed, &l)) take(crossed, l);
      }
    }
  }
  ctx.for_each_side_crossing(w - cube.centre, d, l_hit + tolerance, [&](uint32_t tri, double l) {
    take(tri, l);
    return true;
  });
}

}  // namespace abcube
