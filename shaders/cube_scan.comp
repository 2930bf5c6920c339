// The candidates of many searches' rays (host/gl/gl_cube_scan.hpp) from their walks left on
// the GPU (cube_walks.comp's fill pass): every fragment in every texel walked put to
// scan_lists.glsl's tests. An invocation a texel of the batch; each fragment that passes is
// appended, in any order, which the host sorts into the walk's; cube_refine.comp then runs
// each one's crossing test. The rays a scan that walks (cube_scan_walks.comp) could not finish
// come here.

layout(local_size_x = 64) in;

layout(std430, binding = CUBE_WALK_TEXELS_BINDING) readonly buffer Texels { WalkTexelOut texels[]; };
// The batch's ray k's first texel.
layout(std430, binding = CUBE_WALK_OFFSETS_BINDING) readonly buffer Offsets { uint offsets[]; };

uniform uint first_ray;  // the batch's first ray in the rays bound
uniform uint ray_count;
uniform uint texel_count;
uniform uint groups_per_row;

void main() {
  uint index = (gl_WorkGroupID.y * groups_per_row + gl_WorkGroupID.x) * 64u + gl_LocalInvocationID.x;
  if (index >= texel_count) return;
  // The ray of the texel: the last whose first texel is at or before it.
  uint lo = 0u, hi = ray_count;
  while (hi - lo > 1u) {
    uint mid = (lo + hi) / 2u;
    if (offsets[mid] <= index) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  ScanRay r = rays[first_ray + lo];
  WalkTexelOut t = texels[index];
  dvec2 range2 = squared_range(r.w_lmax.xyz, r.d_self.xyz, t.interval);
  uvec2 list = texel_list(t.texel.xyz);
  for (uint k = list.x; k < list.y; ++k) {
    Fragment f = fragments[k];
    int verdict = fragment_passes(r, f, range2);
    if (verdict == FRAGMENT_PAST_RANGE) break;
    if (verdict == FRAGMENT_FAILS) continue;
    double before_l1 = index > offsets[lo] ? texels[index - 1u].interval.y : -inf();
    append_candidate(index, k, lo, f.id, t.texel.xyz, t.interval, before_l1);
  }
}
