// The walks of many rays (host/gl/gl_cube_walks.hpp), an invocation a ray, in two passes over
// the rays [first_ray, first_ray + ray_count): the count pass writes each ray's texel count and
// flags; the fill pass walks the rays again and writes each one's texels, in order, from its
// offset, never more than the count pass found, then its own count and flags. Flags: 1, the
// cap stopped the walk; 2, the walk ended. A walk that the GL's loop limit cut short has
// neither, and the host refuses it.

layout(local_size_x = 64) in;

// A ray: origin relative to the centre (xyz) and l_max (w); unit direction (xyz) and the
// radius of the ball around the centre it skips (w).
struct WalkRay {
  dvec4 w_lmax;
  dvec4 d_skip;
};

layout(std430, binding = CUBE_WALK_RAYS_BINDING) readonly buffer Rays { WalkRay rays[]; };
layout(std430, binding = CUBE_WALK_TEXELS_BINDING) writeonly buffer Texels { WalkTexelOut texels[]; };
// Per ray (first_ray + index): the count pass's (count, flags), then the fill pass's.
layout(std430, binding = CUBE_WALK_COUNTS_BINDING) buffer Counts { uvec4 counts[]; };
layout(std430, binding = CUBE_WALK_OFFSETS_BINDING) readonly buffer Offsets { uint offsets[]; };

uniform bool fill;  // false: the count pass
uniform uint first_ray;
uniform uint ray_count;
uniform uint walk_cap_texels;
uniform uint groups_per_row;

void main() {
  uint index = (gl_WorkGroupID.y * groups_per_row + gl_WorkGroupID.x) * 64u + gl_LocalInvocationID.x;
  if (index >= ray_count) return;
  uint ray = first_ray + index;
  WalkRay r = rays[ray];
  walk_begin(r.w_lmax.xyz, r.d_skip.xyz, face_resolution, r.w_lmax.w, r.d_skip.w, walk_cap_texels);
  uint room = fill ? counts[ray].x : 0u;
  ivec3 texel;
  dvec2 interval;
  bool after_gap;
  uint count = 0u;
  for (;;) {
    int step = walk_step_once(texel, interval, after_gap);
    if (step < 0) break;
    if (step == 0) continue;
    if (fill && count < room) texels[offsets[index] + count] = WalkTexelOut(ivec4(texel, after_gap ? 1 : 0), interval);
    ++count;
  }
  uint flags = (walk_aborted ? 1u : 0u) | (walk_done ? 2u : 0u);
  if (fill) {
    counts[ray].zw = uvec2(count, flags);
  } else {
    counts[ray].xy = uvec2(count, flags);
  }
}
