// SHADOW EDGES (map_shading.hpp): a shadow's edge inside a pixel, each covered sample given
// its own answer for the light the shading points disagree about; and between pixels, the
// lights whose edge runs between a pixel's points and a neighbour's.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include <glm/glm.hpp>

#include "base/samples.hpp"
#include "raster/abuffer.hpp"
#include "scene/scene_data.hpp"
#include "shading/map_shading.hpp"

namespace abcube {

// For each light whose visibility differs among the `count` shaded points of fragment `f` at
// pixel (x, y) (records `direct`, one a covered quarter `quarter`), or that `forced` names
// (bit l: light l, the first 64), the mean visibility over each quarter's covered samples
// replaces its point's in the quarter's colour: colour[k] += lit_l * (mean - S_l). A
// sample's point is its point of the fragment's plane moved by `on_surface` onto the mesh.
// `sides` (optional) gains the pixel sides that a shadowed, or a lit, sample of a refined
// light lies on (PixelShadows::sides).
void refine_shadow_edges(const SceneData& scene, const ABuffer& camera, const Fragment& f, int x, int y,
                         const CoverageMask* quarter, int count, const PrimaryLights* direct, uint64_t forced,
                         glm::dvec3* colour, const std::function<glm::dvec3(const glm::dvec3&)>& on_surface,
                         const MapShader& shader, MapShadingStats* stats, KnownBlockers* known,
                         uint8_t* sides = nullptr);

// Per pixel, the lights (the first 64) that its shaded points saw wholly lit, and those they
// saw shadowed. A resolve worker owns a row at a time: no two threads write one pixel.
struct PixelShadows {
  std::vector<uint64_t> lit, dark;
  // Per pixel, the sides of the pixel (samples.hpp SIDE_* bits) where its samples, searched
  // one by one for a light its points disagreed about, found a shadowed sample (the low four
  // bits) or a lit one (the same shifted by LIT_SIDES): where a shadow, or a gap of light,
  // reaches the next pixel.
  static constexpr int LIT_SIDES = 4;
  std::vector<uint8_t> sides;
  // Adds the `count` records of a fragment at pixel `at`; `all`: every point was shaded,
  // else only the first and the last (the others took the mean of two).
  void note(size_t at, const SceneData& scene, const PrimaryLights* direct, int count, bool all);
  // Per pixel, the lights it saw only lit where a 4-neighbour saw them only shadowed, or the
  // reverse: an edge between their shading points. And those it saw only lit where a
  // 4-neighbour's points disagreed with a shadowed sample on the side they share, or the
  // reverse: a shadow (or a gap of light) thinner than the points' spacing, met by that
  // neighbour's points, that goes on into this pixel between its own. Pixels outside `only`
  // (when given) get 0.
  std::vector<uint64_t> across(int width, int height, const std::vector<uint8_t>* only) const;
  // Forgets what was noted in the rows `rows` marks (a width-wide image, a byte a row).
  void forget_rows(const std::vector<uint8_t>& rows, int width);
};

// `only` and its 4-neighbours.
std::vector<uint8_t> with_neighbours(const std::vector<uint8_t>& only, int width, int height);

}  // namespace abcube
