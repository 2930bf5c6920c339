// Scene data shared by the GL passes: materials and point lights in SSBOs, indexed by the
// per-vertex material id. Layout mirrors host/gl/gl_scene_buffers.cpp (std430).
struct MaterialGpu {
  vec4 color_ambient;  // rgb = Od, a = ka
  vec4 coefficients;   // x = kd, y = ks, z = shininess n, w = kr (reflect)
  vec4 transmission;   // x = kt (transmit), y = ior, z = opacity, w = texture (-1: none)
};
struct LightGpu {
  vec4 position;  // xyz relative to the pass centre (the eye); w = shadow-map layer, -1 = none
  vec4 color;     // rgb intensity; w = the shadow-volume count of its opaque blockers, -1 = none
  vec4 volumes;   // x = the count of its translucent blockers, -1 = none (gl_shadow_volumes.cpp)
};
layout(std430, binding = MATERIALS_BINDING) readonly buffer Materials { MaterialGpu materials[]; };
layout(std430, binding = LIGHTS_BINDING) readonly buffer Lights { LightGpu lights[]; };
uniform int u_light_count;
uniform vec3 u_ambient;

// Light let through by one surface crossing a shadow segment: (1 - op) + op * kt * Od,
// cpu_core/material/shading.hpp blocker_transmittance (rule "shadows").
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
uniform int u_shadow_peels;          // layers built (0: no translucent caster)
uniform samplerCubeArray u_shadow_peel_maps[MAX_SHADOW_PEELS];

// The environment cube map around the eye (Blinn & Newell 1976), for kr and kt lookups.
uniform bool u_environment;
uniform samplerCube u_environment_map;

// Base-colour textures (cpu_core/scene/texture.hpp THE RULE): Od =
// colour * texture(uv), linear RGB, repeat, trilinear over GL's mipmaps. The images are
// grouped by size into up to MAX_TEXTURE_ARRAYS 2D arrays (gl_scene_buffers.cpp); a material's
// transmission.w = array + MAX_TEXTURE_ARRAYS * layer. Each array is sampled in its own
// branch with the derivatives taken outside it (uniform control flow), so the index need
// not be uniform.
uniform sampler2DArray u_textures[MAX_TEXTURE_ARRAYS];
// True: level 0 only (zero derivatives), the CPU's point sample (abcube crosscheck).
uniform bool u_texture_level0;

// dx, dy: the change of uv from one sample to the next along x and y (the footprint).
vec3 diffuse_color_footprint(MaterialGpu m, vec2 uv, vec2 dx, vec2 dy) {
  if (u_texture_level0) dx = dy = vec2(0.0);
  float code = m.transmission.w;
  if (code < 0.0) return m.color_ambient.rgb;
  int array = int(code) % MAX_TEXTURE_ARRAYS;
  vec3 coordinate = vec3(uv, float(int(code) / MAX_TEXTURE_ARRAYS));
  vec3 t = vec3(1.0);
  if (array == 0) t = textureGrad(u_textures[0], coordinate, dx, dy).rgb;
  else if (array == 1) t = textureGrad(u_textures[1], coordinate, dx, dy).rgb;
  else if (array == 2) t = textureGrad(u_textures[2], coordinate, dx, dy).rgb;
  else t = textureGrad(u_textures[3], coordinate, dx, dy).rgb;
  return m.color_ambient.rgb * t;
}

vec3 diffuse_color(MaterialGpu m, vec2 uv) { return diffuse_color_footprint(m, uv, dFdx(uv), dFdy(uv)); }
