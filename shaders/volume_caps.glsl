// The shadow volumes' near caps (cpu_core/gpu_geometry/shadow_volume.hpp, gl_shadow_volumes.cpp
// GlShadowVolumes::count): the volume program draws the scene's own vertex buffer, so that each cap
// is its surface's triangle, the same vertices in the same order through the same transform
// (the same depth at every sample), and reads each triangle's code here: 0 none (the
// triangle casts nothing in this volume), 1 a cap as wound, 2 a cap oriented against its
// winding. Four codes a word, byte k of word i for triangle 4 i + k. Its binding:
// glsl_shared.hpp VOLUME_CAPS_BINDING.
#define VOLUME_CAPS 1
layout(std430, binding = VOLUME_CAPS_BINDING) readonly buffer VolumeCaps { uint volume_caps[]; };
uniform bool u_caps;  // drawing the near caps (the faces at infinity come clipped, with their own flags)

uint volume_cap_code(int vertex) {
  const uint triangle = uint(vertex) / 3u;
  return (volume_caps[triangle >> 2u] >> (8u * (triangle & 3u))) & 0xffu;
}
