// Shadow-map passes, rendered from a light (gl_shadow_maps.cpp build_shadow_maps). The CPU's
// rule "shadows" (cpu_core/material/shading.hpp): S_l is the product over every surface
// crossing the segment P..L of blocker_transmittance. Opaque casters (transmittance 0 in
// every channel) go to the distance map (u_peel < 0); the others are peeled front to back,
// one layer per pass (u_peel = k >= 0: the nearest crossing behind layer k - 1, in the
// order (distance, triangle)), each layer holding its distance and material, so that the
// lookup multiplies the transmittances of exactly the layers between P and the light.
in vec3 v_relative;
in vec3 v_normal;
flat in uint v_object;
flat in uint v_material;

uniform int u_peel;                 // -1: opaque casters; k >= 0: translucent layer k
uniform float u_light_layer;        // the light's cube-array layer
uniform samplerCubeArray u_opaque;  // the opaque distance map (translucent peels)
uniform samplerCubeArray u_previous;  // layer k - 1 (k >= 1)

// Opaque pass: r = distance. Peels: r = distance (+inf: no layer), g = triangle index,
// b = material index (exact in float up to 2^24).
layout(location = 0) out vec4 o_layer;

void main() {
  vec3 t = blocker_transmittance(materials[v_material]);
  bool opaque = all(equal(t, vec3(0.0)));
  float d = length(v_relative);
  if (u_peel < 0) {
    if (!opaque) discard;
    o_layer = vec4(d, 0.0, 0.0, 0.0);
    return;
  }
  // Fully clear surfaces change nothing; surfaces behind the nearest opaque one are never
  // between a lit point and the light.
  if (opaque || all(equal(t, vec3(1.0)))) discard;
  if (d >= texture(u_opaque, vec4(v_relative, u_light_layer)).r) discard;
  float id = float(gl_PrimitiveID);
  if (u_peel > 0) {
    vec4 previous = texture(u_previous, vec4(v_relative, u_light_layer));
    if (isinf(previous.r) || d < previous.r || (d == previous.r && id <= previous.g)) discard;
  }
  o_layer = vec4(d, id, float(v_material), 0.0);
}
