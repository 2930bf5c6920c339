// Every pass draws the scene's triangles with this stage. u_clip is cube_map.hpp's
// face_clip_matrix or camera_clip_matrix (infinite reversed-Z); u_center is the eye.
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in uint a_object;
layout(location = 3) in uint a_material;
layout(location = 4) in vec2 a_uv;  // texture coordinates (v up); (0, 0) when the scene has none

uniform mat4 u_clip;
uniform vec3 u_center;
// THE TIE RULE (cpu_core/scene/tie_rule.hpp): window depth near/w scaled by
// 1 + u_tie_step (object + 1), so at equal depth the later object passes GL_GREATER.
uniform float u_tie_step;

out vec3 v_relative;  // position relative to the eye, interpolated perspective-correctly
out vec3 v_normal;
flat out uint v_object;
flat out uint v_material;
out vec2 v_uv;

void main() {
  gl_Position = u_clip * vec4(a_position, 1.0);
  gl_Position.z *= 1.0 + u_tie_step * float(a_object + 1u);
  v_relative = a_position - u_center;
  v_normal = a_normal;
  v_object = a_object;
  v_material = a_material;
  v_uv = a_uv;
}
