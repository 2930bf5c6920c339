// abcube export-pov SCENE -o X.pov: the same triangles, camera, lights and materials for
// POV-Ray 3.7 (mapping and residual differences: cpu_core/scene/pov_export.hpp).
#include <memory>

#include <abcube/scene.hpp>

#include "cli/cli_common.hpp"
#include "io/image_io.hpp"
#include "scene/pov_export.hpp"

namespace abcube {

CommandRun add_export_pov_command(CLI::App& app) {
  struct Args {
    std::string scene, output;
  };
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("export-pov", "write the scene for POV-Ray 3.7 (an independent tracer)");
  cmd->add_option("SCENE", a->scene, "scene file")->required();
  cmd->add_option("-o,--output", a->output, "output .pov file, written atomically")->required();
  return [a] {
    const Scene scene = Scene::load(a->scene);
    write_text_atomic(a->output, export_pov(scene.data()));
    print_warnings(scene, "abcube: ");
    return 0;
  };
}

}  // namespace abcube
