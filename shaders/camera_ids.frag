// The visibility pass of the exact camera pass's per-pixel shading (gl_shading_groups.cpp): at
// the view's visible surface (depth EQUAL after its depth pass and its volume counts), the
// triangle's index in the scene's vertex buffer + 1 (its primitive in the one draw of the
// whole buffer; 0 is left where the view shows nothing) and the set of volume lights whose
// count is not 0 there (bit b: count b of common_shading.glsl; at most 32, or the pass
// shades per sample). No discard: the tests come first.
layout(early_fragment_tests) in;
uniform sampler2DArray u_volume_counts;
uniform int u_volume_layers;  // layers of u_volume_counts that hold counts (0: none)

layout(location = 0) out uvec2 o_key;

void main() {
  uint blocked = 0u;
  for (int b = 0; b < u_volume_layers; ++b) {
    blocked |= uint(texelFetch(u_volume_counts, ivec3(ivec2(gl_FragCoord.xy), b), 0).r != 0.0) << uint(b);
  }
  o_key = uvec2(uint(gl_PrimitiveID) + 1u, blocked);
}
