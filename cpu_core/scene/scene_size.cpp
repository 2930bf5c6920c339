// The memory a render of a scene needs, estimated before it starts (scene_load.hpp).
#include <string>

#include "base/error.hpp"
#include "scene/scene_json.hpp"
#include "scene/scene_load.hpp"

namespace abcube {

namespace {

// Bytes per unit of work, for the estimate: a camera pixel holds its colour and A-buffer
// fragment headroom; a cube texel its distance and fragment headroom; a triangle its
// soup entry (3 positions, 3 normals, 2 ids), acceleration-structure headroom (64), and
// the searches' per-triangle data (search.hpp SearchContext: plane 32, refinement bounds
// 128, neighbours 12 bytes, and 120 more while the neighbours are being built).
constexpr uint64_t PIXEL_BYTES = 3 * sizeof(float) + 64;
constexpr uint64_t TEXEL_BYTES = 64;
constexpr uint64_t TRIANGLE_BYTES = 6 * sizeof(glm::vec3) + 2 * sizeof(uint32_t) + 64 + 32 + 128 + 12 + 120;

}  // namespace

uint64_t estimate_render_bytes(const SceneData& scene) {
  const uint64_t pixels = static_cast<uint64_t>(scene.camera.width) * static_cast<uint64_t>(scene.camera.height);
  const uint64_t n = static_cast<uint64_t>(scene.render.cube_resolution);
  return pixels * PIXEL_BYTES + 6 * n * n * TEXEL_BYTES + scene.triangles->triangle_count() * TRIANGLE_BYTES;
}

void check_render_size(const SceneData& scene, uint64_t budget_bytes) {
  const uint64_t need = estimate_render_bytes(scene);
  if (need <= budget_bytes) return;
  constexpr uint64_t MIB = uint64_t{1} << 20;
  throw InputError(detail::one_line(scene.file + ": render: estimated " + std::to_string((need + MIB - 1) / MIB) +
                            " MiB for " + std::to_string(scene.camera.width) + "x" +
                            std::to_string(scene.camera.height) + " and cube " +
                            std::to_string(scene.render.cube_resolution) + " exceeds available memory " +
                            std::to_string(budget_bytes / MIB) + " MiB"));
}

}  // namespace abcube
