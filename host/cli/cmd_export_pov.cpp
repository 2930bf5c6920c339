// abcube export-pov SCENE -o X.pov: the same triangles, camera, lights and materials for
// POV-Ray 3.7 (mapping and residual differences: cpu_core/scene/pov_export.hpp).
#include <memory>

#include <abcube/scene.hpp>

#include "cli/cli_common.hpp"
#include "io/image_io.hpp"
#include "render/render_methods.hpp"
#include "scene/pov_export.hpp"

namespace abcube {

CommandRun add_export_pov_command(CLI::App& app) {
  struct Args {
    std::string scene, output;
    RenderFlags flags;
  };
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "export-pov", "write the scene for POV-Ray 3.7 (an independent tracer), as abcube render would see it");
  cmd->add_option("SCENE", a->scene, "scene file, or a model file (.gltf, .glb, .obj)")->required()->type_name("PATH");
  cmd->add_option("-o,--output", a->output, "output .pov file, written atomically")->required()->type_name("PATH");
  a->flags.add_to(cmd, scene_view_keys());
  return [a] {
    check_output_path(a->output, false);
    const RenderSetup setup = a->flags.setup();
    const Scene scene = Scene::load(a->scene, setup.limits, setup.set);
    write_text_atomic(a->output, export_pov(scene_view(scene.data(), setup.render)));
    print_warnings(scene, "abcube: ");
    return 0;
  };
}

}  // namespace abcube
