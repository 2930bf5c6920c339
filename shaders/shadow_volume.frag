// Depth-fail counting of a light's shadow volume (cpu_core/gpu_geometry/shadow_volume.hpp; Everitt
// & Kilgard 2002): drawn with the depth test passing where the face lies behind or at the
// visible surface (GL_LEQUAL in reversed Z) and additive blending, each outward-oriented
// face adds +1 seen from behind (an exit) and -1 seen from the front (an entry). The sum is
// the number of blocker prisms holding the surface point: nonzero is shadow. A layer a light.
layout(early_fragment_tests) in;  // no depth written: the test first, then the count
flat in uint v_reversed;
layout(location = 0) out float o_count;

void main() {
  const bool front = gl_FrontFacing != (v_reversed != 0u);
  o_count = front ? -1.0 : 1.0;
}
