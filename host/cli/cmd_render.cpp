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
  RenderFlags flags;

  int run() const {
    const Clock::time_point start = Clock::now();
    if (output.empty()) throw InputError("-o OUT: an output image is required");
    check_output_path(output, true);
    check_output_path(stats_path, false);
    RenderSetup setup = flags.setup();
    setup.render.progress = progress_printer();
    Renderer renderer(setup.renderer);
    const Scene s = Scene::load(scene, setup.limits, setup.set);
    try {
      refuse_unused_options(s, setup.render);
    } catch (const OptionError& e) {
      throw_as_flag(e);
    }
    const RenderResult r = renderer.render(s, setup.render);

    const Clock::time_point t0 = Clock::now();
    make_output_folders({output, stats_path});
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
  cmd->add_option("SCENE", c->scene,
                  "scene file (docs/scene-format.md), or a model file (.gltf, .glb, .obj) rendered framed and lit")
      ->required()
      ->type_name("PATH");
  cmd->add_option("-o,--output", c->output, "output image, written atomically; missing folders are made")
      ->type_name("PATH");
  cmd->add_option("--stats", c->stats_path, "stats JSON: plan, per-pass ms, counts, memory, GL path, errors")
      ->type_name("PATH");
  c->flags.add_to(cmd);
  return [c] { return c->run(); };
}

}  // namespace abcube
