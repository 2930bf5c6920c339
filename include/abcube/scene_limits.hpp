// What a scene is loaded under, as plain data: SceneLimits (for scenes from untrusted
// sources) and SceneOverride (a value of the scene file replaced before it is read). The
// Scene they load: <abcube/scene.hpp>.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace abcube {

// Limits for scenes from untrusted sources. Refused with an InputError before anything
// is allocated for them.
struct SceneLimits {
  std::string root;            // every file the scene references must resolve inside it ("" = anywhere)
  uint64_t max_triangles = 0;  // 0 = no cap beyond the machine's memory
  // The memory budget the scene's triangles must fit, MiB (0 = the memory available, as
  // RenderOptions::max_memory_mib): refused at load, before they are made.
  uint64_t max_memory_mib = 0;
  // Threads the load may use (parsing OBJ files, converting glTF accessors, making the
  // triangles), 0 = every core. `--threads` sets it with the render's.
  int threads = 0;
};

// One value of the scene file replaced before it is read (`abcube render --set KEY=VALUE`,
// a batch job's "set", Python's set=): `path` in the messages' own notation
// (camera.fov_y, lights[0].position, materials.glass.ior, materials["my glass"].ior) and
// the new value as JSON text. Members missing on the way are made (render.max_depth in a
// file without "render"); array elements must exist. The value is then validated as if
// the file held it, and a bad one gets the same message.
struct SceneOverride {
  std::string path;
  std::string value;  // JSON text: 30, "gpu", [0, 1, 2], {"color": [1, 0, 0]}
};
using SceneOverrides = std::vector<SceneOverride>;

}  // namespace abcube
