// THE RESOLVE PLAN (cpu_core/shading/resolve.hpp) made by a GL compute shader
// (shaders/resolve_plan.comp), an invocation a pixel of the camera's A-buffer: Pack_Under_Mask
// run over each list with the materials' opacities, writing down what it shades, in its
// order, and the weights it sums them with. Its expressions (the masks' weights, the EXACT
// PRIORITY MASKS' planes and THE TIE RULE) are the CPU's in double precision, operation for
// operation, so that on a GL whose doubles round as IEEE 754 says the CPU's run of the steps
// gives resolve_image's colours bit for bit. docs/design/gpu-abuffer.md has the layout.
#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "raster/abuffer.hpp"
#include "scene/scene_data.hpp"
#include "shading/resolve.hpp"

namespace abcube {

class GlProgram;

// A pixel's plan passes over its list and stack at most this many times (counted as the
// shader's loops may cost) before it is left to the CPU: under llvmpipe's silent 65535.
constexpr uint32_t GPU_RESOLVE_LOOP_BUDGET = 30000;

struct ResolvePlanOptions {
  bool exact_priority = true;  // EXACT PRIORITY MASKS (true) or the thesis' Vis_front estimate
  uint32_t loop_budget = GPU_RESOLVE_LOOP_BUDGET;
  // The memory the plan may take, its upload and its steps on the GPU and the host: 0, none.
  uint64_t max_bytes = 0;
  // The most steps one fill dispatch writes: 0, as many as one storage block holds (at most
  // 64 MiB of them). A pixel's steps are never split; a smaller band only adds dispatches.
  uint64_t band_steps = 0;
  // When set (a byte a pixel, as ResolveOptions::only): only the pixels whose entry is not 0
  // are planned; the others are left to pack, as pixels past the loop budget are (hybrid's
  // CPU part resolves only its pixels, and their neighbours for its edge passes).
  const std::vector<uint8_t>* only = nullptr;
};

// What a plan took.
struct ResolvePlanStats {
  uint64_t pixels = 0, planned = 0, steps = 0;
  uint64_t bytes = 0;  // the most it held, on the GPU and the host together
  double ms = 0;
};

// The compiled program, on the GL context current when it was made (GL 4.5 core with 8
// storage blocks to a compute shader), which must stay current for its life.
class GlResolvePlanner {
 public:
  GlResolvePlanner();
  ~GlResolvePlanner();
  GlResolvePlanner(const GlResolvePlanner&) = delete;
  GlResolvePlanner& operator=(const GlResolvePlanner&) = delete;

  // The plan of `camera`, an A-buffer of `scene`'s triangles. Throws InputError when it
  // would pass options.max_bytes (the figures named), RuntimeFailure when the GL cannot run
  // it or ended an invocation's loops early.
  ResolvePlan plan(const ABuffer& camera, const SceneData& scene, const ResolvePlanOptions& options = {},
                   ResolvePlanStats* stats = nullptr) const;

  // The bytes a plan of `camera` holds before its steps are counted: its upload.
  static uint64_t upload_bytes(const ABuffer& camera, const SceneData& scene);

  // THE PROBE: this GL's plans of a small built-in scene (two half-transparent quads that
  // cross, a faceted veil in front, an opaque wall behind), under both rules, held to
  // pack_under_mask bit for bit (plan_differs_from_pack). Empty when every colour agrees,
  // else why not: a GL whose doubles do not round as IEEE 754 says would change images. Run
  // at the first call only; its time is in `ms`.
  const std::string& probe(double* ms = nullptr) const;

 private:
  std::unique_ptr<GlProgram> program_;
  mutable std::optional<std::string> probe_;
};

}  // namespace abcube
