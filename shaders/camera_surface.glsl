// What the exact camera pass writes for one visible surface (gl_camera_exact.cpp), shared by
// its per-sample colour pass (camera_exact.frag) and its per-group one (camera_groups.frag):
// phong.frag's shading with the shadow volumes' mask, and the weights of dual-source
// blending C = color + weight * C_region: the weight is kr on a planar mirror whose virtual
// view was drawn into its region beforehand (recursed[mirror]), so the mirror shows its local
// colour plus kr times what its reflected rays meet; 0 everywhere else (the colour replaces
// what is there).
// Alpha counts the surfaces on the sample's path that the GPU only approximates (a curved
// mirror or a refraction looked up in the environment map, or left dark with no map built;
// light that a translucent blocker dims, from the shadow maps' peeled layers, by its own
// shadow volume's count): each adds 1, and a mirror drawn behind passes on what its view
// counted (weight 1). The hybrid method has the CPU redo every pixel with a sample above 0.
uniform bool u_bounces_left;        // this view's level is below max_depth: kr and kt terms count
uniform bool u_shadows_approximate; // shadows from maps here (no volume for a light), or lights past the volumes
layout(std430, binding = 2) readonly buffer Recursed { uint recursed[]; };  // per reflector + 1

// p: the point relative to the view's eye; normal: interpolated (not unit); od: its diffuse
// colour (diffuse_color); portal: its planar reflector + 1, 0 none.
void camera_surface(uint material, vec3 p, vec3 normal, vec3 od, uint portal, out vec4 color, out vec4 weight) {
  MaterialGpu m = materials[material];
  bool behind = portal != 0u && recursed[portal] != 0u;
  float kr = behind ? 0.0 : m.coefficients.w, kt = m.transmission.x;
  bool approximate = (u_bounces_left && (kr > 0.0 || kt > 0.0)) || u_shadows_approximate;
  // Light dimmed by a translucent blocker: its transmittances come from the shadow maps.
  vec3 n = normalize(normal);
  if (dot(n, -p) < 0.0) n = -n;
  for (int i = 0; i < u_light_count && !approximate; ++i) {
    float translucent = lights[i].volumes.x;
    approximate = u_volumes && translucent >= 0.0 && dot(n, lights[i].position.xyz - p) > 0.0 &&
                  volume_blocked(int(translucent)) && !volume_blocked(int(lights[i].color.w));
  }
  color = vec4(phong_local(m, p, normal, od) + environment_terms(m, p, normal, behind ? 1u : 0u),
               approximate ? 1.0 : 0.0);
  weight = vec4(vec3(behind ? m.coefficients.w : 0.0), behind ? 1.0 : 0.0);
}
