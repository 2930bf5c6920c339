// The walks of many rays (host/gl/gl_cube_walks.hpp), an invocation a ray, in two passes: the
// count pass writes each ray's texel count and whether the cap stopped it; the fill pass walks
// the rays [first_ray, first_ray + ray_count) again and writes each one's texels, in order,
// from its offset.

layout(local_size_x = 64) in;

// A ray: origin relative to the centre (xyz) and l_max (w); unit direction (xyz) and the
// radius of the ball around the centre it skips (w).
struct WalkRay {
  dvec4 w_lmax;
  dvec4 d_skip;
};
// A texel of a walk: (face, i, j, after_gap) and [l0, l1].
struct WalkTexelOut {
  ivec4 texel;
  dvec2 interval;
};

layout(std430, binding = CUBE_WALK_RAYS_BINDING) readonly buffer Rays { WalkRay rays[]; };
layout(std430, binding = CUBE_WALK_TEXELS_BINDING) writeonly buffer Texels { WalkTexelOut texels[]; };
layout(std430, binding = CUBE_WALK_COUNTS_BINDING) writeonly buffer Counts { uvec2 counts[]; };
layout(std430, binding = CUBE_WALK_OFFSETS_BINDING) readonly buffer Offsets { uint offsets[]; };

uniform bool fill;  // false: the count pass
uniform uint first_ray;
uniform uint ray_count;
uniform int face_resolution;
uniform uint walk_cap_texels;
uniform uint groups_per_row;

void main() {
  uint index = (gl_WorkGroupID.y * groups_per_row + gl_WorkGroupID.x) * 64u + gl_LocalInvocationID.x;
  if (index >= ray_count) return;
  WalkRay r = rays[first_ray + index];
  walk_begin(r.w_lmax.xyz, r.d_skip.xyz, face_resolution, r.w_lmax.w, r.d_skip.w, walk_cap_texels);
  ivec3 texel;
  dvec2 interval;
  bool after_gap;
  uint count = 0u;
  while (walk_next(texel, interval, after_gap)) {
    if (fill) texels[offsets[index] + count] = WalkTexelOut(ivec4(texel, after_gap ? 1 : 0), interval);
    ++count;
  }
  if (!fill) counts[index] = uvec2(count, walk_aborted ? 1u : 0u);
}
