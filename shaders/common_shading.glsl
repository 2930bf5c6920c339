// Phong local shading, the GLSL mirror of cpu_core/shading.hpp phong_local (thesis ch. 6):
//   C = ka Ia Od + sum_l I_l (kd Od max(0, N.L) + ks max(0, R.V)^n),  R = reflect(-L, N),
// with N turned to face the viewer (two-sided lighting). p is relative to the eye.
vec3 phong_local(MaterialGpu m, vec3 p, vec3 n_in) {
  vec3 v = normalize(-p);
  vec3 n = normalize(n_in);
  if (dot(n, v) < 0.0) n = -n;
  vec3 od = m.color_ambient.rgb;
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
    c += lights[i].color.rgb * term;
  }
  return c;
}
