// The A-buffers built by GL compute shaders: a second implementation of build_cube_abuffer and
// build_camera_abuffer (cpu_core/raster/abuffer.hpp), with the same lists. The CPU sets up
// each visible (triangle, view) pair (setup_triangle); the GPU counts each pixel's fragments
// (an invocation an 8 x 8 tile of a pair's pixels), turns the counts into list offsets (a
// prefix sum), fills every list with its fragments' masks and geometry, then sorts, merges
// and caps each list (an invocation a pixel; a list too long for that is finished on the
// CPU). The shaders (shaders/abuffer_*.comp) repeat the CPU raster's double-precision
// arithmetic operation for operation, so a GL whose doubles round as IEEE 754 says gives the
// CPU's lists bit for bit; docs/design/gpu-abuffer.md has the layout and its memory bound.
#pragma once
#include <memory>

#include <glm/glm.hpp>

#include "raster/abuffer.hpp"
#include "scene/scene_data.hpp"

namespace abcube {

// The compiled passes, on the GL context current when it was made (GL 4.5 core with storage
// buffers holding at least ABUFFER_ITEMS_BINDING + 1 bindings), which must stay current
// for its life: made once, it builds any number of A-buffers. Each build throws InputError as
// the CPU's does (the bad option, or the memory estimate above the budget: here the GPU's
// buffers and the read-back copy together), and RuntimeFailure when the GL cannot run the
// passes. options.threads sets up the pairs on the CPU.
class GlABufferBuilder {
 public:
  GlABufferBuilder();
  ~GlABufferBuilder();
  GlABufferBuilder(const GlABufferBuilder&) = delete;
  GlABufferBuilder& operator=(const GlABufferBuilder&) = delete;

  // build_cube_abuffer's result and stats.
  CubeABuffer cube(const SceneData& scene, const glm::dvec3& centre, int n, const ABufferOptions& options = {},
                   ABufferStats* stats = nullptr) const;
  // build_camera_abuffer's result and stats.
  ABuffer camera(const SceneData& scene, const ABufferOptions& options = {}, ABufferStats* stats = nullptr) const;

  struct Programs;  // the four passes' programs (gl_abuffer.cpp)

 private:
  std::unique_ptr<Programs> programs_;
};

// One cube A-buffer by a builder made for it (its programs compiled for this call alone).
CubeABuffer build_cube_abuffer_gl(const SceneData& scene, const glm::dvec3& centre, int n,
                                  const ABufferOptions& options = {}, ABufferStats* stats = nullptr);

}  // namespace abcube
