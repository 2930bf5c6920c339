// The cube A-buffer built by GL compute shaders: a second implementation of
// build_cube_abuffer (cpu_core/raster/abuffer.hpp), with the same lists. The CPU sets up each
// visible (triangle, face) pair (setup_triangle); the GPU counts each pixel's fragments (one
// workgroup a pair), turns the counts into list offsets (a prefix sum), fills every list with
// its fragments' masks and geometry, then sorts, merges and caps each list (one invocation a
// pixel). The shaders (shaders/abuffer_*.comp) repeat the CPU raster's double-precision
// arithmetic operation for operation, so a GL whose doubles round as IEEE 754 says gives the
// CPU's lists bit for bit; docs/design/gpu-abuffer.md has the layout and its memory bound.
#pragma once
#include <glm/glm.hpp>

#include "raster/abuffer.hpp"
#include "scene/scene_data.hpp"

namespace abcube {

// build_cube_abuffer's result and stats, on the current GL context (GL 4.5 core with
// storage buffers holding at least ABUFFER_SCAN_SUMS_BINDING + 1 bindings). Throws
// InputError as build_cube_abuffer does (the bad option, or the memory estimate above the
// budget: here the GPU's buffers and the read-back copy together), and RuntimeFailure when
// the GL cannot run the passes. options.threads sets up the pairs on the CPU.
CubeABuffer build_cube_abuffer_gl(const SceneData& scene, const glm::dvec3& centre, int n,
                                  const ABufferOptions& options = {}, ABufferStats* stats = nullptr);

}  // namespace abcube
