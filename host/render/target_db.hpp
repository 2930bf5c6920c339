// --target-db: the abuffer method's cube-map resolution N chosen for a PSNR target.
//
// Pilot renders, each judged against the exact tracer on a sample of pixels, climb a ladder
// of N from small to large and stop at the first whose predicted PSNR (the one-sided 95%
// lower bound of the sample's estimate, io/metrics.hpp sampled_error) reaches the target.
// When the error stops improving first, the best N found is kept and the stats say the
// target was not reached. The sample is one pixel in each b x b block (b from 2 to 8 as
// the image grows), chosen by a fixed hash: the same pixels every run. One shading point a
// fragment at the ladder's first N is piloted first: where it reaches the target it is the
// choice. Else the ladder is climbed with the quarters unrefined at the samples (the
// cheapest pilots that shade every quarter), and again with the plan asked for only when
// that stops short. At the N chosen,
// more pilots try cheaper shading, cheapest first, and keep the first that still reaches
// the target: one shading point per fragment instead of the quarters; the quarters without
// the shadow and secondary edges' refinement at the samples; without the secondary edges'.
// Then THE COST MODEL (target_db.cpp): from a pilot's counts of search rays, fragment tests
// and mesh refinement's triangles, the next N up is piloted where the model expects it to
// shade for enough less to pay for the pilot, and chosen when it reaches the target and
// its counts say it does (meshes finer than the texels cost less at a larger N).
#pragma once
#include <cstdint>
#include <vector>

#include "render/method_context.hpp"

namespace abcube {

// The raytrace method at a target: the smallest rung of THE SAMPLE LADDER (samples.hpp) whose
// predicted PSNR against the 32 samples reaches it. One pilot traces the sampled pixels
// (pilot_pixels) at the 32 samples and the pixel's centre: every lower rung is a prefix of
// them, so one pilot judges them all. The image is then traced at that rung, the pilot's
// pixels taken from the pilot (the same bits). Writes stats["target_db"] and
// record.timings_ms["target_pilots"]; the stats' raytrace entry is the whole image's.
Image raytrace_for_target(MethodContext& mc);

// The ladder of N the pilots climb, up to max(1024, the scene's own N).
std::vector<int> target_ladder(int scene_n);

// The pilots' pixels: width x height, row-major, non-zero = sampled; `block` gets b.
std::vector<uint8_t> pilot_pixels(int width, int height, int* block);

// The cube map at the chosen N, its shader measuring ray errors against `reference` when
// given. `camera` is the camera's A-buffer the pilots shade; `cube_options` budget the
// cube with it held. Writes stats["target_db"] and record.timings_ms["target_pilots"].
CubeMap cube_map_for_target(MethodContext& mc, const ABuffer& camera, const ABufferOptions& cube_options,
                            const RayTracer* reference);

}  // namespace abcube
