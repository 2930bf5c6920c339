// The cube A-buffer's lists as the candidate scans read them (cube_scan.comp, a texel an
// invocation; cube_scan_walks.comp, a ray an invocation), and the tests each fragment of a
// texel's list must pass before it is a candidate: the z-interval test, the object
// restriction and the own-surface test of cpu_core/search/search_scan.hpp scan, operation for
// operation in double precision.

// Face f's texel (i, j)'s list: fragments [lists[q], lists[q + 1]), q = (f n + j) n + i.
layout(std430, binding = CUBE_SCAN_LISTS_BINDING) readonly buffer Lists { uint lists[]; };
layout(std430, binding = CUBE_SCAN_FRAGMENTS_BINDING) readonly buffer Fragments { Fragment fragments[]; };
// Per triangle its plane: the unit normal (xyz) and offset (w) of SearchContext::plane.
layout(std430, binding = CUBE_SCAN_PLANES_BINDING) readonly buffer Planes { dvec4 planes[]; };
// Per triangle its object; from rows_at, row r's bit o: object o's bounds meet the object
// of the rays with row r (Media::bounds_meet).
layout(std430, binding = CUBE_SCAN_OBJECTS_BINDING) readonly buffer Objects { uint objects[]; };

uniform uint rows_at;
uniform uint row_words;
uniform uint candidate_room;

const uint NO_ROW = 0xffffffffu;
// What fragment_passes says of a fragment.
const int FRAGMENT_PASSES = 0, FRAGMENT_FAILS = 1, FRAGMENT_PAST_RANGE = 2;

// |W + l D|^2 (SquaredDistanceRange::length2_at).
double length2_at(dvec3 w, dvec3 d, double l) {
  precise dvec3 x = w + l * d;
  return dot3(x, x);
}

// SquaredDistanceRange (search_scan.hpp): the squares of the ray's distance from the centre
// over [l0, l1].
dvec2 squared_range(dvec3 w, dvec3 d, dvec2 interval) {
  double l0 = interval.x, l1 = interval.y;
  precise double closest = -dot3(w, d);
  double lc = std_min(std_max(closest, l0), l1);
  double at_l0 = length2_at(w, d, l0);
  double at_l1 = isinf(l1) ? inf() : length2_at(w, d, l1);
  double range_lo = lc == l0 ? at_l0 : (lc == l1 ? at_l1 : length2_at(w, d, lc));
  return dvec2(range_lo, isinf(l1) ? inf() : std_max(at_l0, at_l1));
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

// Face texel t = (face, i, j)'s list: its first fragment and its end.
uvec2 texel_list(ivec3 t) {
  uint q = (uint(t.x) * uint(face_resolution) + uint(t.z)) * uint(face_resolution) + uint(t.y);
  return uvec2(lists[q], lists[q + 1u]);
}

// Does fragment f of a texel whose squared distances from the centre span range2 pass ray r's
// tests? FRAGMENT_PAST_RANGE: no, and (ORDER: the list runs by zmin) nor does any after it.
int fragment_passes(ScanRay r, Fragment f, dvec2 range2) {
  if (double(f.zmin) * double(f.zmin) > range2.y) return FRAGMENT_PAST_RANGE;
  if (double(f.zmax) * double(f.zmax) < range2.x) return FRAGMENT_FAILS;
  uint triangle = f.id & ~BACK_FACE_BIT;
  if (!allowed(r, objects[triangle])) return FRAGMENT_FAILS;
  if (own_surface(planes[triangle], r.w_lmax.xyz, r.d_self.xyz, r.d_self.w)) return FRAGMENT_FAILS;
  return FRAGMENT_PASSES;
}

// Appends fragment k of texel (face, i, j) = t, the ray's texel number `texel` (its walk's,
// or its batch's), as a candidate of batch ray `ray`, when there is room; the slot it took.
uint append_candidate(uint texel, uint k, uint ray, uint id, ivec3 t, dvec2 interval, double before_l1) {
  uint slot = atomicAdd(candidate_count, 1u);
  if (slot < candidate_room) {
    uint ij = uint(t.y) | (uint(t.z) << 16);
    candidates[slot] = CandidateOut(texel, k, ray, id, inf(), 0.0lf, interval, 0u, 0u, 0u, ij, before_l1, 0.0lf);
  }
  return slot;
}
