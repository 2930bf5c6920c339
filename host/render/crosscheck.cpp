#include "render/crosscheck.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "base/error.hpp"
#include "base/parallel.hpp"
#include "base/statistics.hpp"
#include "reference/raytrace.hpp"
#include "search/deferred_searches.hpp"
#include "search/search.hpp"
#include "shading/map_shading.hpp"
#include "raster/abuffer.hpp"
#include "raster/edge_ties.hpp"
#include "raster/raster.hpp"
#include "base/samples.hpp"
#include "scene/camera.hpp"
#include "raster/cube_map.hpp"
#include "io/image_io.hpp"
#include "shading/fragment_texture.hpp"
#include "shading/resolve.hpp"
#include "gl/gl_abuffer.hpp"
#include "gl/gl_cube_scan.hpp"
#include "gl/gl_cube_walks.hpp"
#include "gl/gl_resolve_plan.hpp"
#include "gl/gl_shadow_probe.hpp"
#include "material/shading.hpp"
#include "base/timer.hpp"

namespace abcube {

namespace {

// A pixel whose colour is one triangle's alone: its front fragment covers all 32 samples,
// is opaque, no fragment behind it reaches into its depth range, and its triangle alone
// covers them all. The last rule leaves out the fragments the A-buffer merged (thesis
// 5.2.1: two triangles of one smooth surface sharing the pixel become one fragment with
// their area-weighted normal): there the CPU shades that averaged normal on one triangle's
// plane, the GPU each triangle's own, and the two differ by as much as the shading varies
// across the pixel (a sharp highlight on a coarse sphere), which is the A-buffer's
// approximation, not a convention to check. Interior pixels are shaded at one point on both
// sides: the pixel centre (the centroid of the full mask) on the same triangle. The GPU
// image samples that centre, which is not one of the 32 samples: a feature thinner than the
// samples' spacing can cover it and none of them (thin wires: the GPU shows the wire, the
// A-buffer what is behind). So the exact tracer's ray through the centre must meet the same
// triangle too.
bool interior_pixel(const SceneData& scene, const ABuffer& camera, const RayTracer& tracer, int x, int y) {
  const FragmentList list = camera.list(x, y);
  if (list.empty() || list[0].mask != FULL_MASK) return false;
  if (scene.materials[scene.triangles->material_id[list[0].triangle()]].opacity < 1.0) return false;
  if (list.size() >= 2 && list[1].zmin < list[0].zmax) return false;
  TriangleSetup setup;
  if (setup_triangle(camera.view, *scene.triangles, list[0].triangle(), &setup) != SetupResult::visible) return false;
  if (pixel_mask(setup, x, y) != FULL_MASK) return false;
  Hit hit;
  return tracer.intersect(scene.camera.position, camera.view.direction(x + 0.5, y + 0.5), &hit) &&
         hit.triangle == list[0].triangle();
}

void compare_cube(const SceneData& scene, int n, int threads, GlScene& gl, CrosscheckResult* r) {
  CubeImage gpu;
  CubeIds gpu_ids;
  const double before = gl.timings().cube_distance_ms;
  gl.cube_distance(scene.camera.position, n, &gpu, &gpu_ids);
  r->gpu_ms = gl.timings().cube_distance_ms - before;

  ABufferOptions options;
  options.threads = threads;
  options.near_distance = gl.near_distance();
  ABufferStats stats;
  const Clock::time_point t0 = Clock::now();
  const CubeABuffer cube = build_cube_abuffer(scene, scene.camera.position, n, options, &stats);
  r->cpu_ms = ms_since(t0);
  r->fragments = stats.fragments;
  {  // The GPU's build of the same lists, budgeted with the CPU's held beside it, and freed.
    ABufferOptions gpu_options = options;
    gpu_options.reserved_bytes += stats.bytes_total;
    const Clock::time_point t1 = Clock::now();
    const CubeABuffer gpu_cube = gl.abuffer_builder().cube(scene, scene.camera.position, n, gpu_options);
    r->gpu_abuffer_ms = ms_since(t1);
    r->lists = compare_lists(cube, gpu_cube);
  }
  compare_searches(scene, cube, threads, r);
  const NearestLayer cpu = nearest_layer(cube, *scene.triangles);

  std::vector<double> rel;
  size_t same = 0;
  std::vector<uint8_t> ties(static_cast<size_t>(n) * static_cast<size_t>(n));
  for (int face = 0; face < CUBE_FACES; ++face) {
    // The texels whose centre lies within EDGE_TIE_EPS of a triangle's edge: the GL prepass
    // samples each texel's centre with snapped vertices, so there it may take either side.
    std::fill(ties.begin(), ties.end(), 0);
    visit_edge_ties(cube_face_view(face, scene.camera.position, n, options.near_distance), 1, 1, *scene.triangles,
                    EDGE_TIE_EPS, [&](int64_t x, int64_t y) { ties[static_cast<size_t>(y * n + x)] = 1; });
    for (size_t t = 0; t < static_cast<size_t>(n) * n; ++t) {
      const float g = gpu.faces[face].data[t], c = cpu.distance.faces[face].data[t];
      const bool gc = std::isfinite(g), cc = std::isfinite(c);
      ++r->texels;
      if (ties[t] && (gc != cc || (gc && gpu_ids.faces[face][t] != cpu.object.faces[face][t]))) {
        ++r->texels_edge_ties;  // differing at an edge tie: apart
        continue;
      }
      if (gc && !cc) ++r->gpu_only;
      if (cc && !gc) ++r->cpu_only;
      if (!gc || !cc) continue;
      rel.push_back(std::abs(double(g) - double(c)) / double(c));
      const bool agree = gpu_ids.faces[face][t] == cpu.object.faces[face][t];
      same += agree;
      if (cpu.tied.faces[face][t]) {
        ++r->tied;
        r->tied_agree += agree;
      }
    }
  }
  r->both_covered = rel.size();
  if (!rel.empty()) {
    r->distance_max_rel = *std::max_element(rel.begin(), rel.end());
    r->distance_p99_rel = percentile(rel, 0.99);
    r->distance_median_rel = percentile(rel, 0.5);
    r->same_object = static_cast<double>(same) / static_cast<double>(rel.size());
  }
}

// The GPU's cube walks of the scene's search rays (scene_walk_rays, from up to
// CROSSCHECK_WALK_TRIANGLES triangles) against CubeWalk's, ray by ray.
void compare_cube_walks(const SceneData& scene, int n, CrosscheckResult* r) {
  if (!gpu_walks_at(n)) {
    r->walks_skipped = "not compared at N = " + std::to_string(n) + ": a walk's cap is above the GPU's " +
                       std::to_string(GPU_WALK_MAX_TEXELS) + " texels";
    return;
  }
  const std::vector<WalkRay> rays = scene_walk_rays(scene, scene.camera.position, CROSSCHECK_WALK_TRIANGLES);
  const std::vector<RayWalk> cpu = cpu_cube_walks(rays, n);
  const Clock::time_point t0 = Clock::now();
  const std::vector<RayWalk> gpu = GlCubeWalks().walk(rays, n);
  r->gpu_walks_ms = ms_since(t0);
  r->walks = compare_walks(cpu, gpu);
}

// The GPU's build of the camera's lists against `cpu` (built with `options`, holding
// `cpu_bytes`), budgeted with the CPU's held beside it, and freed.
void compare_camera_lists(const SceneData& scene, GlScene& gl, const ABuffer& cpu, ABufferOptions options,
                          uint64_t cpu_bytes, CrosscheckResult* r) {
  options.reserved_bytes += cpu_bytes;
  const Clock::time_point t0 = Clock::now();
  const ABuffer gpu = gl.abuffer_builder().camera(scene, options);
  r->gpu_camera_abuffer_ms = ms_since(t0);
  r->camera_lists = compare_lists(cpu, gpu);
}

// THE RESOLVE PLAN made on the GPU, its steps run on the CPU, against `cpu`: pack's image.
void compare_resolve_plan(const SceneData& scene, GlScene& gl, const ABuffer& camera, const ResolveOptions& ro,
                          const Image& cpu, CrosscheckResult* r) {
  CrosscheckResult::ResolvePlanCheck& c = r->resolve_plan;
  ResolvePlanStats s;
  ResolvePlan plan;
  try {
    c.probe = gl.resolve_planner().probe();
    plan = gl.resolve_planner().plan(camera, scene, {}, &s);
  } catch (const RuntimeFailure& e) {
    c.skipped = e.what();
    return;
  }
  c.ms = s.ms, c.pixels = s.pixels, c.planned = s.planned, c.steps = s.steps;
  ResolveOptions with = ro;
  with.plan = &plan;
  const Image by_steps =
      resolve_image(camera, *scene.triangles, local_phong_shader(scene, camera, false), scene.background, with);
  for (int y = 0; y < camera.height(); ++y) {
    for (int x = 0; x < camera.width(); ++x) {
      const glm::vec3 a = cpu.rgb(x, y), b = by_steps.rgb(x, y);
      if (std::memcmp(&a, &b, sizeof(a)) == 0) {
        ++c.identical;
      } else if (c.example.empty()) {
        c.example = "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ")";
      }
    }
  }
}

void compare_camera(const SceneData& scene, int threads, GlScene& gl, CrosscheckResult* r) {
  const Image gpu = gl.camera_color(scene.camera);
  ABufferOptions options;
  options.threads = threads;
  options.near_distance = gl.near_distance();
  ABufferStats stats;
  const ABuffer camera = build_camera_abuffer(scene, options, &stats);
  compare_camera_lists(scene, gl, camera, options, stats.bytes_total, r);
  ResolveOptions ro;
  ro.threads = threads;
  const Image cpu =
      resolve_image(camera, *scene.triangles, local_phong_shader(scene, camera, false), scene.background, ro);
  r->cpu_image = cpu;
  compare_resolve_plan(scene, gl, camera, ro, cpu, r);
  // Interior: one triangle over all 32 samples and the centre, none of them at an edge tie
  // (edge_ties.hpp).
  const std::vector<uint8_t> tie_pixels = edge_tie_pixels(scene);
  const RayTracer tracer(scene);
  double sum_sq = 0;
  for (int y = 0; y < camera.height(); ++y) {
    for (int x = 0; x < camera.width(); ++x) {
      ++r->pixels;
      if (!interior_pixel(scene, camera, tracer, x, y)) continue;
      if (tie_pixels[static_cast<size_t>(y) * static_cast<size_t>(camera.width()) + static_cast<size_t>(x)]) continue;
      ++r->interior_pixels;
      const glm::vec3 a = gpu.rgb(x, y), b = cpu.rgb(x, y);
      for (int c = 0; c < 3; ++c) {
        const double d = std::abs(double(srgb_encode(a[c])) - double(srgb_encode(b[c])));
        sum_sq += d * d;
        r->interior_max_abs = std::max(r->interior_max_abs, d);
      }
    }
  }
  if (r->interior_pixels > 0) r->interior_rmse = std::sqrt(sum_sq / (3.0 * double(r->interior_pixels)));

  // Visibility, sample by sample: the GPU's object ids at the 4x8 sample grid against the
  // A-buffer's nearest surface per sample.
  // A sample within 1/128 of a sample of an edge is counted apart when the two differ: GL's
  // snapped vertices may put it on either side (edge_ties.hpp).
  const std::vector<uint32_t> gpu_ids = gl.camera_objects(scene.camera);
  const std::vector<uint8_t> ties = edge_tie_samples(scene);
  const TriangleSoup& soup = *scene.triangles;
  const int64_t grid_w = int64_t{camera.width()} * MASK_COLUMNS;
  r->sample_disagreement = Image(camera.width(), camera.height(), 1);
  uint32_t seen[MASK_SAMPLES];
  for (int y = 0; y < camera.height(); ++y) {
    for (int x = 0; x < camera.width(); ++x) {
      visible_triangles(camera, soup, x, y, seen);
      int differ = 0;
      for (int k = 0; k < MASK_SAMPLES; ++k) {
        const int64_t gy = int64_t{y} * MASK_ROWS + k / MASK_COLUMNS, gx = int64_t{x} * MASK_COLUMNS + k % MASK_COLUMNS;
        const uint32_t g = gpu_ids[static_cast<size_t>(gy * grid_w + gx)];
        const uint32_t c = seen[k] == NO_SAMPLE_TRIANGLE ? NO_OBJECT : soup.object_id[seen[k]];
        ++r->samples;
        if (g == c) {
          ++r->samples_same;
          continue;
        }
        if (ties[static_cast<size_t>(gy * grid_w + gx)]) {
          ++r->samples_edge_ties;
          continue;
        }
        ++differ;
        if (c == NO_OBJECT)
          ++r->samples_gpu_only;
        else if (g == NO_OBJECT)
          ++r->samples_cpu_only;
        else
          ++r->samples_other_object;
      }
      r->sample_disagreement
          .data[static_cast<size_t>(y) * static_cast<size_t>(camera.width()) + static_cast<size_t>(x)] =
          float(differ) / float(MASK_SAMPLES);
    }
  }
  if (r->samples > r->samples_edge_ties) {
    r->sample_agreement = double(r->samples_same) / double(r->samples - r->samples_edge_ties);
  }
}

// What the exact tracer says at each sample of the shadow camera: the visible object, and per
// probed light whether an opaque blocker stops it (S_l = 0) where the surface faces it.
struct ExactShadows {
  std::vector<uint32_t> object;  // NO_OBJECT where nothing
  std::vector<uint16_t> blocked, lit;
  std::vector<uint16_t> search_blocked;  // the CPU's shadow search at the same point
};

constexpr double GRAZING_COSINE = 1e-3;

// The exact tracer's shadows, and the CPU's shadow search's, at the visible surface of each
// camera sample, for the probed lights.
ExactShadows trace_shadows(const SceneData& scene, const Camera& camera, int n, int threads, double near_distance,
                           const std::vector<int>& lights) {
  const RayTracer tracer(scene);
  ABufferOptions options;
  options.threads = threads;
  options.near_distance = near_distance;
  const CubeABuffer cube = build_cube_abuffer(scene, scene.camera.position, n, options);
  const SearchContext context(scene, cube);
  const RasterView view = camera_view(make_camera_frame(camera), near_distance);
  const int64_t gw = int64_t{camera.width} * MASK_COLUMNS, gh = int64_t{camera.height} * MASK_ROWS;
  ExactShadows exact;
  exact.object.assign(static_cast<size_t>(gw * gh), NO_OBJECT);
  exact.blocked.assign(exact.object.size(), 0);
  exact.lit.assign(exact.object.size(), 0);
  exact.search_blocked.assign(exact.object.size(), 0);
  parallel_for(static_cast<size_t>(gh), threads, [&](size_t gy, int) {
    for (int64_t gx = 0; gx < gw; ++gx) {
      const size_t g = gy * static_cast<size_t>(gw) + static_cast<size_t>(gx);
      const int x = static_cast<int>(gx / MASK_COLUMNS), y = static_cast<int>(gy / MASK_ROWS);
      const int k = sample_index(static_cast<int>(gx % MASK_COLUMNS), static_cast<int>(gy % MASK_ROWS));
      const glm::dvec3 dir = view.direction(x + sample_dx(k), y + sample_dy(k));
      Hit hit;
      if (!tracer.intersect(camera.position, dir, &hit)) continue;
      exact.object[g] = hit.object_id;
      const glm::dvec3 v = glm::normalize(-dir);
      const glm::dvec3 nrm = face_forward(hit.shading_normal, v);
      for (size_t b = 0; b < lights.size(); ++b) {
        const PointLight& light = scene.lights[static_cast<size_t>(lights[b])];
        // Faces the light, by more than grazing: at N.L below GRAZING_COSINE the light adds
        // less than that share of its full diffuse term, and whether it is blocked is
        // decided by rounding (a light on a surface: the floor under it, seen by the GPU's
        // float depths, by the tracer in double).
        if (glm::dot(nrm, glm::normalize(light.position - hit.point)) <= GRAZING_COSINE) continue;
        exact.lit[g] |= static_cast<uint16_t>(1u << b);
        if (tracer.light_visibility(hit, light, nullptr) == glm::dvec3(0.0)) {
          exact.blocked[g] |= static_cast<uint16_t>(1u << b);
        }
        if (shadow_search(context, hit.point, light.position).blocked) {
          exact.search_blocked[g] |= static_cast<uint16_t>(1u << b);
        }
      }
    }
  });
  return exact;
}

// Each sample and light both sides light: the volumes', the maps' and the search's answers
// against the tracer's, also counted apart where the 3x3 samples around agree (interior).
void tally_shadows(const ExactShadows& exact, const GlShadowProbe& probe, const std::vector<uint32_t>& gpu_ids,
                   const Camera& camera, CrosscheckResult* r) {
  const int64_t gw = int64_t{camera.width} * MASK_COLUMNS, gh = int64_t{camera.height} * MASK_ROWS;
  r->shadow_disagreement = Image(camera.width, camera.height, 1);
  std::vector<int> pairs_of_pixel(static_cast<size_t>(camera.width) * static_cast<size_t>(camera.height), 0);
  for (int64_t gy = 0; gy < gh; ++gy) {
    for (int64_t gx = 0; gx < gw; ++gx) {
      const size_t g = static_cast<size_t>(gy * gw + gx);
      if (exact.object[g] == NO_OBJECT || gpu_ids[g] != exact.object[g]) continue;
      for (size_t b = 0; b < probe.lights.size(); ++b) {
        const uint16_t bit = static_cast<uint16_t>(1u << b);
        if (!(exact.lit[g] & bit) || !(probe.lit[g] & bit)) continue;  // faces away: no light to block
        const bool truth = exact.blocked[g] & bit;
        bool interior = true;
        for (int64_t dy = -1; dy <= 1 && interior; ++dy) {
          for (int64_t dx = -1; dx <= 1 && interior; ++dx) {
            const int64_t ny = gy + dy, nx = gx + dx;
            if (ny < 0 || nx < 0 || ny >= gh || nx >= gw) continue;
            const size_t h = static_cast<size_t>(ny * gw + nx);
            interior = exact.object[h] == exact.object[g] && bool(exact.blocked[h] & bit) == truth;
          }
        }
        const auto count = [&](ShadowAgreement& a, bool said) {
          ++a.pairs;
          a.agree += said == truth;
          a.false_shadow += said && !truth;
          a.false_light += !said && truth;
          if (interior) {
            ++a.interior;
            a.interior_agree += said == truth;
          }
        };
        count(r->volumes, probe.volume[g] & bit);
        count(r->maps, probe.map[g] & bit);
        count(r->search, exact.search_blocked[g] & bit);
        const size_t pixel = static_cast<size_t>(gy / MASK_ROWS) * static_cast<size_t>(camera.width) +
                             static_cast<size_t>(gx / MASK_COLUMNS);
        ++pairs_of_pixel[pixel];
        if (bool(probe.volume[g] & bit) != truth) r->shadow_disagreement.data[pixel] += 1.f;
      }
    }
  }
  for (size_t p = 0; p < pairs_of_pixel.size(); ++p) {
    if (pairs_of_pixel[p] > 0) r->shadow_disagreement.data[p] /= float(pairs_of_pixel[p]);
  }
}

void compare_shadows(const SceneData& scene, int n, int threads, GlScene& gl, CrosscheckResult* r) {
  Camera camera = scene.camera;
  if (camera.width > SHADOW_CHECK_MAX_WIDTH) {
    camera.height =
        std::max(1, static_cast<int>(std::lround(double(camera.height) * SHADOW_CHECK_MAX_WIDTH / camera.width)));
    camera.width = SHADOW_CHECK_MAX_WIDTH;
  }
  r->shadow_width = camera.width;
  r->shadow_height = camera.height;
  gl.build_shadow_maps(n);
  const GlShadowProbe probe = probe_camera_shadows(gl, camera);
  const std::vector<uint32_t> gpu_ids = gl.camera_objects(camera);
  r->shadow_lights = static_cast<int>(probe.lights.size());
  if (probe.lights.empty()) return;

  const ExactShadows exact = trace_shadows(scene, camera, n, threads, gl.near_distance(), probe.lights);
  tally_shadows(exact, probe, gpu_ids, camera, r);
}

}  // namespace

CrosscheckResult crosscheck(const SceneData& scene, int n, int threads, const CrosscheckTolerances& tol) {
  CrosscheckResult r;
  GlScene gl(scene);
  gl.set_texture_level0(true);  // the CPU's point samples (scene/texture.hpp)
  compare_cube(scene, n, threads, gl, &r);
  compare_camera(scene, threads, gl, &r);
  compare_shadows(scene, n, threads, gl, &r);
  compare_cube_walks(scene, n, &r);
  const double mismatch = r.texels ? static_cast<double>(r.gpu_only + r.cpu_only) / static_cast<double>(r.texels) : 0.0;
  auto fail = [&r](bool bad, const std::string& what) {
    if (bad) r.failures += (r.failures.empty() ? "" : "; ") + what;
  };
  fail(r.distance_median_rel > tol.distance_median_rel, "distance median");
  // The p99 of a few hundred texels is decided by the few at the objects' silhouettes:
  // below FEW_TEXELS the verdict says so, and what to do.
  constexpr size_t FEW_TEXELS = 10000;
  fail(r.distance_p99_rel > tol.distance_p99_rel,
       r.both_covered < FEW_TEXELS ? "distance p99 over few texels (" + std::to_string(r.both_covered) +
                                         " covered on both, its 1% at silhouettes): raise --cube-res"
                                   : std::string("distance p99"));
  fail(r.both_covered > 0 && r.same_object < tol.same_object_min, "same object share");
  fail(mismatch > tol.coverage_mismatch_max, "coverage mismatch");
  fail(r.interior_rmse > tol.interior_rmse, "camera interior RMSE");
  fail(r.interior_max_abs > tol.interior_max_abs, "camera interior max abs");
  fail(r.sample_agreement < tol.sample_agreement_min, "camera sample agreement");
  fail(r.volumes.interior_share() < tol.volumes_agreement_min, "shadow volumes against the tracer");
  fail(!r.lists.within_bounds(), "GPU A-buffer lists");
  fail(!r.camera_lists.within_bounds(), "GPU camera A-buffer lists");
  // The plan's steps are pack's expressions; on a GL whose doubles round as IEEE 754 says,
  // every colour is the same bits. A plan that planned no pixel would pass that by pack's
  // colours alone: it fails, as does a GL that failed THE PROBE (gl_resolve_plan.hpp).
  const CrosscheckResult::ResolvePlanCheck& plan = r.resolve_plan;
  fail(plan.skipped.empty() &&
           (plan.identical < plan.pixels || (plan.pixels > 0 && plan.planned == 0) || !plan.probe.empty()),
       "GPU resolve plan");
  fail(r.walks.differing > 0, "GPU cube walks");
  // A GL whose double division or square root does not round as IEEE 754 says moves a walk's
  // ends within rounding; a fragment at the end of a texel's range may then pass on one side
  // only. The candidates must then agree only as well as the walks do.
  fail(r.candidates.differing > 0 && r.walks.within_rounding == 0, "GPU search candidates");
  fail(r.answers.same < r.answers.rays && r.walks.within_rounding == 0, "GPU search answers");
  // The method's own bar: within 1/255 on 99.9% of the pixels.
  const CrosscheckResult::SearchImages& si = r.search_images;
  fail(si.differing * 1000 > static_cast<size_t>(si.width) * static_cast<size_t>(si.height), "GPU search image");
  r.pass = r.failures.empty();
  return r;
}

nlohmann::json shadow_json(const ShadowAgreement& a) {
  return {{"pairs", a.pairs},
          {"agreement", a.share()},
          {"false_shadow", a.false_shadow},
          {"false_light", a.false_light},
          {"interior_pairs", a.interior},
          {"interior_agreement", a.interior_share()}};
}

nlohmann::json lists_json(const ListComparison& c) {
  nlohmann::json classes = nlohmann::json::object();
  for (int k = 0; k < LIST_DIFFERENCE_CLASSES; ++k) {
    const size_t i = static_cast<size_t>(k);
    classes[list_difference_name(static_cast<ListDifference>(k))] = {{"count", c.count[i]}, {"first", c.example[i]}};
  }
  return {{"lists", c.lists},
          {"lists_identical", c.lists_identical},
          {"fragments", c.fragments},
          {"fragments_identical", c.fragments_identical},
          {"depth_rel_max", c.depth_max_rel},
          {"differences", classes},
          {"within_bounds", c.within_bounds()}};
}

nlohmann::json crosscheck_json(const CrosscheckResult& r, const CrosscheckTolerances& tol) {
  using nlohmann::json;
  return json{{"abuffer_lists", lists_json(r.lists)},
              {"gpu_abuffer_ms", r.gpu_abuffer_ms},
              {"camera_abuffer_lists", lists_json(r.camera_lists)},
              {"gpu_camera_abuffer_ms", r.gpu_camera_abuffer_ms},
              {"resolve_plan",
               {{"pixels", r.resolve_plan.pixels},
                {"planned", r.resolve_plan.planned},
                {"identical", r.resolve_plan.identical},
                {"probe", r.resolve_plan.probe.empty() ? "agrees" : r.resolve_plan.probe},
                {"steps", r.resolve_plan.steps},
                {"first_not_identical", r.resolve_plan.example},
                {"not_compared", r.resolve_plan.skipped},
                {"gpu_ms", r.resolve_plan.ms}}},
              {"cube_walks",
               {{"rays", r.walks.rays},
                {"identical", r.walks.identical},
                {"within_rounding", r.walks.within_rounding},
                {"differing", r.walks.differing},
                {"texels", r.walks.texels},
                {"first_not_identical", r.walks.example},
                {"not_compared", r.walks_skipped},
                {"gpu_ms", r.gpu_walks_ms}}},
              {"search_candidates", search_candidates_json(r)},
              {"cube",
               {{"texels", r.texels},
                {"both_covered", r.both_covered},
                {"gpu_only", r.gpu_only},
                {"cpu_only", r.cpu_only},
                {"distance_rel_median", r.distance_median_rel},
                {"distance_rel_p99", r.distance_p99_rel},
                {"distance_rel_max", r.distance_max_rel},
                {"same_object", r.same_object},
                {"tied", r.tied},
                {"tied_agree", r.tied_agree},
                {"texels_edge_ties", r.texels_edge_ties},
                {"gpu_prepass_ms", r.gpu_ms},
                {"cpu_abuffer_ms", r.cpu_ms},
                {"fragments", r.fragments}}},
              {"camera",
               {{"pixels", r.pixels},
                {"interior_pixels", r.interior_pixels},
                {"interior_rmse", r.interior_rmse},
                {"interior_max_abs", r.interior_max_abs}}},
              {"shadows",
               {{"camera", {r.shadow_width, r.shadow_height}},
                {"lights", r.shadow_lights},
                {"volumes", shadow_json(r.volumes)},
                {"maps", shadow_json(r.maps)},
                {"cpu_search", shadow_json(r.search)}}},
              {"camera_samples",
               {{"samples", r.samples},
                {"same_object", r.samples_same},
                {"gpu_only", r.samples_gpu_only},
                {"cpu_only", r.samples_cpu_only},
                {"other_object", r.samples_other_object},
                {"edge_ties_differing", r.samples_edge_ties},
                {"agreement", r.sample_agreement}}},
              {"tolerances",
               {{"distance_rel_median", tol.distance_median_rel},
                {"distance_rel_p99", tol.distance_p99_rel},
                {"same_object_min", tol.same_object_min},
                {"coverage_mismatch_max", tol.coverage_mismatch_max},
                {"interior_rmse", tol.interior_rmse},
                {"interior_max_abs", tol.interior_max_abs},
                {"sample_agreement_min", tol.sample_agreement_min},
                {"volumes_agreement_min", tol.volumes_agreement_min}}},
              {"pass", r.pass},
              {"failures", r.failures}};
}

Image disagreement_overlay(const Image& share, const Image& base) {
  Image out(share.width, share.height, 3);
  const bool has_base = base.width == share.width && base.height == share.height;
  for (int y = 0; y < share.height; ++y) {
    for (int x = 0; x < share.width; ++x) {
      const float s = share.at(x, y)[0];
      if (s > 0) {
        out.set_rgb(x, y, glm::vec3(1.f, std::min(1.f, s), 0.f));
        continue;
      }
      const glm::vec3 c = has_base ? base.rgb(x, y) : glm::vec3(0.02f);
      const float grey = 0.5f * (0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b);
      out.set_rgb(x, y, glm::vec3(grey));
    }
  }
  return out;
}

}  // namespace abcube
