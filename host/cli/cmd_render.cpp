// abcube render SCENE -o OUT: one render through the library (renderer.hpp).
#include <memory>
#include <string>

#include <abcube/renderer.hpp>
#include <nlohmann/json.hpp>

#include "base/timer.hpp"
#include "cli/cli_common.hpp"
#include "io/image_io.hpp"

namespace abcube {

namespace {

struct RenderCommand {
  std::string scene, output, stats_path;
  double timeout_s = 0;
  RenderFlags flags;

  int run() const {
    const Clock::time_point start = Clock::now();
    if (output.empty()) throw InputError("-o OUT: an output image is required");
    check_output_path(output, true);
    check_output_path(stats_path, false);
    RenderOptions o = flags.render_options();
    o.timeout_s = timeout_s;
    o.progress = progress_printer();
    Renderer renderer(flags.renderer);
    const Scene s = Scene::load(scene, flags.limits);
    refuse_unused_options(s, o);
    const RenderResult r = renderer.render(s, o);

    const Clock::time_point t0 = Clock::now();
    write_outputs(output, r);
    if (!stats_path.empty()) {
      // The library's stats, with the CLI's own write time in the total.
      nlohmann::json stats = nlohmann::json::parse(r.stats.json);
      stats["timings_ms"]["load"] = s.load_ms();
      stats["timings_ms"]["write"] = ms_since(t0);
      stats["timings_ms"]["total"] = ms_since(start);
      write_text_atomic(stats_path, stats.dump(2) + "\n");
    }
    print_warnings(s, "abcube: ");
    return 0;
  }
};

}  // namespace

CommandRun add_render_command(CLI::App& app) {
  auto c = std::make_shared<RenderCommand>();
  CLI::App* cmd = app.add_subcommand("render", "render a scene into an image (PNG, EXR, TIFF, ... by extension)");
  cmd->add_option("SCENE", c->scene, "scene file (../shared/scene-format.md), or a model file (.gltf, .glb, .obj) rendered framed and lit")->required();
  cmd->add_option("-o,--output", c->output, "output image, written atomically");
  cmd->add_option("--stats", c->stats_path, "stats JSON: plan, per-pass ms, counts, memory, GL path, errors");
  cmd->add_option("--timeout", c->timeout_s, "stop the render past this many seconds, 0 = no limit (exit 1)")
      ->capture_default_str()->check(CLI::Range(0.0, 1e9));
  c->flags.add_to(cmd);
  return [c] { return c->run(); };
}

}  // namespace abcube
