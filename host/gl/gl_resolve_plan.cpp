#include "gl/gl_resolve_plan.hpp"

#include <glad/gl.h>

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "base/error.hpp"
#include "base/timer.hpp"
#include "gl/gl_compute.hpp"
#include "gl/gl_program.hpp"
#include "gl/gl_view.hpp"
#include "gl/glsl_shared.hpp"
#include "scene/scene_load.hpp"
#include "scene/tie_rule.hpp"

namespace abcube {

namespace {

// resolve_plan.comp's TriangleInfo in std430.
struct GpuTriangleInfo {
  uint32_t object, pad;
  double opacity;
};
static_assert(sizeof(GpuTriangleInfo) == 16, "must match shaders/resolve_plan.comp");

// The steps a fill pass writes at most: a band of pixels whose steps fit one storage block,
// and no more than 64 MiB on the GPU at a time.
uint64_t band_steps(const ResolvePlanOptions& options) {
  const uint64_t most =
      std::max<uint64_t>(1, std::min<uint64_t>(max_block_bytes(), uint64_t{64} << 20) / sizeof(ResolveStep));
  return options.band_steps ? std::min(options.band_steps, most) : most;
}

const char* const WHAT = "GPU resolve plan";

// The statuses both passes gave (two words a pixel: steps, status) must show every invocation
// ran to its end (bit 4), with the same steps in both.
void check_passes(const std::vector<uint32_t>& counted, const std::vector<uint32_t>& filled, size_t first, size_t end) {
  for (size_t p = first; p < end; ++p) {
    const uint32_t status = counted[2 * p + 1];
    if (!(status & 4u) || filled[2 * (p - first)] != counted[2 * p] || filled[2 * (p - first) + 1] != status) {
      throw RuntimeFailure(std::string(WHAT) + ": the GL ended pixel " + std::to_string(p) +
                           "'s plan early or differently between its passes; resolve on the CPU");
    }
  }
}

}  // namespace

GlResolvePlanner::GlResolvePlanner() {
  require_storage_bindings(WHAT, std::max({RESOLVE_VIEW_BINDING, RESOLVE_LISTS_BINDING, RESOLVE_FRAGMENTS_BINDING,
                                           RESOLVE_TRIANGLES_BINDING, RESOLVE_POSITIONS_BINDING, RESOLVE_COUNTS_BINDING,
                                           RESOLVE_STARTS_BINDING, RESOLVE_STEPS_BINDING}));
  require_compute_blocks(WHAT, 8);
  program_ = std::make_unique<GlProgram>(
      std::vector<const char*>{"double_math.glsl", "fragment.glsl", "view.glsl", "resolve_plan.comp"});
}

GlResolvePlanner::~GlResolvePlanner() = default;

uint64_t GlResolvePlanner::upload_bytes(const ABuffer& camera, const SceneData& scene) {
  const uint64_t pixels = camera.view.pixel_count();
  const uint64_t triangles = scene.triangles->triangle_count();
  return sizeof(GpuView) + (pixels + 1) * sizeof(uint32_t) + camera.fragments.size() * sizeof(Fragment) +
         triangles * (sizeof(GpuTriangleInfo) + 9 * sizeof(float)) + 2 * pixels * 2 * sizeof(uint32_t) +
         (pixels + 1) * sizeof(uint32_t);
}

namespace {

// The plan's inputs on the GPU, bound, with the program's uniforms set.
struct PlanUpload {
  GlBuffer view, lists, fragments, triangles, positions;

  PlanUpload(const GlProgram& p, const ABuffer& camera, const TriangleSoup& soup, const ResolvePlanOptions& options,
             const GpuView& v, const std::vector<GpuTriangleInfo>& info)
      : view(sizeof(v), &v),
        lists(camera.offsets.size() * sizeof(uint32_t), camera.offsets.data()),
        fragments(camera.fragments.size() * sizeof(Fragment), camera.fragments.data()),
        triangles(info.size() * sizeof(GpuTriangleInfo), info.data()),
        positions(soup.positions.size() * sizeof(glm::vec3), soup.positions.data()) {
    p.use();
    view.bind(RESOLVE_VIEW_BINDING);
    lists.bind(RESOLVE_LISTS_BINDING);
    fragments.bind(RESOLVE_FRAGMENTS_BINDING);
    triangles.bind(RESOLVE_TRIANGLES_BINDING);
    positions.bind(RESOLVE_POSITIONS_BINDING);
    glUniform1i(p.uniform("exact_priority"), options.exact_priority ? 1 : 0);
    glUniform3d(p.uniform("centre"), camera.view.centre.x, camera.view.centre.y, camera.view.centre.z);
    glUniform1d(p.uniform("tie_relative"), TIE_RELATIVE);
    glUniform1ui(p.uniform("loop_budget"), options.loop_budget);
    glUniform1ui(p.uniform("one"), 1u);
  }
};

// One dispatch over pixels [first, first + count), counting (writing false) or writing steps
// at the bound starts, each pixel's count and status written at the bound counts.
void run_pass(const GlProgram& p, size_t first, size_t count, bool writing) {
  glUniform1ui(p.uniform("first_pixel"), static_cast<GLuint>(first));
  glUniform1ui(p.uniform("pixel_count"), static_cast<GLuint>(count));
  glUniform1i(p.uniform("writing"), writing ? 1 : 0);
  dispatch(p, (count + 63) / 64);
}

// The count pass: two words a pixel, its steps and its status.
std::vector<uint32_t> count_steps(const GlProgram& p, size_t pixels) {
  const GlBuffer counts(2 * pixels * sizeof(uint32_t), nullptr);
  const GlBuffer no_starts(4, nullptr), no_steps(sizeof(ResolveStep), nullptr);
  counts.bind(RESOLVE_COUNTS_BINDING);
  no_starts.bind(RESOLVE_STARTS_BINDING);
  no_steps.bind(RESOLVE_STEPS_BINDING);
  run_pass(p, 0, pixels, false);
  return counts.read<uint32_t>(2 * pixels);
}

// The fill pass in bands of whole pixels whose steps fit `band`, into out->steps.
void fill_steps(const GlProgram& p, const std::vector<uint32_t>& counted, uint64_t band, ResolvePlan* out) {
  const size_t pixels = out->planned.size();
  for (size_t first = 0; first < pixels;) {
    size_t end = first + 1;
    while (end < pixels && out->offsets[end + 1] - out->offsets[first] <= band) ++end;
    const uint32_t base = out->offsets[first];
    std::vector<uint32_t> starts(end - first + 1);
    for (size_t q = first; q <= end; ++q) starts[q - first] = out->offsets[q] - base;
    const uint64_t count = starts.back();
    const GlBuffer start_buffer(starts.size() * sizeof(uint32_t), starts.data());
    // Every word all ones first: a step the GPU did not write reads as no kind at no fragment,
    // which run_steps refuses, never as a shade of the list's first fragment.
    const GlBuffer step_buffer(std::max<uint64_t>(count, 1) * sizeof(ResolveStep), nullptr);
    step_buffer.fill(0xffffffffu);
    const GlBuffer band_counts(2 * (end - first) * sizeof(uint32_t), nullptr);
    start_buffer.bind(RESOLVE_STARTS_BINDING);
    step_buffer.bind(RESOLVE_STEPS_BINDING);
    band_counts.bind(RESOLVE_COUNTS_BINDING);
    run_pass(p, first, end - first, true);
    check_passes(counted, band_counts.read<uint32_t>(2 * (end - first)), first, end);
    const std::vector<ResolveStep> got = step_buffer.read<ResolveStep>(count);
    if (base + count > out->steps.size()) throw std::logic_error("GPU resolve plan: a band past its steps");
    std::copy(got.begin(), got.end(), out->steps.begin() + base);
    first = end;
  }
}

}  // namespace

ResolvePlan GlResolvePlanner::plan(const ABuffer& camera, const SceneData& scene, const ResolvePlanOptions& options,
                                   ResolvePlanStats* stats) const {
  const Clock::time_point t0 = Clock::now();
  const TriangleSoup& soup = *scene.triangles;
  const size_t pixels = camera.view.pixel_count();
  const uint64_t upload = upload_bytes(camera, scene);
  const auto over_budget = [&](uint64_t bytes, const std::string& what) {
    if (options.max_bytes && bytes > options.max_bytes) {
      throw InputError(std::string(WHAT) + ": " + what + " take " + std::to_string(bytes >> 20) +
                       " MiB, over the memory budget's " + std::to_string(options.max_bytes >> 20) +
                       " MiB left; raise --max-memory or resolve on the CPU");
    }
  };
  over_budget(upload, "its lists and triangles");
  require_block_bytes(std::string(WHAT) + ": the camera's fragments", camera.fragments.size() * sizeof(Fragment),
                      "resolve on the CPU");
  require_block_bytes(std::string(WHAT) + ": the pixels' counts", 2 * uint64_t{pixels} * sizeof(uint32_t),
                      "resolve on the CPU");
  if (options.only && options.only->size() != pixels)
    throw std::logic_error("GPU resolve plan: `only` of another size");

  ResolvePlan out;
  out.exact_priority = options.exact_priority;
  out.fragments = camera.fragments.size();
  for (const Material& m : scene.materials) out.opacity.push_back(std::clamp(m.opacity, 0.0, 1.0));
  std::vector<GpuTriangleInfo> info(soup.triangle_count());
  for (size_t t = 0; t < info.size(); ++t) info[t] = {soup.object_id[t], 0u, out.opacity[soup.material_id[t]]};
  const PlanUpload bound(*program_, camera, soup, options, gpu_view(camera.view, 0), info);
  const std::vector<uint32_t> counted = count_steps(*program_, pixels);

  // Each pixel's steps from the count: none where it is left to the CPU.
  // The offsets are 32-bit: a plan of more steps is refused before they could wrap.
  out.offsets.assign(pixels + 1, 0);
  out.planned.assign(pixels, 0);
  uint64_t total = 0;
  for (size_t q = 0; q < pixels; ++q) {
    const bool planned = (counted[2 * q + 1] & 3u) == 1u && (!options.only || (*options.only)[q]);
    out.planned[q] = planned ? 1 : 0;
    total += planned ? counted[2 * q] : 0u;
    if (total > UINT32_MAX) {
      throw InputError(std::string(WHAT) + ": more than " + std::to_string(UINT32_MAX) +
                       " steps, past a plan's offsets; resolve on the CPU");
    }
    out.offsets[q + 1] = static_cast<uint32_t>(total);
  }
  const uint64_t band = band_steps(options);
  // At the peak: the upload, the plan on the host, and one band on the GPU and in its copy back.
  const uint64_t held = upload + pixels + (total + 2 * std::min(total, band)) * sizeof(ResolveStep);
  over_budget(held, "its " + std::to_string(total) + " steps and upload");
  out.steps.resize(total);
  fill_steps(*program_, counted, band, &out);
  check_gl(WHAT);
  if (stats) {
    stats->pixels = pixels;
    stats->planned = static_cast<uint64_t>(std::count(out.planned.begin(), out.planned.end(), 1));
    stats->steps = total;
    stats->bytes = held;
    stats->ms = ms_since(t0);
  }
  return out;
}

namespace {

// The probe's scene: in most pixels two or more half-transparent layers, where the quads
// cross two objects' fragments at nearly the same depth (the EXACT PRIORITY MASKS, THE TIE
// RULE), and partly covered pixels along every edge.
const char* const PROBE_SCENE = R"({"version": 1,
  "camera": {"position": [0.13, 0.21, 3.1], "look_at": [0, 0, 0], "fov_y": 40, "width": 24, "height": 18},
  "background": [0.2, 0.3, 0.4],
  "materials": {"veil": {"color": [0.8, 0.2, 0.2], "opacity": 0.5}, "glass": {"color": [0.2, 0.8, 0.2], "opacity": 0.7},
                "mist": {"color": [0.3, 0.3, 0.9], "opacity": 0.3}},
  "objects": [
    {"type": "quad", "vertices": [[-1, -1, -0.5], [1, -1, 0.5], [1, 1, 0.5], [-1, 1, -0.5]], "material": "veil"},
    {"type": "quad", "vertices": [[-1, -1, 0.5], [1, -1, -0.5], [1, 1, -0.5], [-1, 1, 0.5]], "material": "glass"},
    {"type": "sphere", "center": [0.3, 0.2, 0.9], "radius": 0.45, "segments": 10, "material": "mist"},
    {"type": "box", "min": [-1.6, -1.6, -1.6], "max": [1.6, 1.6, -1.3]}]})";

}  // namespace

const std::string& GlResolvePlanner::probe(double* ms) const {
  const Clock::time_point t0 = Clock::now();
  if (!probe_) {
    std::string why;
    const SceneData scene = load_scene_text(PROBE_SCENE, "the resolve plan's probe", ".");
    const ABuffer camera = build_camera_abuffer(scene);
    for (const bool exact : {true, false}) {
      ResolvePlanOptions o;
      o.exact_priority = exact;
      ResolvePlanStats s;
      const ResolvePlan plan = this->plan(camera, scene, o, &s);
      const std::string rule = exact ? " (exact priority masks)" : " (the Vis estimate)";
      if (s.planned < s.pixels) {
        why = "the GL left " + std::to_string(s.pixels - s.planned) + " of a probe's pixels unplanned" + rule;
      } else if (const std::string at = plan_differs_from_pack(camera, scene, plan); !at.empty()) {
        why = "the GL's plan of a probe scene gives another colour than the CPU's resolve at " + at + rule +
              ": its doubles do not round as the CPU's";
      }
      if (!why.empty()) break;
    }
    probe_ = why;
  }
  if (ms) *ms = ms_since(t0);
  return *probe_;
}

}  // namespace abcube
