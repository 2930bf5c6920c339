// Z-buffer colour pass: local Phong per point light, no shadows.
in vec3 v_relative;
in vec3 v_normal;
flat in uint v_object;
flat in uint v_material;

layout(location = 0) out vec4 o_color;

void main() {
  o_color = vec4(phong_local(materials[v_material], v_relative, v_normal), 1.0);
}
