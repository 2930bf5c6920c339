// The memory a render of a scene needs, estimated before it starts (scene_load.hpp).
#include <string>

#include "base/error.hpp"
#include "scene/scene_json.hpp"
#include "scene/scene_load.hpp"

namespace abcube {

namespace {

// Bytes per unit of work, for the estimate: a camera pixel holds its colour and A-buffer
// fragment headroom; a cube texel its distance and fragment headroom. A triangle: the peak
// resident bytes a triangle of scene data costs above the process's own, measured by
// bench/memory.py on 440k- and 1M-triangle meshes (bench/results/memory.txt, the exact
// tracer and the side structure on Embree: at most 168 for raytrace, abuffer, zbuffer and
// envmap; the soup's 80 of it), rounded up; the gpu method adds the GL vertex buffer
// (3 vertices of 32 bytes, gl_passes.cpp) and what llvmpipe holds while it draws them
// (about 90 more, measured from /proc/self/statm around the first draw); gpu measured
// 380 a triangle at 1M triangles (marginal 230).
constexpr uint64_t PIXEL_BYTES = 3 * sizeof(float) + 64;
constexpr uint64_t TEXEL_BYTES = 64;
constexpr uint64_t TRIANGLE_BYTES = 170;
constexpr uint64_t GL_TRIANGLE_BYTES = 3 * 32 + 90;
static_assert(TRIANGLE_BYTES >= 6 * sizeof(glm::vec3) + 2 * sizeof(uint32_t), "the soup alone");

}  // namespace

uint64_t estimate_render_bytes(const SceneData& scene) {
  const uint64_t pixels = static_cast<uint64_t>(scene.camera.width) * static_cast<uint64_t>(scene.camera.height);
  const uint64_t n = static_cast<uint64_t>(scene.render.cube_resolution);
  const uint64_t per_triangle = TRIANGLE_BYTES + (scene.render.method == Method::gpu ? GL_TRIANGLE_BYTES : 0);
  return pixels * PIXEL_BYTES + 6 * n * n * TEXEL_BYTES + scene.triangles->triangle_count() * per_triangle;
}

void check_render_size(const SceneData& scene, uint64_t budget_bytes) {
  const uint64_t need = estimate_render_bytes(scene);
  if (need <= budget_bytes) return;
  constexpr uint64_t MIB = uint64_t{1} << 20;
  throw InputError(one_line(scene.file + ": render: estimated " + std::to_string((need + MIB - 1) / MIB) +
                            " MiB for " + std::to_string(scene.camera.width) + "x" +
                            std::to_string(scene.camera.height) + " and cube " +
                            std::to_string(scene.render.cube_resolution) + " exceeds available memory " +
                            std::to_string(budget_bytes / MIB) + " MiB"));
}

}  // namespace abcube
