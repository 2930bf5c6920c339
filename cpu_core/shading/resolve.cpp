#include "shading/resolve.hpp"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "base/error.hpp"
#include "base/parallel.hpp"
#include "scene/tie_rule.hpp"

namespace abcube {

namespace {

// Thesis 5.2.1.2, Vis_front = (zmax_next - zmin_front) / ((zmax-zmin)_front + (zmax-zmin)_next),
// clamped to [0, 1]; 1 when both ranges are empty.
double visible_fraction(const Fragment& front, const Fragment& next) {
  const double denom = (double(front.zmax) - front.zmin) + (double(next.zmax) - next.zmin);
  if (!(denom > 0.0)) return 1.0;
  return std::clamp((double(next.zmax) - front.zmin) / denom, 0.0, 1.0);
}

// The first fragment at or after `i` whose mask meets `mask` (list.size() if none).
size_t first_overlapping(FragmentList list, size_t i, CoverageMask mask) {
  while (i < list.size() && (list[i].mask & mask) == 0) ++i;
  return i;
}

// Pack_Under_Mask as a weighted sum (resolve.hpp): items (position, mask, weight) stand
// for "weight * pack(list from position, mask)".
template <class Shade>
glm::dvec3 pack(FragmentList list, CoverageMask search, Shade&& shade, const TriangleSoup& triangles,
                const glm::dvec3& background, PackScratch* sc, const SampleDepth* depth) {
  if (search == 0) return background;
  const size_t n = list.size();
  sc->shaded.resize(n);
  sc->done.assign(n, 0);
  sc->stack.clear();
  const auto shaded = [&](size_t i) -> const ShadedFragment& {
    if (!sc->done[i]) {
      sc->shaded[i] = shade(list[i]);
      sc->shaded[i].opacity = std::clamp(sc->shaded[i].opacity, 0.0, 1.0);
      sc->done[i] = 1;
    }
    return sc->shaded[i];
  };
  // A fragment seen over only part of its mask, where another's plane passes in front of
  // its own inside the pixel: shaded over the samples where it is seen (its shading points
  // then lie there, not on its hidden part, which may be in another light: a floor running
  // on behind a wall), and not kept (its whole-mask shade stays the cached one).
  const auto shaded_over = [&](size_t i, CoverageMask seen) -> ShadedFragment {
    if ((list[i].mask & ~seen) == 0) return shaded(i);
    Fragment part = list[i];
    part.mask = seen;
    ShadedFragment s = shade(part);
    s.opacity = std::clamp(s.opacity, 0.0, 1.0);
    return s;
  };
  glm::dvec3 colour(0.0);
  sc->stack.push_back({0, search, 1.0});
  while (!sc->stack.empty()) {
    const PackScratch::Item item = sc->stack.back();
    sc->stack.pop_back();
    const size_t i = first_overlapping(list, item.position, item.mask);
    if (i == n) {  // nothing left under this mask
      colour += item.weight * background;
      continue;
    }
    const Fragment& f = list[i];
    // Thesis 5.2.1.1: M_in = M_search & M_f, M_out = M_search & ~M_f; areas from bit counts,
    // C = (a_in C_in + a_out C_out) / (a_in + a_out).
    const CoverageMask in = item.mask & f.mask, out = item.mask & ~f.mask;
    const double total = mask_count(item.mask);
    if (out != 0) sc->stack.push_back({i + 1, out, item.weight * (mask_count(out) / total)});
    const double w_in = item.weight * (mask_count(in) / total);

    const ShadedFragment& sf = shaded(i);
    double alpha = sf.opacity;  // thesis 5.2.1.1: C_in = Op_f C_f + (1 - Op_f) C_behind
    const size_t j = first_overlapping(list, i + 1, in);
    const bool intersecting =
        j < n && list[j].zmin <= f.zmax && triangles.object_id[list[j].triangle()] != triangles.object_id[f.triangle()];
    if (intersecting && depth) {
      // EXACT PRIORITY MASKS (thesis 11.2.4; docs/design/resolve.md): next is in front where
      // its plane is nearer.
      const CoverageMask behind = depth->nearer(f, list[j], in & list[j].mask), front = in & ~behind;
      if (behind != 0) {
        const double w_b = w_in * (mask_count(behind) / static_cast<double>(mask_count(in)));
        const ShadedFragment sn = shaded_over(j, behind);
        const glm::dvec3 f_colour = sn.opacity < 1.0 ? shaded_over(i, behind).colour : glm::dvec3(0.0);
        colour += (w_b * sn.opacity) * sn.colour + (w_b * (1.0 - sn.opacity) * sf.opacity) * f_colour;
        const double through = w_b * (1.0 - sn.opacity) * (1.0 - sf.opacity);
        if (through > 0.0) sc->stack.push_back({j + 1, behind, through});
      }
      if (front != 0) {
        const double w_f = w_in * (mask_count(front) / static_cast<double>(mask_count(in)));
        colour += (w_f * sf.opacity) * shaded_over(i, front).colour;
        if (sf.opacity < 1.0) sc->stack.push_back({i + 1, front, w_f * (1.0 - sf.opacity)});
      }
      continue;
    }
    if (intersecting) {
      // Thesis 5.2.1.2, intersecting surfaces: alpha_in = Vis Op_f + (1 - Vis)(1 - alpha_next),
      // times Op_f for a transparent front fragment (resolve.hpp).
      const double vis = visible_fraction(f, list[j]);
      alpha = sf.opacity * (vis + (1.0 - vis) * (1.0 - shaded(j).opacity));
    }
    colour += (w_in * alpha) * sf.colour;
    if (alpha < 1.0) sc->stack.push_back({i + 1, in, w_in * (1.0 - alpha)});
  }
  return colour;
}

// A pixel's colour by its planned steps (ResolvePlan): the shader called in pack's order,
// whole shades kept as pack keeps them, and each sum pack's expression. A shade whose
// opacity is not the one planned would make the plan wrong: a logic error, never trusted.
template <class Shade>
glm::dvec3 run_steps(FragmentList list, const ResolveStep* steps, size_t count, Shade&& shade,
                     const TriangleSoup& triangles, const ResolvePlan& plan, const glm::dvec3& background,
                     PackScratch* sc) {
  sc->shaded.resize(list.size());
  sc->done.assign(list.size(), 0);
  const auto checked = [&](const Fragment& f) {
    ShadedFragment s = shade(f);
    s.opacity = std::clamp(s.opacity, 0.0, 1.0);
    if (s.opacity != plan.opacity[triangles.material_id[f.triangle()]]) {
      throw std::logic_error("resolve plan: a shader answered an opacity other than its material's");
    }
    return s;
  };
  const auto colour_of = [&](uint32_t at, CoverageMask mask) -> glm::dvec3 {
    if (mask == 0) {
      if (!sc->done[at]) sc->shaded[at] = checked(list[at]), sc->done[at] = 1;
      return sc->shaded[at].colour;
    }
    Fragment part = list[at];
    part.mask = mask;
    return checked(part).colour;
  };
  glm::dvec3 colour(0.0);
  for (size_t k = 0; k < count; ++k) {
    const ResolveStep& s = steps[k];
    // Every step but the background's names a fragment of this list first; only add_two may
    // name a second, or NONE. A step from the GPU that breaks this is refused, not read.
    const bool first_ok = s.kind == ResolveStep::background ? s.at[0] == ResolveStep::NONE : s.at[0] < list.size();
    const bool second_ok = s.at[1] == ResolveStep::NONE || (s.kind == ResolveStep::add_two && s.at[1] < list.size());
    if (!first_ok || !second_ok) throw std::logic_error("resolve plan: a step past its list");
    switch (s.kind) {
      case ResolveStep::shade: colour_of(s.at[0], 0); break;
      case ResolveStep::add: colour += s.weight[0] * colour_of(s.at[0], s.mask[0]); break;
      case ResolveStep::add_two: {
        const glm::dvec3 c0 = colour_of(s.at[0], s.mask[0]);
        const glm::dvec3 c1 = s.at[1] == ResolveStep::NONE ? glm::dvec3(0.0) : colour_of(s.at[1], s.mask[1]);
        colour += s.weight[0] * c0 + s.weight[1] * c1;
        break;
      }
      case ResolveStep::background: colour += s.weight[0] * background; break;
      default: throw std::logic_error("resolve plan: a step of no kind");
    }
  }
  return colour;
}

}  // namespace

double SampleDepth::t(const Fragment& f, int k) const {
  const size_t v = 3 * static_cast<size_t>(f.triangle());
  const glm::dvec3 a(triangles->positions[v]), b(triangles->positions[v + 1]), c(triangles->positions[v + 2]);
  const glm::dvec3 normal = glm::cross(b - a, c - a);
  const glm::dvec3 d = view->direction(x + sample_dx(k), y + sample_dy(k));
  const double along = glm::dot(normal, d);
  if (along == 0.0) return std::numeric_limits<double>::infinity();
  return glm::dot(normal, a - view->centre) / along;  // plane: normal . (X - a) = 0
}

CoverageMask SampleDepth::nearer(const Fragment& a, const Fragment& b, CoverageMask in) const {
  CoverageMask out = 0;
  for (CoverageMask m = in; m != 0; m &= m - 1) {
    const int k = __builtin_ctz(m);
    // THE TIE RULE (scene/tie_rule.hpp): at the same distance the later object wins.
    const glm::dvec3 d = view->direction(x + sample_dx(k), y + sample_dy(k));
    if (seen_before(*triangles, d, {b.triangle(), t(b, k)}, {a.triangle(), t(a, k)})) out |= CoverageMask{1} << k;
  }
  return out;
}

glm::dvec3 pack_under_mask(FragmentList list, CoverageMask search, const FragmentShader& shade,
                           const TriangleSoup& triangles, const glm::dvec3& background, PackScratch* scratch,
                           const SampleDepth* depth) {
  PackScratch local;
  return pack(list, search, shade, triangles, background, scratch ? scratch : &local, depth);
}

void visible_triangles(const ABuffer& camera, const TriangleSoup& triangles, int x, int y, uint32_t out[MASK_SAMPLES]) {
  const FragmentList list = camera.list(x, y);
  const SampleDepth depth{&camera.view, &triangles, x, y};
  for (int k = 0; k < MASK_SAMPLES; ++k) {
    const CoverageMask bit = CoverageMask{1} << k;
    const Fragment* seen = nullptr;
    for (const Fragment& f : list) {
      if (!(f.mask & bit)) continue;
      if (!seen) {
        seen = &f;
      } else if (f.zmin > seen->zmax) {
        break;  // the rest lie behind
      } else if (triangles.object_id[f.triangle()] != triangles.object_id[seen->triangle()] &&
                 depth.nearer(*seen, f, bit)) {
        seen = &f;  // overlapping in depth, and its plane met first on this sample's ray
      }
    }
    out[k] = seen ? seen->triangle() : NO_SAMPLE_TRIANGLE;
  }
}

void ResolvePlan::check(const ABuffer& camera, bool exact) const {
  const size_t pixels = camera.view.pixel_count();
  if (offsets.size() != pixels + 1 || planned.size() != pixels || fragments != camera.fragments.size() ||
      offsets.back() != steps.size() || exact_priority != exact) {
    throw InputError("resolve: the plan given is not of this camera A-buffer and rule");
  }
}

ShadedFragment probe_shade(const SceneData& scene, const Fragment& f, int x, int y) {
  uint64_t h = f.triangle_and_facing * 0x9E3779B97F4A7C15ull ^ (uint64_t{f.mask} << 7) ^ f.normal;
  h = (h ^ (static_cast<uint64_t>(x) << 40) ^ (static_cast<uint64_t>(y) << 20)) * 0xBF58476D1CE4E5B9ull;
  const auto part = [&](int k) { return static_cast<double>((h >> (16 * k)) & 0xffff) / 65535.0; };
  return {glm::dvec3(part(0), part(1), part(2)), scene.materials[scene.triangles->material_id[f.triangle()]].opacity};
}

std::string plan_differs_from_pack(const ABuffer& camera, const SceneData& scene, const ResolvePlan& plan) {
  const TriangleSoup& soup = *scene.triangles;
  const PixelShader shade = [&](const Fragment& f, int x, int y) { return probe_shade(scene, f, x, y); };
  ResolveOptions ro;
  ro.exact_priority = plan.exact_priority;
  const Image by_pack = resolve_image(camera, soup, shade, scene.background, ro);
  ro.plan = &plan;
  const Image by_plan = resolve_image(camera, soup, shade, scene.background, ro);
  for (int y = 0; y < camera.height(); ++y) {
    for (int x = 0; x < camera.width(); ++x) {
      const glm::vec3 a = by_pack.rgb(x, y), b = by_plan.rgb(x, y);
      if (std::memcmp(&a, &b, sizeof(a)) != 0) return "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ")";
    }
  }
  return "";
}

int resolve_workers(const ABuffer& camera, const ResolveOptions& options) {
  if (options.threads < 0) throw InputError("resolve: threads must be >= 0, got " + std::to_string(options.threads));
  return thread_count(options.threads, static_cast<size_t>(camera.height()));
}

Image resolve_image(const ABuffer& camera, const TriangleSoup& triangles, const PixelShader& shade,
                    const glm::dvec3& background, const ResolveOptions& options) {
  const WorkerPixelShader by_worker = [&shade](const Fragment& f, int x, int y, int) { return shade(f, x, y); };
  return resolve_image_per_worker(camera, triangles, by_worker, background, options);
}

Image resolve_image_per_worker(const ABuffer& camera, const TriangleSoup& triangles, const WorkerPixelShader& shade,
                               const glm::dvec3& background, const ResolveOptions& options) {
  const int threads = resolve_workers(camera, options);
  const ResolvePlan* plan = options.plan;
  if (plan) plan->check(camera, options.exact_priority);
  Image image(camera.width(), camera.height(), 3);
  std::vector<PackScratch> scratch(static_cast<size_t>(threads));
  std::atomic<int> rows_done{0};
  double reported = 0;  // written by worker 0 only, the calling thread
  parallel_for(static_cast<size_t>(camera.height()), threads, [&](size_t row, int worker) {
    const int y = static_cast<int>(row);
    const auto report = [&] {
      const int done = ++rows_done;
      if (worker == 0 && options.progress) options.progress(reported = static_cast<double>(done) / camera.height());
    };
    for (int x = 0; x < camera.width(); ++x) {
      if (options.only &&
          !(*options.only)[static_cast<size_t>(y) * static_cast<size_t>(camera.width()) + static_cast<size_t>(x)]) {
        continue;
      }
      const auto shade_here = [&](const Fragment& f) { return shade(f, x, y, worker); };
      const size_t p = static_cast<size_t>(y) * static_cast<size_t>(camera.width()) + static_cast<size_t>(x);
      if (plan && plan->planned[p]) {
        const uint32_t first = plan->offsets[p];
        const glm::dvec3 c = run_steps(camera.list(x, y), plan->steps.data() + first, plan->offsets[p + 1] - first,
                                       shade_here, triangles, *plan, background, &scratch[static_cast<size_t>(worker)]);
        image.set_rgb(x, y, glm::vec3(c));
        continue;
      }
      const SampleDepth depth{&camera.view, &triangles, x, y};
      const glm::dvec3 c = pack(camera.list(x, y), FULL_MASK, shade_here, triangles, background,
                                &scratch[static_cast<size_t>(worker)], options.exact_priority ? &depth : nullptr);
      image.set_rgb(x, y, glm::vec3(c));
    }
    report();
  });
  if (options.progress && reported < 1.0) options.progress(1.0);  // the other threads did the last rows
  return image;
}

}  // namespace abcube
