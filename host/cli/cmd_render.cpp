// abcube render: the command line of one render through the library (renderer.hpp).
#include <cstdio>
#include <filesystem>
#include <string>

#include <abcube/renderer.hpp>
#include <nlohmann/json.hpp>

#include "base/timer.hpp"
#include "cli/cli_common.hpp"
#include "io/image_io.hpp"

namespace abcube {

namespace {

// Refuse before any work an output whose folder does not exist or whose format has no writer.
void check_output_paths(const std::string& image, const std::string& stats) {
  if (image.empty()) throw InputError("-o OUT: an output image is required");
  if (!image_format_supported(image)) throw InputError(image + ": no image writer for this file extension");
  for (const std::string* path : {&image, &stats}) {
    if (path->empty()) continue;
    const std::filesystem::path dir = std::filesystem::path(*path).parent_path();
    if (!dir.empty() && !std::filesystem::is_directory(dir)) {
      throw InputError(*path + ": folder " + dir.string() + " does not exist");
    }
  }
}

// The --stats file: the library's stats, with the CLI's own write time in the total.
std::string final_stats(const RenderResult& r, double write_ms, double total_ms) {
  nlohmann::json stats = nlohmann::json::parse(r.stats.json);
  stats["timings_ms"]["write"] = write_ms;
  stats["timings_ms"]["total"] = total_ms;
  return stats.dump(2) + "\n";
}

}  // namespace

int cmd_render(const std::vector<std::string>& words) {
  const Clock::time_point start = Clock::now();
  const Args args(words,
                  {"-o", "--output", "--method", "--cube-res", "--max-depth", "--threads", "--gl", "--gl-device",
                   "--stats", "--max-memory", "--max-layers", "--search", "--refine", "--theta-max", "--refraction",
                   "--envmap-lookup", "--error-target", "--reference-image", "--plan", "--root", "--max-pixels",
                   "--max-triangles", "--aovs", "--timeout"},
                  {"--reference", "--fresnel"});
  args.expect_positional(1, "SCENE.json");
  const std::string output = args.has("-o") ? args.get("-o") : args.get("--output");
  const std::string stats_path = args.get("--stats");
  check_output_paths(output, stats_path);

  RendererOptions ro;
  ro.gl = args.get("--gl", "auto");
  ro.gl_device = args.get_int("--gl-device", -1, 0, 1024);
  ro.threads = args.get_int("--threads", 0, 0, 4096);
  RenderOptions o = render_options_from(args);
  SceneLimits limits;
  limits.root = args.get("--root");
  limits.max_triangles = static_cast<uint64_t>(args.get_double("--max-triangles", 0, 0, 1e12));

  Renderer renderer(ro);
  const Scene scene = Scene::load(args.positional()[0], limits);
  o.progress = progress_printer();
  const RenderResult r = renderer.render(scene, o);

  const Clock::time_point t0 = Clock::now();
  write_outputs(output, r);
  const double write_ms = ms_since(t0);
  if (!stats_path.empty()) write_text_atomic(stats_path, final_stats(r, write_ms, ms_since(start)));
  return 0;
}

}  // namespace abcube
