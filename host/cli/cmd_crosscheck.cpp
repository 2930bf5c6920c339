// abcube crosscheck SCENE [--cube-res N] [--gl ...] [--threads K] [--stats F]: the GPU
// distance prepass against the CPU A-buffer, texel by texel, and the GPU Z-buffer image
// against the CPU A-buffer image away from silhouettes. Exit 0 within the documented
// tolerances (host/render/crosscheck.hpp), 1 beyond, 2 for bad input.
#include <cstdio>

#include "cli/cli_common.hpp"
#include "render/crosscheck.hpp"
#include "base/error.hpp"
#include "gl/gl_context.hpp"
#include "io/image_io.hpp"
#include "base/memory.hpp"
#include "scene/scene_load.hpp"

namespace abcube {

int cmd_crosscheck(const std::vector<std::string>& words) {
  const Args args(words, {"--cube-res", "--gl", "--gl-device", "--threads", "--stats"}, {});
  args.expect_positional(1, "SCENE.json");
  GlChoice choice = GlChoice::automatic;
  if (args.has("--gl") && !parse_gl_choice(args.get("--gl"), &choice)) {
    throw InputError("--gl: unknown path '" + args.get("--gl") + "'");
  }
  if (choice == GlChoice::none) throw InputError("--gl none: the cross-check compares GL with the CPU");
  const int device = args.get_int("--gl-device", -1, 0, 1024);
  const int threads = args.get_int("--threads", 0, 0, 4096);
  const std::string stats_path = args.get("--stats");
  SceneData scene = load_scene(args.positional()[0]);
  scene.render.cube_resolution = args.get_int("--cube-res", scene.render.cube_resolution, 1, 16384);
  check_render_size(scene, available_memory_bytes());

  std::string log;
  auto ctx = open_gl_context(choice, device, &log);
  if (!ctx) throw RuntimeFailure("the cross-check needs OpenGL and no GL path works here: " + log);
  const CrosscheckTolerances tol;
  const CrosscheckResult r = crosscheck(scene, scene.render.cube_resolution, threads, tol);

  std::printf("crosscheck %s, cube %d, %s\n", args.positional()[0].c_str(), scene.render.cube_resolution,
              describe_gl(ctx.get()).c_str());
  std::printf("cube texels: %zu, covered on both %zu, GPU only %zu, CPU only %zu\n", r.texels, r.both_covered,
              r.gpu_only, r.cpu_only);
  std::printf("distance |gpu-cpu|/cpu: median %.2e (<= %.0e), p99 %.2e (<= %.0e), max %.2e\n",
              r.distance_median_rel, tol.distance_median_rel, r.distance_p99_rel, tol.distance_p99_rel,
              r.distance_max_rel);
  std::printf("same object id: %.5f (>= %.3f)\n", r.same_object, tol.same_object_min);
  std::printf("camera interior pixels: %zu of %zu, RMSE %.2e (<= %.0e), max abs %.2e (<= %.2e)\n",
              r.interior_pixels, r.pixels, r.interior_rmse, tol.interior_rmse, r.interior_max_abs,
              tol.interior_max_abs);
  std::printf("time: GPU prepass %.1f ms, CPU cube A-buffer %.1f ms (%llu fragments)\n", r.gpu_ms, r.cpu_ms,
              static_cast<unsigned long long>(r.fragments));
  std::printf("%s\n", r.pass ? "PASS" : ("FAIL: " + r.failures).c_str());
  if (!stats_path.empty()) {
    nlohmann::json j = crosscheck_json(r, tol);
    j["gl"] = {{"path", ctx->info().api}, {"renderer", ctx->info().gl_renderer}};
    write_text_atomic(stats_path, j.dump(2) + "\n");
  }
  return r.pass ? 0 : 1;
}

}  // namespace abcube
