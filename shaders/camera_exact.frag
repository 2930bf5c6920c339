// The colour pass of the exact camera pass, one surface a sample (gl_camera_exact.cpp,
// ExactCameraOptions::shading samples): camera_surface.glsl's colour at the view's visible
// surface (depth EQUAL after the view's depth pass), blended by dual-source blending.
in vec3 v_relative;
in vec3 v_normal;
flat in uint v_object;
flat in uint v_material;
in vec2 v_uv;
flat in uint v_portal;

layout(location = 0, index = 0) out vec4 o_color;
layout(location = 0, index = 1) out vec4 o_weight;

void main() {
  camera_surface(v_material, v_relative, v_normal, diffuse_color(materials[v_material], v_uv), v_portal,
                 camera_environment(v_material, v_relative, v_normal, v_portal), o_color, o_weight);
}
