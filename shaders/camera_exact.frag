// The colour pass of the exact camera pass (gl_camera_exact.cpp): phong.frag's shading at the
// view's visible surface (depth GEQUAL after the view's depth pass), with the shadow
// volumes' mask (u_volumes), and dual-source blending C = C_surface + weight * C_region:
// the weight is kr on a planar mirror whose virtual view was drawn into its region
// beforehand (recursed[mirror]), so the mirror shows its local colour plus kr times what
// its reflected rays meet; 0 everywhere else (the colour replaces what is there).
in vec3 v_relative;
in vec3 v_normal;
flat in uint v_object;
flat in uint v_material;
in vec2 v_uv;
flat in uint v_portal;
uniform uint u_skip_portal;  // the mirror this view is seen through (planar reflector + 1; 0: none)
layout(std430, binding = 2) readonly buffer Recursed { uint recursed[]; };  // per reflector + 1

layout(location = 0, index = 0) out vec4 o_color;
layout(location = 0, index = 1) out vec4 o_weight;

void main() {
  // Before the discard: the texture's derivatives need the whole quad of fragments.
  vec3 od = diffuse_color(materials[v_material], v_uv);
  if (u_skip_portal != 0u && v_portal == u_skip_portal) discard;
  MaterialGpu m = materials[v_material];
  bool behind = v_portal != 0u && recursed[v_portal] != 0u;
  o_color = vec4(phong_local(m, v_relative, v_normal, od) + environment_terms(m, v_relative, v_normal, behind ? 1u : 0u),
                 1.0);
  o_weight = vec4(vec3(behind ? m.coefficients.w : 0.0), 0.0);
}
