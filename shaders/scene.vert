// Every pass draws the scene's triangles with this stage. The vertex is taken relative to
// the eye u_center in double (a scene kilometres wide with millimetre detail keeps its
// detail in the float that follows), then u_clip maps it: cube_map.hpp's face_clip_matrix or
// camera_clip_matrix with the eye at the origin (infinite reversed-Z), times the linear part
// of the reflections of the planar mirrors a virtual view has passed through
// (gl_camera_exact.cpp), one matrix made on the CPU so that every program computes the same
// expression. gl_ClipDistance[0] keeps what lies on u_clip_plane's positive side (the
// mirror's front, relative to the eye) when GL_CLIP_DISTANCE0 is on.
// The shadow volumes (shadow_volume.frag) come through here too: their near caps are the
// scene's own triangles with a code each (volume_caps.glsl, prepended for that program
// alone), and gl_Position is invariant, so a cap and the surface it caps get the same depth
// at every sample; their faces at infinity come clipped on the CPU, as window-space points.
layout(location = 0) in vec4 a_position;  // the scene's buffer gives xyz: w = 1
layout(location = 1) in vec3 a_normal;
layout(location = 2) in uint a_object;    // where the triangle's ids are not read (triangle_ids.glsl)
layout(location = 3) in uint a_material;
layout(location = 4) in vec2 a_uv;  // texture coordinates (v up); (0, 0) when the scene has none
layout(location = 5) in uint a_portal;    // planar reflector + 1 (planar_reflectors.hpp); 0: none
layout(location = 6) in uint a_reversed;  // shadow volumes: the face's outward orientation is against its winding

uniform mat4 u_clip;
uniform vec4 u_clip_plane;
uniform dvec3 u_center;
// THE TIE RULE (cpu_core/scene/tie_rule.hpp): window depth near/w scaled by
// 1 + u_tie_step (object + 1), so at equal depth the later object passes GL_GREATER.
uniform float u_tie_step;
// The planar reflector (+ 1) a virtual view is seen through (gl_camera_exact.cpp): its
// triangles are left out, every vertex put at the clip origin (w = 0), where no triangle is
// drawn. 0: none.
uniform uint u_skip_portal;

invariant gl_Position;
out vec3 v_relative;  // position relative to the eye, interpolated perspective-correctly
out vec3 v_normal;
flat out uint v_object;
flat out uint v_material;
out vec2 v_uv;
flat out uint v_portal;
flat out uint v_reversed;

void main() {
  uint object = a_object, material = a_material;
#ifdef TRIANGLE_IDS
  if (!u_vertex_ids) {
    const uint triangle = uint(gl_VertexID) / 3u;
    object = object_ids[triangle];
    material = material_ids[triangle];
  }
#endif
  // A point at infinity (w = 0, the shadow volumes') is a direction: nothing to subtract.
  vec4 relative = a_position.w == 0.0 ? a_position : vec4(vec3(dvec3(a_position.xyz) - u_center), 1.0);
  gl_Position = u_clip * relative;
  gl_Position.z *= 1.0 + u_tie_step * float(object + 1u);
  if (u_skip_portal != 0u && a_portal == u_skip_portal) gl_Position = vec4(0.0);
  uint reversed = a_reversed;
#ifdef VOLUME_CAPS
  if (u_caps) {
    const uint code = volume_cap_code(gl_VertexID);
    if (code == 0u) gl_Position = vec4(0.0);
    reversed = code == 2u ? 1u : 0u;
  }
#endif
  gl_ClipDistance[0] = dot(u_clip_plane, relative);  // at infinity: its direction's side
  v_relative = relative.xyz;
  v_normal = a_normal;
  v_object = object;
  v_material = material;
  v_uv = a_uv;
  v_portal = a_portal;
  v_reversed = reversed;
}
