// abcube crosscheck SCENE [--cube-res N] [--gl ...] [--threads K] [--stats F]: the GPU
// distance prepass against the CPU A-buffer, texel by texel, and the GPU Z-buffer image
// against the CPU A-buffer image away from silhouettes. Exit 0 within the documented
// tolerances (host/render/crosscheck.hpp), 1 beyond, 2 for bad input.
#include <cstdio>
#include <memory>

#include <abcube/scene.hpp>

#include "cli/cli_common.hpp"
#include "render/crosscheck.hpp"
#include "base/error.hpp"
#include "gl/gl_context.hpp"
#include "io/image_io.hpp"
#include "render/render_methods.hpp"
#include "base/memory.hpp"
#include "scene/scene_load.hpp"

namespace abcube {

namespace {

constexpr const char* CROSSCHECK_COVERS =
    "covers: visibility (cube texels, camera samples), the cube's and the camera's A-buffer lists, the cube walks of "
    "shadow and reflection rays, the searches' candidates and answers in the cube A-buffer, direct shading of "
    "interior pixels, hard shadows; not covered: reflected and refracted colours, antialiased edges (abcube report "
    "compares whole images with the exact tracer)";

// One of the searches' pieces run on the GPU against the CPU's, ray by ray: why it was not
// compared, or its classes, the count of `unit` in the CPU's results and the GPU's time.
template <class Comparison>
void print_rays(const char* what, const std::string& skipped, const Comparison& c, uint64_t count, const char* unit,
                double ms) {
  if (!skipped.empty()) {
    std::printf("%s: %s\n", what, skipped.c_str());
    return;
  }
  std::printf("%s: %zu of %zu rays identical, %zu within rounding, %zu differing, %llu %s (%.1f ms)%s%s\n", what,
              c.identical, c.rays, c.within_rounding, c.differing, static_cast<unsigned long long>(count), unit, ms,
              c.example.empty() ? "" : "; first not identical: ", c.example.c_str());
}

// The searches' pieces run on the GPU (the walks, the candidates) against the CPU's.
void print_searches(const CrosscheckResult& r) {
  print_rays("GPU cube walks", r.walks_skipped, r.walks, r.walks.texels, "texels", r.gpu_walks_ms);
  if (!r.walks_skipped.empty()) return;
  print_rays("GPU search candidates", r.candidates_skipped, r.candidates, r.candidates.candidates, "candidates",
             r.gpu_candidates_ms);
  if (!r.candidates_skipped.empty()) return;
  const CrosscheckResult::Answers& a = r.answers;
  std::printf("GPU search answers: %zu of %zu the CPU's search's, %zu hits or blocked segments%s%s\n", a.same, a.rays,
              a.found, a.example.empty() ? "" : "; first not: ", a.example.c_str());
  const CrosscheckResult::SearchImages& i = r.search_images;
  std::printf("GPU search image: %dx%d, %zu pixels over 1/255 (largest %.4f), %s (%llu passes, %.0f ms)\n", i.width,
              i.height, i.differing, i.max_diff, i.same_bytes ? "the same bytes" : "not the same bytes",
              static_cast<unsigned long long>(i.passes), i.ms);
}

// A GPU build's lists against the CPU's: the counts, then each class of difference found.
void print_lists(const char* what, const ListComparison& c, double ms) {
  std::printf("%s: %llu of %llu identical, fragments %llu of %llu (%.1f ms)\n", what,
              static_cast<unsigned long long>(c.lists_identical), static_cast<unsigned long long>(c.lists),
              static_cast<unsigned long long>(c.fragments_identical), static_cast<unsigned long long>(c.fragments), ms);
  for (int k = 0; k < LIST_DIFFERENCE_CLASSES; ++k) {
    const size_t i = static_cast<size_t>(k);
    if (c.count[i] == 0) continue;
    std::printf("  %s: %llu, first at %s\n", list_difference_name(static_cast<ListDifference>(k)),
                static_cast<unsigned long long>(c.count[i]), c.example[i].c_str());
  }
}

struct CrosscheckCommand {
  std::string scene_path, stats_path, samples_image, shadow_image, gl = "auto";
  int cube_res = 0, device = -1, threads = 0;
  RenderFlags flags;  // the scene as seen: size, camera, --set, --max-depth

  int run() const {
    GlChoice choice = GlChoice::automatic;
    if (!parse_gl_choice(gl, &choice)) throw InputError("--gl: unknown path " + quote(gl));
    if (choice == GlChoice::none) throw InputError("--gl none: the cross-check compares GL with the CPU");
    check_output_path(stats_path, false);
    check_output_path(samples_image, true);
    check_output_path(shadow_image, true);
    const RenderSetup setup = flags.setup();
    const Scene loaded = Scene::load(scene_path, setup.limits, setup.set);
    SceneData scene = scene_view(loaded.data(), setup.render);  // shares the triangles
    if (cube_res > 0) scene.render.cube_resolution = cube_res;
    check_render_size(scene, true, memory_budget_bytes(0), false);

    std::string log;
    auto ctx = open_gl_context(choice, device, &log);
    if (!ctx) throw RuntimeFailure("the cross-check needs OpenGL and no GL path works here: " + log);
    const CrosscheckTolerances tol;
    const CrosscheckResult r = crosscheck(scene, scene.render.cube_resolution, threads, tol);

    std::printf("crosscheck %s, cube %d, %s\n", scene_path.c_str(), scene.render.cube_resolution,
                describe_gl(ctx.get()).c_str());
    std::printf("%s\n", CROSSCHECK_COVERS);
    std::printf(
        "cube texels: %zu, covered on both %zu, GPU only %zu, CPU only %zu; differing within 1/128 of a "
        "texel of an edge (edge_ties.hpp, apart) %zu\n",
        r.texels, r.both_covered, r.gpu_only, r.cpu_only, r.texels_edge_ties);
    std::printf("distance |gpu-cpu|/cpu: median %.2e (<= %.0e), p99 %.2e (<= %.0e), max %.2e\n", r.distance_median_rel,
                tol.distance_median_rel, r.distance_p99_rel, tol.distance_p99_rel, r.distance_max_rel);
    std::printf("same object id: %.5f (>= %.3f)\n", r.same_object, tol.same_object_min);
    std::printf("exact ties (two objects at the same distance, tie_rule.hpp): %zu texels, resolved alike %zu\n", r.tied,
                r.tied_agree);
    print_lists("GPU cube A-buffer lists", r.lists, r.gpu_abuffer_ms);
    print_lists("GPU camera A-buffer lists", r.camera_lists, r.gpu_camera_abuffer_ms);
    const CrosscheckResult::ResolvePlanCheck& plan = r.resolve_plan;
    if (!plan.skipped.empty()) {
      std::printf("GPU resolve plan: %s\n", plan.skipped.c_str());
    } else {
      std::printf(
          "GPU resolve plan: %zu of %zu pixels the CPU's resolve, bit for bit; %zu planned, %llu steps "
          "(%.1f ms)%s%s; the probe: %s\n",
          plan.identical, plan.pixels, plan.planned, static_cast<unsigned long long>(plan.steps), plan.ms,
          plan.example.empty() ? "" : "; first not: ", plan.example.c_str(),
          plan.probe.empty() ? "agrees" : plan.probe.c_str());
    }
    print_searches(r);
    std::printf("camera interior pixels: %zu of %zu, RMSE %.2e (<= %.0e), max abs %.2e (<= %.2e)\n", r.interior_pixels,
                r.pixels, r.interior_rmse, tol.interior_rmse, r.interior_max_abs, tol.interior_max_abs);
    std::printf(
        "camera samples: %zu, same object %zu (agreement %.6f >= %.4f), GPU only %zu, CPU only %zu, "
        "other object %zu; differing within 1/128 of a sample of an edge (edge_ties.hpp, apart) %zu\n",
        r.samples, r.samples_same, r.sample_agreement, tol.sample_agreement_min, r.samples_gpu_only, r.samples_cpu_only,
        r.samples_other_object, r.samples_edge_ties);
    if (r.shadow_lights > 0) {
      auto line = [](const char* what, const ShadowAgreement& a) {
        std::printf("  %-22s %.5f of %zu, away from edges %.5f of %zu (false shadow %zu, false light %zu)\n", what,
                    a.share(), a.pairs, a.interior_share(), a.interior, a.false_shadow, a.false_light);
      };
      std::printf("shadows against the exact tracer (%dx%d, 32 samples a pixel, %d lights):\n", r.shadow_width,
                  r.shadow_height, r.shadow_lights);
      line("GPU shadow volumes", r.volumes);
      line("GPU shadow maps", r.maps);
      line("CPU shadow search", r.search);
    }
    std::printf("time: GPU prepass %.1f ms, CPU cube A-buffer %.1f ms (%llu fragments)\n", r.gpu_ms, r.cpu_ms,
                static_cast<unsigned long long>(r.fragments));
    std::printf("%s\n", r.pass ? "PASS" : ("FAIL: " + r.failures).c_str());
    if (!stats_path.empty()) {
      nlohmann::json j = crosscheck_json(r, tol);
      j["gl"] = {{"path", ctx->info().api}, {"renderer", ctx->info().gl_renderer}};
      write_text_atomic(stats_path, j.dump(2) + "\n");
    }
    if (!samples_image.empty()) write_image(samples_image, disagreement_overlay(r.sample_disagreement, r.cpu_image));
    if (!shadow_image.empty() && r.shadow_lights > 0) {
      write_image(shadow_image, disagreement_overlay(r.shadow_disagreement, Image()));
    }
    print_warnings(loaded, "abcube: ");
    return r.pass ? 0 : 1;
  }
};

}  // namespace

CommandRun add_crosscheck_command(CLI::App& app) {
  auto c = std::make_shared<CrosscheckCommand>();
  CLI::App* cmd = app.add_subcommand(
      "crosscheck",
      "the GPU against the CPU where both must agree exactly (exit 1 beyond tolerance): the cube map's distance "
      "prepass against the CPU A-buffer's nearest layer, texel by texel; which object each camera sample sees; "
      "interior pixels' direct shading; shadows sample by sample against the exact tracer. It does NOT compare "
      "reflections, refractions or antialiased edges, where the methods differ by design: `abcube report` shows "
      "every method against the exact tracer");
  cmd->footer(std::string(CROSSCHECK_COVERS));
  cmd->add_option("SCENE", c->scene_path, "scene file, or a model file (.gltf, .glb, .obj)")
      ->required()
      ->type_name("PATH");
  c->flags.add_to(cmd, scene_view_keys());
  cmd->add_option("--cube-res", c->cube_res, "cube map face edge N (texels, 1 to 16384; default: the scene's)")
      ->type_name("INT")
      ->check(CLI::Range(1, 16384).description(""));
  cmd->add_option("--gl", c->gl, "GL path: auto | egl | egl-device | egl-surfaceless | osmesa (default: auto)")
      ->type_name("NAME");
  cmd->add_option("--gl-device", c->device,
                  "EGL device index (0 to 1024; default: ABCUBE_EGL_DEVICE, else the first GPU)")
      ->type_name("INT")
      ->check(CLI::Range(0, 1024).description(""));
  cmd->add_option("--threads", c->threads, "worker threads (threads, 0 to 4096; default: 0, every core)")
      ->type_name("INT")
      ->check(CLI::Range(0, 4096).description(""));
  cmd->add_option("--stats", c->stats_path, "figures and tolerances as JSON")->type_name("PATH");
  cmd->add_option("--samples-image", c->samples_image,
                  "where GPU and CPU see different objects: pixels with any of their 32 samples differing in red (to "
                  "yellow when all do) over the CPU image in grey")
      ->type_name("PATH");
  cmd->add_option("--shadow-image", c->shadow_image,
                  "per pixel of the shadow camera, the share of (sample, light) pairs where the GPU's shadow volumes "
                  "and the exact tracer differ")
      ->type_name("PATH");
  return [c] { return c->run(); };
}

}  // namespace abcube
