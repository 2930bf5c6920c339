#include "render/method_context.hpp"

#include "base/error.hpp"
#include "base/timer.hpp"
#include "gl/gl_abuffer.hpp"
#include "gl/gl_passes.hpp"

namespace abcube {

MapShadingOptions map_shading_options(const MethodContext& mc) {
  MapShadingOptions options = mc.request.map;
  options.walk_all_shadows = mc.request.plan_everything;
  return options;
}

namespace {

// The GL builder of `mc`'s scene when the request builds its A-buffers on GL, else null.
const GlABufferBuilder* gl_builder(const MethodContext& mc) {
  if (!mc.request.abuffers_on_gl) return nullptr;
  ABCUBE_CHECK(mc.gl_scene != nullptr, "A-buffers on GL without the scene on GL");
  return &mc.gl_scene->abuffer_builder();
}

}  // namespace

ABuffer build_camera_abuffer(const MethodContext& mc, const ABufferOptions& options, ABufferStats* stats) {
  const GlABufferBuilder* gl = gl_builder(mc);
  return gl ? gl->camera(mc.scene, options, stats) : build_camera_abuffer(mc.scene, options, stats);
}

CubeMap build_cube_map(const MethodContext& mc, int n, const ABufferOptions& options, const RayTracer* reference,
                       const MapShadingOptions& shading) {
  CubeMap m;
  m.n = n;
  Clock::time_point t0 = Clock::now();
  const GlABufferBuilder* gl = gl_builder(mc);
  const glm::dvec3& centre = mc.scene.camera.position;
  m.cube = std::make_unique<CubeABuffer>(gl ? gl->cube(mc.scene, centre, n, options, &m.stats)
                                            : build_cube_abuffer(mc.scene, centre, n, options, &m.stats));
  m.build_ms = ms_since(t0);
  t0 = Clock::now();
  m.shader = std::make_unique<MapShader>(mc.scene, *m.cube, shading, reference, &mc.cache);
  m.setup_ms = ms_since(t0);
  return m;
}

}  // namespace abcube
