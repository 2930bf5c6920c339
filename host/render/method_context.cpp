#include "render/method_context.hpp"

#include "base/timer.hpp"

namespace abcube {

MapShadingOptions map_shading_options(const MethodContext& mc) {
  MapShadingOptions options = mc.request.map;
  options.walk_all_shadows = mc.request.plan_everything;
  return options;
}

CubeMap build_cube_map(const MethodContext& mc, int n, const ABufferOptions& options, const RayTracer* reference,
                       const MapShadingOptions& shading) {
  CubeMap m;
  m.n = n;
  Clock::time_point t0 = Clock::now();
  m.cube = std::make_unique<CubeABuffer>(build_cube_abuffer(mc.scene, mc.scene.camera.position, n, options, &m.stats));
  m.build_ms = ms_since(t0);
  t0 = Clock::now();
  m.shader = std::make_unique<MapShader>(mc.scene, *m.cube, shading, reference, &mc.cache);
  m.setup_ms = ms_since(t0);
  return m;
}

}  // namespace abcube
