// The memory a render of a scene needs, estimated before it starts (scene_load.hpp).
#include <algorithm>
#include <string>

#include "base/error.hpp"
#include "base/memory.hpp"
#include "scene/scene_json.hpp"
#include "scene/scene_load.hpp"
#include "scene/gpu_limits.hpp"

namespace abcube {

namespace {

constexpr uint64_t MIB = uint64_t{1} << 20;

// Bytes per unit of work, beside the A-buffers' fragments: a camera pixel holds its colour,
// the A-buffer's per-pixel index and room for the AOVs and the reference image; a cube texel
// its distance, the A-buffer's index and the searches' block bounds and pyramid (or the gpu
// method's cube textures); a triangle SCENE_TRIANGLE_BYTES. The gpu method adds the GL's
// arrays (gl_scene_buffers.cpp), counted at their largest, a copy with ids on every vertex, since
// the estimate is made before the GL is opened, plus an allowance for what a software GL
// holds while it draws them; a shadow-casting light's cube map of N x N floats; and its
// shadow volumes (gpu_geometry/shadow_volume.hpp: a code a triangle and the runs of casting triangles,
// twice, and the side pairing's buckets), counted for every gpu render since the method's
// options are not read yet. docs/design/scene-size.md has the accounting.
constexpr uint64_t VOLUME_TRIANGLE_BYTES = 2 * (2 + 8);
constexpr uint64_t VOLUME_PAIRING_TRIANGLE_BYTES = 3;
constexpr uint64_t VOLUME_PAIRING_EDGES_BYTES = PAIRING_BUCKET_EDGES * PAIRING_EDGE_BYTES;
constexpr uint64_t PIXEL_BYTES = 3 * sizeof(float) + 64;
constexpr uint64_t TEXEL_BYTES = 64;
constexpr uint64_t GL_TRIANGLE_BYTES = 104 + 90;
constexpr uint64_t GL_SHADOW_TEXEL_BYTES = 6 * sizeof(float);  // six faces
static_assert(SCENE_TRIANGLE_BYTES >= 6 * sizeof(glm::vec3) + 2 * sizeof(uint32_t), "the soup alone");

std::string mib(uint64_t bytes) { return std::to_string((bytes + MIB - 1) / MIB); }

}  // namespace

uint64_t memory_budget_bytes(uint64_t max_memory_bytes) {
  return max_memory_bytes > 0 ? max_memory_bytes : available_memory_bytes();
}

std::string budget_words(uint64_t budget_bytes, bool capped) {
  return capped ? "above --max-memory " + std::to_string(budget_bytes / MIB) + " MiB"
                : "above the " + std::to_string(budget_bytes / MIB) + " MiB of memory available";
}

uint64_t estimate_render_bytes(const SceneData& scene, bool gpu) {
  const uint64_t pixels = static_cast<uint64_t>(scene.camera.width) * static_cast<uint64_t>(scene.camera.height);
  const uint64_t n = static_cast<uint64_t>(scene.render.cube_resolution);
  uint64_t shadow_lights = 0;
  for (const PointLight& l : scene.lights) shadow_lights += l.cast_shadows ? 1 : 0;
  const uint64_t volume_lights = std::min(shadow_lights, uint64_t{MAX_VOLUME_LIGHTS});
  const uint64_t triangles = scene.triangles->triangle_count();
  const uint64_t volumes =
      volume_lights > 0 ? volume_lights * VOLUME_TRIANGLE_BYTES + VOLUME_PAIRING_TRIANGLE_BYTES : 0;
  const uint64_t pairing =
      volume_lights > 0 ? std::min(VOLUME_PAIRING_EDGES_BYTES, 3 * PAIRING_EDGE_BYTES * triangles) : 0;
  const uint64_t per_triangle = SCENE_TRIANGLE_BYTES + (gpu ? GL_TRIANGLE_BYTES + volumes : 0);
  return pixels * PIXEL_BYTES + 6 * n * n * TEXEL_BYTES + triangles * per_triangle +
         (gpu ? shadow_lights * n * n * GL_SHADOW_TEXEL_BYTES + pairing : 0);
}

void check_render_size(const SceneData& scene, bool gl, uint64_t budget_bytes, bool capped) {
  const uint64_t need = estimate_render_bytes(scene, gl);
  if (need <= budget_bytes) return;
  throw InputError(one_line(scene.file + ": render: estimated " + mib(need) + " MiB for " +
                            std::to_string(scene.camera.width) + "x" + std::to_string(scene.camera.height) + ", cube " +
                            std::to_string(scene.render.cube_resolution) + " and " +
                            std::to_string(scene.triangles->triangle_count()) +
                            " triangles (before the A-buffers' "
                            "fragments), " +
                            budget_words(budget_bytes, capped)));
}

}  // namespace abcube
