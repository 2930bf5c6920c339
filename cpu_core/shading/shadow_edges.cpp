#include "shading/shadow_edges.hpp"

#include <algorithm>

#include "base/samples.hpp"
#include "raster/raster.hpp"

namespace abcube {

namespace {

size_t pixel_index(int width, int x, int y) {
  return static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x);
}

}  // namespace

void refine_shadow_edges(const SceneData& scene, const ABuffer& camera, const Fragment& f, int x, int y,
                         const CoverageMask* quarter, int count, const PrimaryLights* direct, uint64_t forced,
                         glm::dvec3* colour, const std::function<glm::dvec3(const glm::dvec3&)>& on_surface,
                         const MapShader& shader, MapShadingStats* stats, KnownBlockers* known, uint8_t* sides) {
  bool any = false;
  for (size_t l = 0; l < scene.lights.size(); ++l) {
    bool refine = l < 64 && ((forced >> l) & 1u) != 0;
    for (int k = 1; k < count && !refine; ++k) refine = direct[k].shadow[l] != direct[0].shadow[l];
    if (!refine) continue;
    any = true;
    for (int k = 0; k < count; ++k) {
      if (direct[k].lit[l] == glm::dvec3(0.0)) continue;
      glm::dvec3 sum(0.0);
      for (CoverageMask m = quarter[k]; m; m &= m - 1) {
        const int b = __builtin_ctz(m);
        const glm::dvec3 p =
            point_on_triangle_plane(camera.view, *scene.triangles, f.triangle(), x + sample_dx(b), y + sample_dy(b));
        const glm::dvec3 v = shader.visibility(on_surface(p), l, stats, known);
        sum += v;
        ++stats->shadow_edge_samples;
        if (sides)
          *sides =
              static_cast<uint8_t>(*sides | sample_sides(b) << (v == glm::dvec3(1.0) ? PixelShadows::LIT_SIDES : 0));
      }
      colour[k] += direct[k].lit[l] * (sum / double(mask_count(quarter[k])) - direct[k].shadow[l]);
    }
  }
  if (any) ++stats->shadow_edge_fragments;
}

void PixelShadows::note(size_t at, const SceneData& scene, const PrimaryLights* direct, int count, bool all) {
  for (int k = 0; k < count; ++k) {
    if (!all && k != 0 && k != count - 1) continue;  // given the mean of two, not shaded
    for (size_t l = 0; l < std::min<size_t>(64, scene.lights.size()); ++l) {
      if (!scene.lights[l].cast_shadows || direct[k].lit[l] == glm::dvec3(0.0)) continue;
      (direct[k].shadow[l] == glm::dvec3(1.0) ? lit : dark)[at] |= uint64_t{1} << l;
    }
  }
}

void PixelShadows::forget_rows(const std::vector<uint8_t>& rows, int width) {
  for (size_t p = 0; p < lit.size(); ++p) {
    if (!rows[p / static_cast<size_t>(width)]) continue;
    lit[p] = dark[p] = 0;
    if (!sides.empty()) sides[p] = 0;
  }
}

std::vector<uint64_t> PixelShadows::across(int width, int height, const std::vector<uint8_t>* only) const {
  std::vector<uint64_t> out(lit.size(), 0);
  const auto at = [width](int x, int y) { return pixel_index(width, x, y); };
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t p = at(x, y);
      if (only && !(*only)[p]) continue;
      const uint64_t pure_lit = lit[p] & ~dark[p], pure_dark = dark[p] & ~lit[p];
      uint64_t edge = 0;
      // q: a 4-neighbour; side: q's side that faces this pixel.
      const auto against = [&](size_t q, uint8_t side) {
        edge |= (pure_lit & dark[q] & ~lit[q]) | (pure_dark & lit[q] & ~dark[q]);
        const uint8_t s = sides.empty() ? 0 : sides[q];
        const uint64_t mixed = dark[q] & lit[q];
        if (s & side) edge |= pure_lit & mixed;
        if (s & (side << LIT_SIDES)) edge |= pure_dark & mixed;
      };
      if (x > 0) against(at(x - 1, y), SIDE_RIGHT);
      if (x + 1 < width) against(at(x + 1, y), SIDE_LEFT);
      if (y > 0) against(at(x, y - 1), SIDE_BOTTOM);
      if (y + 1 < height) against(at(x, y + 1), SIDE_TOP);
      out[p] = edge;
    }
  }
  return out;
}

std::vector<uint8_t> with_neighbours(const std::vector<uint8_t>& only, int width, int height) {
  std::vector<uint8_t> out(only);
  const auto at = [width](int x, int y) { return pixel_index(width, x, y); };
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (!only[at(x, y)]) continue;
      if (x > 0) out[at(x - 1, y)] = 1;
      if (x + 1 < width) out[at(x + 1, y)] = 1;
      if (y > 0) out[at(x, y - 1)] = 1;
      if (y + 1 < height) out[at(x, y + 1)] = 1;
    }
  }
  return out;
}

}  // namespace abcube
