// The candidates of many searches' rays (host/gl/gl_cube_scan.hpp): the z-interval test of
// every fragment in every texel the rays' walks crossed (cube_walks.comp's fill pass, left on
// the GPU), with the object restriction and the own-surface test (cpu_core/search/
// search_scan.hpp scan), operation for operation in double precision. An invocation a texel
// of the batch; each fragment that passes is appended, in any order, which the host sorts into
// the walk's; cube_refine.comp then runs each one's crossing test.

layout(local_size_x = 64) in;

// A fragment (raster/abuffer.hpp Fragment, 20 bytes).
struct Fragment {
  float zmin, zmax;
  uint mask, id, normal;
};

layout(std430, binding = CUBE_WALK_TEXELS_BINDING) readonly buffer Texels { WalkTexelOut texels[]; };
// The batch's ray k's first texel.
layout(std430, binding = CUBE_WALK_OFFSETS_BINDING) readonly buffer Offsets { uint offsets[]; };
// Face f's texel (i, j)'s list: fragments [lists[q], lists[q + 1]), q = (f n + j) n + i.
layout(std430, binding = CUBE_SCAN_LISTS_BINDING) readonly buffer Lists { uint lists[]; };
layout(std430, binding = CUBE_SCAN_FRAGMENTS_BINDING) readonly buffer Fragments { Fragment fragments[]; };
// Per triangle its plane: the unit normal (xyz) and offset (w) of SearchContext::plane.
layout(std430, binding = CUBE_SCAN_PLANES_BINDING) readonly buffer Planes { dvec4 planes[]; };
// Per triangle its object; from rows_at, row r's bit o: object o's bounds meet the object
// of the rays with row r (Media::bounds_meet).
layout(std430, binding = CUBE_SCAN_OBJECTS_BINDING) readonly buffer Objects { uint objects[]; };

uniform uint first_ray;  // the batch's first ray in the rays bound
uniform uint ray_count;
uniform uint texel_count;
uniform int face_resolution;
uniform uint rows_at;
uniform uint row_words;
uniform uint candidate_room;
uniform uint groups_per_row;

const uint NO_ROW = 0xffffffffu;

// |W + l D|^2 (SquaredDistanceRange::length2_at).
double length2_at(dvec3 w, dvec3 d, double l) {
  precise dvec3 x = w + l * d;
  return dot3(x, x);
}

// May a surface of `object` answer the ray (allowed, search_internal.hpp)?
bool allowed(ScanRay r, uint object) {
  if (r.object_row.y == NO_ROW || object == r.object_row.x) return true;
  return ((objects[rows_at + r.object_row.y * row_words + object / 32u] >> (object % 32u)) & 1u) != 0u;
}

// W's own surface (own_surface, search_scan.hpp).
bool own_surface(dvec4 plane, dvec3 w, dvec3 d, double self) {
  precise double delta = dot3(plane.xyz, w) - plane.w;
  if (!(abs(delta) <= self)) return false;
  double den = dot3(plane.xyz, d);
  precise double along = -delta / den;
  return !(den != 0.0lf && along > self);
}

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
  dvec3 w = r.w_lmax.xyz, d = r.d_self.xyz;
  double l0 = t.interval.x, l1 = t.interval.y;
  // SquaredDistanceRange (search_scan.hpp): the squares of the ray's distance range over
  // [l0, l1].
  precise double closest = -dot3(w, d);
  double lc = std_min(std_max(closest, l0), l1);
  double at_l0 = length2_at(w, d, l0);
  double at_l1 = isinf(l1) ? inf() : length2_at(w, d, l1);
  double range_lo = lc == l0 ? at_l0 : (lc == l1 ? at_l1 : length2_at(w, d, lc));
  double range_hi = isinf(l1) ? inf() : std_max(at_l0, at_l1);
  uint list = (uint(t.texel.x) * uint(face_resolution) + uint(t.texel.z)) * uint(face_resolution) + uint(t.texel.y);
  for (uint k = lists[list]; k < lists[list + 1u]; ++k) {
    Fragment f = fragments[k];
    // ORDER: the list runs by zmin, so every fragment past the range's far end fails too.
    if (double(f.zmin) * double(f.zmin) > range_hi) break;
    if (double(f.zmax) * double(f.zmax) < range_lo) continue;
    uint triangle = f.id & ~BACK_FACE_BIT;
    if (!allowed(r, objects[triangle])) continue;
    if (own_surface(planes[triangle], w, d, r.d_self.w)) continue;
    uint slot = atomicAdd(candidate_count, 1u);
    if (slot < candidate_room) {
      double before_l1 = index > offsets[lo] ? texels[index - 1u].interval.y : -inf();
      uint ij = uint(t.texel.y) | (uint(t.texel.z) << 16);
      candidates[slot] = CandidateOut(index, k, lo, f.id, inf(), 0.0lf, t.interval, 0u, 0u, 0u, ij, before_l1, 0.0lf);
    }
  }
}
