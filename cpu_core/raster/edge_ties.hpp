// Pixels where a rasteriser with snapped vertices may decide a sample unlike the exact
// rules (raster.hpp's coverage, the tracer's ray through the sample): where a triangle's
// edge passes within `eps` samples of a sample centre.
//
// GL rasterisers snap window coordinates to a sub-pixel grid (8 bits on llvmpipe and
// D3D-class GPUs: 1/256 of a target pixel, which the exact camera pass makes one sample), so
// an edge may move by up to 1/512 of a sample before its samples are tested. An edge
// parallel to a sample row (the top of an upright mirror seen level) puts a whole row of
// samples that close at once: a line of pixels a quarter wrong. The hybrid method hands
// every marked pixel to the CPU's A-buffer, whose coverage follows the exact rules.
//
// Every edge of every triangle (hidden or not: conservative), in double, projected by the
// camera (camera.hpp) onto the sample grid (samples.hpp); the part behind the eye is cut at
// depth 1e-6 of the scene's reach from the eye. Cost: one step per sample column (or row)
// an edge spans on screen.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "raster/raster.hpp"
#include "scene/scene_data.hpp"

namespace abcube {

// 1 for every pixel (row-major, width x height of scene.camera) with a sample within `eps`
// of an edge, measured along the edge's minor axis (the sample row or column it crosses).
// Snapping each end by up to 1/512 on each axis moves the edge along that axis by at most
// (1 + |slope|) / 512 <= 1/256 (|slope| <= 1 on the minor axis); the default is twice that.
constexpr double EDGE_TIE_EPS = 1.0 / 128.0;
// Calls visit(sx, sy) for each such sample, by its column and row in the sample grid (once
// per edge that comes that close).
void visit_edge_ties(const SceneData& scene, double eps, const std::function<void(int64_t, int64_t)>& visit);
std::vector<uint8_t> edge_tie_pixels(const SceneData& scene, double eps = EDGE_TIE_EPS);
// The same for any view (raster.hpp: a camera image, a cube face) with `columns` x `rows`
// samples a pixel (1 x 1: a GL pass sampling each pixel's centre, as the cube prepass).
void visit_edge_ties(const RasterView& view, int columns, int rows, const TriangleSoup& soup, double eps,
                     const std::function<void(int64_t, int64_t)>& visit);
// The same per sample: (width * 8) x (height * 4), row-major, row 0 at the top (crosscheck).
std::vector<uint8_t> edge_tie_samples(const SceneData& scene, double eps = EDGE_TIE_EPS);

}  // namespace abcube
