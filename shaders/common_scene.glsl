// Scene data shared by the GL passes: materials and point lights in SSBOs, indexed by the
// per-vertex material id. Layout mirrors host/gl_passes.cpp (std430).
struct MaterialGpu {
  vec4 color_ambient;  // rgb = Od, a = ka
  vec4 coefficients;   // x = kd, y = ks, z = shininess n, w unused
};
struct LightGpu {
  vec4 position;  // xyz relative to the pass centre (the eye)
  vec4 color;     // rgb intensity
};
layout(std430, binding = 0) readonly buffer Materials { MaterialGpu materials[]; };
layout(std430, binding = 1) readonly buffer Lights { LightGpu lights[]; };
uniform int u_light_count;
uniform vec3 u_ambient;
