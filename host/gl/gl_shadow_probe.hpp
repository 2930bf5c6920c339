// abcube crosscheck's shadow probe: at the visible surface of each camera sample (the 4x8
// grid, row 0 at the top, as GlScene::camera_objects), for the first 16 shadow-casting
// lights (`lights`, probe bit k = lights[k]): the lights blocked by an opaque blocker
// according to the shadow volumes, according to the cube shadow maps (build_shadow_maps
// first), and the lights the surface faces (shadow_probe.frag).
#pragma once
#include <cstdint>
#include <vector>

#include "gl/gl_passes.hpp"

namespace abcube {

struct GlShadowProbe {
  std::vector<int> lights;
  std::vector<uint16_t> volume, map, lit;
};

GlShadowProbe probe_camera_shadows(GlScene& gl, const Camera& camera);

}  // namespace abcube
