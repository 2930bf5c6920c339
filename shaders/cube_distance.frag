// Distance prepass: Euclidean distance from the eye (not window z), and the object id.
// Also the depth pre-pass and the mirror marks of gl_camera_exact.cpp, which leave out the
// mirror a virtual view is seen through (u_skip_portal, planar reflector + 1; 0: none).
in vec3 v_relative;
in vec3 v_normal;
flat in uint v_object;
flat in uint v_material;
flat in uint v_portal;
uniform uint u_skip_portal;

layout(location = 0) out float o_distance;
layout(location = 1) out uint o_object;

void main() {
  if (u_skip_portal != 0u && v_portal == u_skip_portal) discard;
  o_distance = length(v_relative);
  o_object = v_object;
}
