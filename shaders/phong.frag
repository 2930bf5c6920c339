// Z-buffer colour pass: local Phong per point light, shadows from the cube shadow maps when
// they are bound, and Blinn-Newell environment lookups when the environment map is bound.
in vec3 v_relative;
in vec3 v_normal;
flat in uint v_object;
flat in uint v_material;

layout(location = 0) out vec4 o_color;

void main() {
  MaterialGpu m = materials[v_material];
  o_color = vec4(phong_local(m, v_relative, v_normal) + environment_terms(m, v_relative, v_normal), 1.0);
}
