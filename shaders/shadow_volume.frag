// Depth-fail counting of a light's shadow volume (cpu_core/scene/shadow_volume.hpp; Everitt
// & Kilgard 2002): drawn with the depth test passing where the face lies behind or at the
// visible surface (GL_LEQUAL in reversed Z) and additive blending, each outward-oriented
// face adds +1 seen from behind (an exit) and -1 seen from the front (an entry). The sum is
// the number of blocker prisms holding the surface point: nonzero is shadow. Four lights a
// layer, one channel each.
flat in uint v_reversed;
layout(location = 0) out vec4 o_count;  // every channel; the light's alone is written (glColorMaski)

void main() {
  const bool front = gl_FrontFacing != (v_reversed != 0u);
  o_count = vec4(front ? -1.0 : 1.0);
}
