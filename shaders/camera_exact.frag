// The colour pass of the exact camera pass (gl_camera_exact.cpp): phong.frag's shading at the
// view's visible surface (depth EQUAL after the view's depth pass), with the shadow
// volumes' mask (u_volumes), and dual-source blending C = C_surface + weight * C_region:
// the weight is kr on a planar mirror whose virtual view was drawn into its region
// beforehand (recursed[mirror]), so the mirror shows its local colour plus kr times what
// its reflected rays meet; 0 everywhere else (the colour replaces what is there).
// Alpha counts the surfaces on the sample's path that the GPU only approximates (a curved
// mirror or a refraction looked up in the environment map, or left dark with no map built;
// light that a translucent blocker dims, from the shadow maps' peeled layers, by its own
// shadow volume's count): each adds 1, and a mirror drawn
// behind passes on what its view counted (weight 1). The hybrid method has the CPU redo
// every pixel with a sample above 0.
in vec3 v_relative;
in vec3 v_normal;
flat in uint v_object;
flat in uint v_material;
in vec2 v_uv;
flat in uint v_portal;
uniform bool u_bounces_left;        // this view's level is below max_depth: kr and kt terms count
uniform bool u_shadows_approximate; // shadows from maps here (no volume for a light), or lights past the volumes
layout(std430, binding = 2) readonly buffer Recursed { uint recursed[]; };  // per reflector + 1

layout(location = 0, index = 0) out vec4 o_color;
layout(location = 0, index = 1) out vec4 o_weight;

void main() {
  vec3 od = diffuse_color(materials[v_material], v_uv);
  MaterialGpu m = materials[v_material];
  bool behind = v_portal != 0u && recursed[v_portal] != 0u;
  float kr = behind ? 0.0 : m.coefficients.w, kt = m.transmission.x;
  bool approximate = (u_bounces_left && (kr > 0.0 || kt > 0.0)) || u_shadows_approximate;
  // Light dimmed by a translucent blocker: its transmittances come from the shadow maps.
  vec3 n = normalize(v_normal);
  if (dot(n, -v_relative) < 0.0) n = -n;
  for (int i = 0; i < u_light_count && !approximate; ++i) {
    float translucent = lights[i].volumes.x;
    approximate = u_volumes && translucent >= 0.0 && dot(n, lights[i].position.xyz - v_relative) > 0.0 &&
                  volume_blocked(int(translucent)) && !volume_blocked(int(lights[i].color.w));
  }
  o_color = vec4(phong_local(m, v_relative, v_normal, od) + environment_terms(m, v_relative, v_normal, behind ? 1u : 0u),
                 approximate ? 1.0 : 0.0);
  o_weight = vec4(vec3(behind ? m.coefficients.w : 0.0), behind ? 1.0 : 0.0);
}
