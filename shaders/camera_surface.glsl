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
layout(std430, binding = RECURSED_BINDING) readonly buffer Recursed { uint recursed[]; };  // per reflector + 1

// Whether a planar mirror's virtual view was drawn behind it (portal: its reflector + 1).
bool drawn_behind(uint portal) { return portal != 0u && recursed[portal] != 0u; }

// What a surface shows of the environment map (curved mirrors, refraction), the term
// camera_surface adds (environment_terms; 0 where it looks nothing up), and whether it looks
// anything up.
vec3 camera_environment(uint material, vec3 p, vec3 normal, uint portal) {
  return environment_terms(materials[material], p, normal, drawn_behind(portal) ? 1u : 0u);
}
bool camera_looks_up(uint material, uint portal) {
  return environment_looked_up(materials[material], drawn_behind(portal) ? 1u : 0u);
}

// p: the point relative to the view's eye; normal: interpolated (not unit); od: its diffuse
// colour (diffuse_color); portal: its planar reflector + 1, 0 none; environment: its
// camera_environment (at the point, or the mean of a group's samples').
void camera_surface(uint material, vec3 p, vec3 normal, vec3 od, uint portal, vec3 environment, out vec4 color,
                    out vec4 weight) {
  MaterialGpu m = materials[material];
  bool behind = drawn_behind(portal);
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
  color = vec4(phong_local(m, p, normal, od) + environment,
               approximate ? 1.0 : 0.0);
  weight = vec4(vec3(behind ? m.coefficients.w : 0.0), behind ? 1.0 : 0.0);
}
