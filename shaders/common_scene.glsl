// Scene data shared by the GL passes: materials and point lights in SSBOs, indexed by the
// per-vertex material id. Layout mirrors host/gl/gl_passes.cpp (std430).
struct MaterialGpu {
  vec4 color_ambient;  // rgb = Od, a = ka
  vec4 coefficients;   // x = kd, y = ks, z = shininess n, w = kr (reflect)
  vec4 transmission;   // x = kt (transmit), y = ior, z = opacity, w unused
};
struct LightGpu {
  vec4 position;  // xyz relative to the pass centre (the eye); w = shadow-map layer, -1 = none
  vec4 color;     // rgb intensity
};
layout(std430, binding = 0) readonly buffer Materials { MaterialGpu materials[]; };
layout(std430, binding = 1) readonly buffer Lights { LightGpu lights[]; };
uniform int u_light_count;
uniform vec3 u_ambient;

// Light let through by one surface crossing a shadow segment: (1 - op) + op * kt * Od,
// cpu_core/shading/shading.hpp blocker_transmittance (rule "shadows").
vec3 blocker_transmittance(MaterialGpu m) {
  float op = m.transmission.z;
  return vec3(1.0 - op) + (op * m.transmission.x) * m.color_ambient.rgb;
}

// Cube shadow maps, one cube-array layer per shadow-casting light: the distance from the
// light to the nearest opaque surface (shadow_caster.frag, u_peel < 0).
uniform bool u_shadows;
uniform samplerCubeArray u_shadow_maps;
uniform float u_shadow_texel;        // 2/N: a texel's width at unit distance, face centre
uniform float u_shadow_bias_texels;  // the bias, in texels of the shadow map
// The translucent casters, peeled front to back: layer k of light i holds the k-th nearest
// translucent crossing (distance, triangle, material; +inf distance: none).
const int MAX_SHADOW_PEELS = 8;      // gl_passes.hpp MAX_SHADOW_PEELS
uniform int u_shadow_peels;          // layers built (0: no translucent caster)
uniform samplerCubeArray u_shadow_peel_maps[MAX_SHADOW_PEELS];

// The environment cube map around the eye (Blinn & Newell 1976), for kr and kt lookups.
uniform bool u_environment;
uniform samplerCube u_environment_map;
