// One light's shadow count (shadow_volume.frag) into its bit of the mask the camera pass
// reads (common_shading.glsl light_visibility), OR-ed in (glLogicOp): 128 lights at most.
uniform sampler2D u_count;
uniform int u_bit;
layout(location = 0) out uvec4 o_mask;

void main() {
  uvec4 m = uvec4(0u);
  if (texelFetch(u_count, ivec2(gl_FragCoord.xy), 0).r != 0.0) m[u_bit / 32] = 1u << uint(u_bit % 32);
  o_mask = m;
}
