// Phong local shading, the GLSL mirror of cpu_core/material/shading.hpp (thesis ch. 6):
//   C = ka Ia Od + sum_l S_l I_l (kd Od max(0, N.L) + ks max(0, R.V)^n),  R = reflect(-L, N),
// with N turned to face the viewer (two-sided lighting). p is relative to the eye.

// Shadow volumes (gl_shadow_volumes.cpp): per camera sample and volume light (the light's
// color.w, -1: none; count b is layer b), the depth-fail count of its
// volume's faces behind the surface (shadow_volume.frag): the number of opaque blockers'
// prisms holding the surface point, 0 when none lies between it and the light. Camera
// passes only.
uniform bool u_volumes;
uniform sampler2DArray u_volume_counts;

// A pass that shades a group of samples at once (camera_groups.frag) gives their common
// answer instead: bit b of volume_set (volume_from_set true).
bool volume_from_set = false;
uvec4 volume_set = uvec4(0u);

bool volume_blocked(int b) {
  if (volume_from_set) return ((volume_set[b / 32] >> uint(b % 32)) & 1u) != 0u;
  return texelFetch(u_volume_counts, ivec3(ivec2(gl_FragCoord.xy), b), 0).r != 0.0;
}

// S_l (rule "shadows", as the CPU's shadow search and the exact tracer): 0 when an opaque
// blocker lies between p and the light: from the shadow volumes' count when the light has
// one, else from its cube shadow map (p farther from the light than the nearest opaque
// surface the map stored in that direction, plus a bias of u_shadow_bias_texels texels, a
// texel at distance d being about u_shadow_texel * d wide, grown at grazing light); then the
// product of the transmittances of the translucent layers nearer to the light than p (less
// the same bias).
vec3 light_visibility(int i, vec3 p, vec3 n) {
  float layer = lights[i].position.w;
  float bit = lights[i].color.w;
  bool volume = u_volumes && bit >= 0.0;
  if (!volume && (!u_shadows || layer < 0.0)) return vec3(1.0);
  if (volume) {
    if (volume_blocked(int(bit))) return vec3(0.0);
    // No translucent blocker between: nothing to dim (its volume counted 0).
    float translucent = lights[i].volumes.x;
    if (translucent >= 0.0 && !volume_blocked(int(translucent))) return vec3(1.0);
    if (!u_shadows || layer < 0.0) return vec3(1.0);
  }
  vec3 d = p - lights[i].position.xyz;
  float dist = length(d);
  float slope = max(abs(dot(n, d / dist)), 0.2);
  float bias = u_shadow_bias_texels * u_shadow_texel * dist / slope;
  if (!volume && dist > texture(u_shadow_maps, vec4(d, layer)).r + bias) return vec3(0.0);
  vec3 s = vec3(1.0);
  for (int k = 0; k < u_shadow_peels; ++k) {
    vec4 crossing = texture(u_shadow_peel_maps[k], vec4(d, layer));
    if (!(crossing.r + bias < dist)) break;  // layers are sorted: the rest are farther
    s *= blocker_transmittance(materials[int(crossing.b)]);
  }
  return s;
}

// od: the diffuse colour at the point (diffuse_color in common_scene.glsl).
vec3 phong_local(MaterialGpu m, vec3 p, vec3 n_in, vec3 od) {
  vec3 v = normalize(-p);
  vec3 n = normalize(n_in);
  if (dot(n, v) < 0.0) n = -n;
  vec3 c = m.color_ambient.a * u_ambient * od;
  for (int i = 0; i < u_light_count; ++i) {
    vec3 l = normalize(lights[i].position.xyz - p);
    float ndotl = dot(n, l);
    if (ndotl <= 0.0) continue;
    vec3 term = m.coefficients.x * ndotl * od;
    if (m.coefficients.y > 0.0) {
      vec3 r = 2.0 * ndotl * n - l;
      float rdotv = dot(r, v);
      if (rdotv > 0.0) term += vec3(m.coefficients.y * pow(rdotv, m.coefficients.z));
    }
    c += light_visibility(i, p, n) * lights[i].color.rgb * term;
  }
  return c;
}

// Blinn & Newell 1976: what a mirror (kr) and a refracting surface (kt) show, looked up in
// the environment map around the eye in the reflected and refracted directions, as if
// everything were infinitely far away. Refraction is one interface (Snell with eta =
// 1/ior; total internal reflection looks up the mirror direction). The lookup direction
// is the envmap method's (map_shading.cpp envmap_direction, thesis 9.2): u_lookup 0 the
// ray's direction R, 1 the bisector [[R + [[W]]]], 2 [[W]] (W = p, the eye is the map's
// centre). With u_fresnel, Schlick's weights as shading.hpp secondary_weights (the cosine
// on the incident side: this one interface is always entered).
uniform int u_lookup;
uniform bool u_fresnel;
// True in the camera pass of gl_camera_exact.cpp: a planar mirror whose virtual view was
// drawn (portal != 0) gets its reflection from it, not from the environment map.
uniform bool u_portals_exact;

vec3 lookup_direction(vec3 p, vec3 r) {
  vec3 w = normalize(p);
  if (u_lookup == 1) {
    vec3 b = r + w;
    return dot(b, b) > 1e-24 ? normalize(b) : r;  // R = -[[W]]: no bisector
  }
  return u_lookup == 2 ? w : r;
}

// Whether environment_terms looks material m up in the map (portal as there).
bool environment_looked_up(MaterialGpu m, uint portal) {
  float kr = (u_portals_exact && portal != 0u) ? 0.0 : m.coefficients.w;
  return u_environment && (kr > 0.0 || m.transmission.x > 0.0);
}

vec3 environment_terms(MaterialGpu m, vec3 p, vec3 n_in, uint portal) {
  if (!environment_looked_up(m, portal)) return vec3(0.0);
  float kr = (u_portals_exact && portal != 0u) ? 0.0 : m.coefficients.w, kt = m.transmission.x;
  vec3 i = normalize(p);
  vec3 n = normalize(n_in);
  if (dot(n, i) > 0.0) n = -n;
  vec3 t = refract(i, n, 1.0 / m.transmission.y);
  bool total = t == vec3(0.0);
  if (total) t = reflect(i, n);
  if (u_fresnel && kt > 0.0 && !total) {
    float ior = m.transmission.y;
    float f0 = ((ior - 1.0) / (ior + 1.0)) * ((ior - 1.0) / (ior + 1.0));
    float f = f0 + (1.0 - f0) * pow(1.0 - min(abs(dot(i, n)), 1.0), 5.0);
    kr += f * kt;
    kt *= 1.0 - f;
  }
  vec3 c = vec3(0.0);
  if (kr > 0.0) c += kr * texture(u_environment_map, lookup_direction(p, reflect(i, n))).rgb;
  if (kt > 0.0) c += kt * texture(u_environment_map, lookup_direction(p, t)).rgb;
  return c;
}
