// Z-buffer colour pass: local Phong per point light, shadows from the cube shadow maps when
// they are bound, and Blinn-Newell environment lookups when the environment map is bound.
// The camera view of a scene with coverage transparency is peeled (gl_camera_pass.cpp
// camera_color): pass u_peel = k >= 1 keeps only what lies behind layer k - 1 at this
// sample, in the order (distance, triangle); alpha is the material's opacity.
in vec3 v_relative;
in vec3 v_normal;
flat in uint v_object;
flat in uint v_material;
in vec2 v_uv;

uniform int u_peel;            // 0: the nearest surface; k >= 1: the k-th behind it
uniform sampler2D u_previous;  // layer k - 1: (distance, triangle) per sample

layout(location = 0) out vec4 o_color;
layout(location = 1) out vec2 o_layer;  // (distance, triangle) of this sample's surface

void main() {
  // Before any discard: the texture's derivatives need the whole quad of fragments.
  vec3 od = diffuse_color(materials[v_material], v_uv);
  float d = length(v_relative);
  float id = float(gl_PrimitiveID);
  if (u_peel > 0) {
    vec2 previous = texelFetch(u_previous, ivec2(gl_FragCoord.xy), 0).rg;
    if (isinf(previous.r) || d < previous.r || (d == previous.r && id <= previous.g)) discard;
  }
  MaterialGpu m = materials[v_material];
  o_color = vec4(phong_local(m, v_relative, v_normal, od) + environment_terms(m, v_relative, v_normal, 0u),
                 m.transmission.z);
  o_layer = vec2(d, id);
}
