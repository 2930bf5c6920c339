// The candidates of many searches' rays (host/gl/gl_cube_scan.hpp), an invocation a ray: its
// walk (cube_walk.glsl) and, as the walk reaches each texel, that texel's list put to
// scan_lists.glsl's tests, each fragment that passes appended in the walk's order; then
// cube_refine.comp runs each one's crossing test. A ray with a STOP HINT
// (cpu_core/search/search.hpp ScanStop, in object_row.z) tries each candidate's crossing on
// its own triangle here (triangle_geometry.glsl texel_crossing) and ends where the hint says.
//
// Mesa's llvmpipe ends an invocation's loops, silently, after 65535 iterations in all: the
// walk's steps, every fragment read and each crossing tried are counted against loop_budget,
// and a ray that would pass it ends, flagged, before the texel that would; the host scans it
// with the passes that read walks (cube_walks.comp, cube_scan.comp).

layout(local_size_x = 64) in;

// Per ray: the texels walked, the flags (1 the cap stopped the walk, 2 the walk ended, 4 the
// stop hint ended it, 8 the loop budget did, 16 the loops all ran) and the end of the last
// texel walked.
struct RayScanOut {
  uint texels, flags, pad0, pad1;
  double last_l1, pad;
};
layout(std430, binding = CUBE_WALK_COUNTS_BINDING) writeonly buffer Outs { RayScanOut outs[]; };
// BLOCK BOUNDS (SearchContext): per face and block of GPU_BOUNDS_BLOCK texels a side, the
// smallest zmin and the largest zmax of its fragments ((+inf, -inf): none), blocks_per_row
// blocks a row. A texel whose block holds nothing in the ray's range is passed unread: no
// fragment of it could pass, so the candidates are the same.
layout(std430, binding = CUBE_SCAN_BLOCKS_BINDING) readonly buffer Blocks { vec2 blocks[]; };

uniform uint ray_count;
uniform uint walk_cap_texels;
uniform double skip_radius;  // the radius around the centre every walk skips
uniform uint opaque_at;      // from here in objects, bit t: triangle t lets no light through
uniform uint loop_budget;
uniform uint one;  // 1: the bound of the last loop, which the compiler cannot drop
uniform uint groups_per_row;
uniform int blocks_per_row;

const uint STOP_NONE = 0u, STOP_CROSSING = 1u, STOP_SHADOW = 2u;
// What a walk's step, a fragment's reading and a crossing's trial may cost against the budget:
// their loops, and the loops the compiler makes of a function's early returns.
const uint STEP_COST = 4u, FRAGMENT_COST = 4u, CROSSING_COST = 32u;

bool lets_no_light(uint triangle) { return ((objects[opaque_at + triangle / 32u] >> (triangle % 32u)) & 1u) != 0u; }

void main() {
  uint ray = (gl_WorkGroupID.y * groups_per_row + gl_WorkGroupID.x) * 64u + gl_LocalInvocationID.x;
  if (ray >= ray_count) return;
  ScanRay r = rays[ray];
  dvec3 w = r.w_lmax.xyz, d = r.d_self.xyz;
  double l_max = r.w_lmax.w;
  uint stop = r.object_row.z;
  walk_begin(w, d, face_resolution, l_max, skip_radius, walk_cap_texels);
  // STOP HINTS: the first texel with a crossing on its own triangle, the nearest such
  // crossing, and whether one lets no light through.
  int first = -1;
  double nearest = inf();
  bool blocked = false;
  uint texel = 0u, spent = 0u, flags = 0u;
  double before_l1 = -inf();
  ivec3 t;
  dvec2 interval;
  bool after_gap;
  for (;;) {
    int step = walk_step_once(t, interval, after_gap);
    if (step < 0) break;
    if (step == 0) continue;
    dvec2 range2 = squared_range(w, d, interval);
    vec2 z = blocks[(t.x * blocks_per_row + t.z / GPU_BOUNDS_BLOCK) * blocks_per_row + t.y / GPU_BOUNDS_BLOCK];
    bool unread = z.x > z.y || double(z.y) * double(z.y) < range2.x || double(z.x) * double(z.x) > range2.y;
    uvec2 list = unread ? uvec2(0u) : texel_list(t);
    uint worst = (list.y - list.x) * (FRAGMENT_COST + (stop != STOP_NONE ? CROSSING_COST : 0u));
    if (walk_iterations * STEP_COST + spent + worst > loop_budget) {
      flags |= 8u;
      break;
    }
    for (uint k = list.x; k < list.y; ++k) {
      spent += FRAGMENT_COST;
      Fragment f = fragments[k];
      int verdict = fragment_passes(r, f, range2);
      if (verdict == FRAGMENT_PAST_RANGE) break;
      if (verdict == FRAGMENT_FAILS) continue;
      append_candidate(texel, k, ray, f.id, t, interval, before_l1);
      if (stop == STOP_NONE) continue;
      spent += CROSSING_COST;
      uint tri = f.id & ~BACK_FACE_BIT;
      double l, outside;
      dvec4 p = planes[tri];
      if (!texel_crossing(tri, p.xyz, p.w, w, d, r.d_self.w, l_max, interval.x, interval.y, l, outside) ||
          !(outside <= on_triangle_texels && outside <= tolerance_texels)) {
        continue;
      }
      if (stop == STOP_CROSSING) {
        if (first < 0) first = int(texel);
        nearest = std_min(nearest, l);
      } else if (l < l_max && lets_no_light(tri)) {
        blocked = true;
      }
    }
    before_l1 = interval.y;
    ++texel;
    bool past = stop == STOP_CROSSING && first >= 0 && texel - 1u >= uint(first) + uint(GPU_CROSSING_WINDOW_TEXELS) &&
                interval.y > nearest;
    if (past || (stop == STOP_SHADOW && blocked)) {
      flags |= 4u;
      break;
    }
  }
  flags |= (walk_aborted ? 1u : 0u) | (walk_done ? 2u : 0u);
  // A GL past its loop limit runs no more passes of any loop: this one's flag (16) says the
  // limit was not reached.
  for (uint k = 0u; k < one; ++k) flags |= 16u;
  outs[ray] = RayScanOut(texel, flags, 0u, 0u, before_l1, 0.0lf);
}
