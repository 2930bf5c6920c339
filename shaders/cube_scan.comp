// The candidates of many searches' rays (host/gl/gl_cube_scan.hpp): the z-interval test of
// every fragment in every texel the rays' walks crossed (cube_walks.comp's fill pass, left on
// the GPU), with the object restriction and the own-surface test (cpu_core/search/
// search_scan.hpp scan), then each candidate's crossing test (search_candidates.cpp
// crossing_candidate without the mesh refinement), operation for operation in double
// precision. An invocation a texel of the batch; each fragment that passes is appended with
// its crossing, in any order, which the host sorts into the walk's.

layout(local_size_x = 64) in;

// A search's ray (SearchRay): origin relative to the centre (xyz) and l_max (w); unit
// direction (xyz) and self offset (w); the object a refraction exit is restricted to and its
// row of objects allowed (NO_ROW: not restricted); the self tolerance (x).
struct ScanRay {
  dvec4 w_lmax;
  dvec4 d_self;
  uvec4 object_row;
  dvec2 self_tolerance;
};
// A candidate found: the batch's texel, the fragment, the crossing's verdicts (bit 0 tested,
// 1 exact, 2 valid), its l and its distance from the triangle in texels.
struct CandidateOut {
  uint texel, fragment, flags, pad;
  double l, outside;
};
// A fragment (raster/abuffer.hpp Fragment, 20 bytes).
struct Fragment {
  float zmin, zmax;
  uint mask, id, normal;
};

layout(std430, binding = CUBE_SCAN_RAYS_BINDING) readonly buffer Rays { ScanRay rays[]; };
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
// Per triangle its three vertices, as the scene's soup holds them (float x, y, z).
layout(std430, binding = CUBE_SCAN_POSITIONS_BINDING) readonly buffer Positions { float positions[]; };
// The count of candidates found, then up to candidate_room of them.
layout(std430, binding = CUBE_SCAN_CANDIDATES_BINDING) buffer Candidates {
  uint candidate_count;
  uint candidate_pad;
  CandidateOut candidates[];
};

uniform uint first_ray;  // the batch's first ray in the rays bound
uniform uint ray_count;
uniform uint texel_count;
uniform int face_resolution;
uniform uint rows_at;
uniform uint row_words;
uniform uint candidate_room;
uniform dvec3 centre;             // the cube's centre, world space
uniform double tolerance_texels;  // SearchOptions::tolerance_texels
// search_internal.hpp ON_TRIANGLE_TEXELS.
uniform double on_triangle_texels;
uniform uint groups_per_row;

const uint BACK_FACE_BIT = 0x80000000u;
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

// SearchContext::vertex: vertex k of triangle `tri` relative to the centre.
dvec3 vertex(uint tri, uint k) {
  uint at = 9u * tri + 3u * k;
  precise dvec3 v = dvec3(double(positions[at]), double(positions[at + 1u]), double(positions[at + 2u])) - centre;
  return v;
}

// texel_size_at (cube_walk.hpp): 2 |x|_inf / n.
double texel_size_at(dvec3 x) {
  double m = std_max(std_max(abs(x.x), abs(x.y)), abs(x.z));
  precise double size = 2.0lf * m / double(face_resolution);
  return size;
}

// distance_to_triangle (search_candidates.cpp): p's distance from triangle v0 v1 v2 whose
// plane has unit normal n and offset o.
double distance_to_triangle(dvec3 p, dvec3 v[3], dvec3 n, double o) {
  precise double off_plane = dot3(n, p) - o;
  precise dvec3 q = p - off_plane * n;
  bool inside = true;
  for (int k = 0; k < 3; ++k) {
    precise dvec3 edge = v[(k + 1) % 3] - v[k];
    precise dvec3 to_q = q - v[k];
    inside = inside && dot3(cross3(edge, to_q), n) >= 0.0lf;
  }
  if (inside) return abs(off_plane);
  double in_plane = inf();
  for (int k = 0; k < 3; ++k) {
    precise dvec3 e = v[(k + 1) % 3] - v[k];
    double len2 = dot3(e, e);
    precise dvec3 to_q = q - v[k];
    precise double along = dot3(to_q, e) / len2;
    double u = len2 > 0.0lf ? std_min(std_max(along, 0.0lf), 1.0lf) : 0.0lf;
    precise dvec3 foot = v[k] + u * e;
    precise dvec3 away = q - foot;
    in_plane = std_min(in_plane, length3(away));
  }
  precise double squares = in_plane * in_plane + off_plane * off_plane;
  return sqrt(squares);
}

// crossing_candidate's test without the mesh refinement: the flags, l and outside of a
// candidate whose fragment's triangle has plane `plane`, in the texel [l0, l1].
CandidateOut crossing(ScanRay r, dvec4 plane, uint triangle, double l0, double l1) {
  CandidateOut c = CandidateOut(0u, 0u, 0u, 0u, inf(), 0.0lf);
  dvec3 w = r.w_lmax.xyz, d = r.d_self.xyz;
  double self = r.d_self.w;
  double den = dot3(plane.xyz, d);
  precise double to_plane = plane.w - dot3(plane.xyz, w);
  precise double l_at = to_plane / den;
  double l = den == 0.0lf ? inf() : l_at;
  precise double slack = 1e-9lf * (abs(l) + length3(w));
  precise double lo = l0 - slack;
  precise double hi = l1 + slack;
  bool in_texel = den != 0.0lf && l >= self && l <= r.w_lmax.w && l >= lo && l <= hi;
  if (!in_texel) return c;
  precise dvec3 x = w + l * d;
  dvec3 v[3] = dvec3[3](vertex(triangle, 0u), vertex(triangle, 1u), vertex(triangle, 2u));
  precise double outside = distance_to_triangle(x, v, plane.xyz, plane.w) / texel_size_at(x);
  bool exact = outside <= on_triangle_texels;
  bool valid = outside <= tolerance_texels && (exact || l >= r.self_tolerance.x);
  c.flags = 1u | (exact ? 2u : 0u) | (valid ? 4u : 0u);
  c.l = l;
  c.outside = outside;
  return c;
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
      CandidateOut c = crossing(r, planes[triangle], triangle, l0, l1);
      c.texel = index;
      c.fragment = k;
      candidates[slot] = c;
    }
  }
}
