// Resolving an A-buffer list into a pixel colour: Pack_Under_Mask (Carpenter 1984; thesis
// 5.2.1.1 and 5.2.1.2). The first fragment over the search mask splits it into `in` and
// `out`; where the next fragment of another object overlaps it in z, EXACT PRIORITY MASKS
// (thesis 11.2.4) decide per sample by THE TIE RULE which plane is seen first (given the
// pixel's SampleDepth), each of the two shaded over the samples where it is seen; or the
// thesis' Vis estimate from the z ranges does (without it). pack is evaluated with an
// explicit stack of (list position, mask, weight) items: no stack overflow on long lists,
// each fragment shaded at most once over its mask, at most 32 items a position.
// docs/design/resolve.md has the pseudo-code and the whole argument.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "raster/abuffer.hpp"
#include "raster/raster.hpp"
#include "io/image.hpp"
#include "scene/scene_data.hpp"

namespace abcube {

// What the caller's shading says about a fragment.
struct ShadedFragment {
  glm::dvec3 colour{0.0};
  double opacity = 1.0;  // material opacity in [0, 1]; < 1 blends with what is behind
};

// Shades one fragment of the list being packed.
using FragmentShader = std::function<ShadedFragment(const Fragment&)>;

// Reusable memory for pack_under_mask (one per thread); optional.
struct PackScratch {
  std::vector<ShadedFragment> shaded;
  std::vector<unsigned char> done;
  struct Item {
    size_t position;
    CoverageMask mask;
    double weight;
  };
  std::vector<Item> stack;
};

// The geometry of one pixel for EXACT PRIORITY MASKS: where each sample's eye ray meets a
// fragment's triangle plane.
struct SampleDepth {
  const RasterView* view = nullptr;
  const TriangleSoup* triangles = nullptr;
  int x = 0, y = 0;
  // Ray parameter t of sample k's ray centre + t D_k (D_k = view->direction(x + dx, y + dy))
  // at the plane of fragment f's triangle; +inf when the ray runs along the plane.
  double t(const Fragment& f, int k) const;
  // The samples of `in` where b's plane is seen before a's (THE TIE RULE, tie_rule.hpp).
  CoverageMask nearer(const Fragment& a, const Fragment& b, CoverageMask in) const;
};

// The colour of the part `search` of a pixel whose list is `list` (front to back).
// `triangles` gives each fragment's object id (the intersection test); `depth` (optional)
// the pixel's geometry for exact priority masks (else the thesis' Vis_front estimate).
glm::dvec3 pack_under_mask(FragmentList list, CoverageMask search, const FragmentShader& shade,
                           const TriangleSoup& triangles, const glm::dvec3& background, PackScratch* scratch = nullptr,
                           const SampleDepth* depth = nullptr);

// THE RESOLVE PLAN: pack_under_mask split in two. Its masks, weights and the order in which
// it shades never depend on a fragment's colour, only on its material's opacity (every
// shader here answers that opacity), so a planner that knows the opacities can write down a
// pixel's resolve as steps, and the colours come after: shade these fragments, in this
// order, and sum them with these weights. The GPU plans (host/gl/gl_resolve_plan.hpp); the
// CPU runs the steps, calling the shader exactly as pack_under_mask would, and with the
// same sums, so the colour is pack_under_mask's bit for bit.
struct ResolveStep {
  enum Kind : uint32_t {
    shade = 0,       // shade at[0] over its whole mask (once a pixel: later steps reuse it)
    add = 1,         // colour += weight[0] * C(0)
    add_two = 2,     // colour += weight[0] * C(0) + weight[1] * C(1), C(1) zero if at[1] is NONE
    background = 3,  // colour += weight[0] * background
  };
  static constexpr uint32_t NONE = 0xffffffffu;
  uint32_t kind = shade;
  uint32_t at[2] = {NONE, NONE};  // list positions of the colours summed (C(k)), in shading order
  CoverageMask mask[2] = {0, 0};  // 0: the fragment's whole shade; else the samples it is shaded over
  uint32_t pad = 0;
  double weight[2] = {0.0, 0.0};
};
static_assert(sizeof(ResolveStep) == 40, "ResolveStep must match shaders/resolve_plan.comp");

// A camera A-buffer's plan: pixel p's steps are steps[offsets[p], offsets[p + 1]). A pixel
// whose `planned` is 0 is left to pack_under_mask (the planner's stack or loops ran out).
struct ResolvePlan {
  std::vector<uint32_t> offsets;
  std::vector<ResolveStep> steps;
  std::vector<uint8_t> planned;
  std::vector<double> opacity;  // each material's, clamped to [0, 1]: what the plan assumed
  size_t fragments = 0;         // the A-buffer's fragment count (a check that it is this one)
  bool exact_priority = true;   // the rule it planned intersecting fragments by

  // Throws InputError unless this plan is of `camera` with `exact_priority`'s rule.
  void check(const ABuffer& camera, bool exact_priority) const;
};

// Shades fragment f of pixel (x, y) of the camera A-buffer.
using PixelShader = std::function<ShadedFragment(const Fragment& f, int x, int y)>;

struct ResolveOptions {
  int threads = 0;  // 0 = std::thread::hardware_concurrency()
  // Intersecting fragments: EXACT PRIORITY MASKS (true) or the thesis' Vis_front estimate.
  bool exact_priority = true;
  // When set (width x height, row 0 at the top): only the pixels whose entry is not 0 are
  // resolved; the others stay black (the hybrid method: the pixels the GPU left to the CPU).
  const std::vector<uint8_t>* only = nullptr;
  // Called now and then on the calling thread with the share of rows resolved, in [0, 1].
  std::function<void(double)> progress;
  // When set: the pixels it planned are resolved by its steps (the same colours), the others
  // by pack_under_mask. It must be this A-buffer's, with exact_priority's rule.
  const ResolvePlan* plan = nullptr;
};

// The antialiased image (row 0 at the top): pack_under_mask(list, FULL_MASK) per pixel.
// Rows go to threads dynamically; every pixel is computed the same way whatever the
// thread, so the image is identical for any number of threads. `shade` is called from
// several threads at once.
Image resolve_image(const ABuffer& camera, const TriangleSoup& triangles, const PixelShader& shade,
                    const glm::dvec3& background, const ResolveOptions& options = {});

// Same, `shade` told which worker calls it (0 to resolve_workers() - 1; one worker never
// runs two calls at once), so per-worker state (statistics) needs no lock.
using WorkerPixelShader = std::function<ShadedFragment(const Fragment& f, int x, int y, int worker)>;
int resolve_workers(const ABuffer& camera, const ResolveOptions& options);
Image resolve_image_per_worker(const ABuffer& camera, const TriangleSoup& triangles, const WorkerPixelShader& shade,
                               const glm::dvec3& background, const ResolveOptions& options = {});

// A shade for checking resolves: the fragment, its mask and the pixel hashed into a colour,
// with its material's opacity. A step at another fragment or over another mask, or a weight
// off by more than the image's float rounding, shows in the colours it sums.
ShadedFragment probe_shade(const SceneData& scene, const Fragment& f, int x, int y);

// Where resolving `camera` by `plan` (made under its exact_priority rule) with probe_shade
// differs from pack_under_mask: "pixel (x, y)", the first such, or empty when every colour
// is the same bits.
std::string plan_differs_from_pack(const ABuffer& camera, const SceneData& scene, const ResolvePlan& plan);

// What each of the 32 samples of pixel (x, y) sees: the triangle of the nearest surface
// covering it (NO_SAMPLE_TRIANGLE where none), by the list's coverage masks and, where
// fragments of different objects overlap in depth, the EXACT PRIORITY MASKS rule (each
// sample's own eye ray, THE TIE RULE): the GPU's Z-buffer at the same sample positions
// sees the same surfaces (`abcube crosscheck`, sample by sample). Opacity is not applied:
// this is visibility.
constexpr uint32_t NO_SAMPLE_TRIANGLE = 0xffffffffu;
void visible_triangles(const ABuffer& camera, const TriangleSoup& triangles, int x, int y, uint32_t out[MASK_SAMPLES]);

}  // namespace abcube
