// abcube crosscheck: at the visible surface of each camera sample, for the first 16
// shadow-casting lights (the light's probe index u_probe[i], -1: not probed), whether the
// shadow volumes' count and the cube shadow map each say an opaque blocker lies between the
// surface and the light, and whether the surface faces the light (N.L > 0, N turned to the
// eye): three 16-bit sets, as exact floats. common_shading.glsl's rules, taken apart.
in vec3 v_relative;
in vec3 v_normal;
flat in uint v_material;
uniform int u_probe[64];

layout(location = 0) out vec4 o_bits;

void main() {
  vec3 p = v_relative;
  vec3 n = normalize(v_normal);
  if (dot(n, -p) < 0.0) n = -n;
  uint volume = 0u, map = 0u, lit = 0u;
  for (int i = 0; i < min(u_light_count, 64); ++i) {
    int k = u_probe[i];
    if (k < 0) continue;
    vec3 to_light = lights[i].position.xyz - p;
    if (dot(n, to_light) > 0.0) lit |= 1u << uint(k);
    int b = int(lights[i].color.w);
    if (b >= 0 && volume_blocked(b)) volume |= 1u << uint(k);
    float layer = lights[i].position.w;
    if (u_shadows && layer >= 0.0) {
      vec3 d = p - lights[i].position.xyz;
      float dist = length(d);
      float slope = max(abs(dot(n, d / dist)), 0.2);
      float bias = u_shadow_bias_texels * u_shadow_texel * dist / slope;
      if (dist > texture(u_shadow_maps, vec4(d, layer)).r + bias) map |= 1u << uint(k);
    }
  }
  o_bits = vec4(float(volume), float(map), float(lit), 1.0);
}
