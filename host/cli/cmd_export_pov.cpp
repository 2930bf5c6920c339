// abcube export-pov SCENE -o X.pov: the same triangles, camera, lights and materials for
// POV-Ray 3.7 (mapping and residual differences: cpu_core/io/pov_export.hpp).
#include "cli/cli_common.hpp"
#include "base/error.hpp"
#include "io/image_io.hpp"
#include "io/pov_export.hpp"
#include "scene/scene_load.hpp"

namespace abcube {

int cmd_export_pov(const std::vector<std::string>& words) {
  const Args args(words, {"-o", "--output"}, {});
  args.expect_positional(1, "SCENE.json");
  const std::string out = args.has("-o") ? args.get("-o") : args.get("--output");
  if (out.empty()) throw InputError("-o OUT.pov: an output file is required");
  const SceneData scene = load_scene(args.positional()[0]);
  write_text_atomic(out, export_pov(scene));
  return 0;
}

}  // namespace abcube
