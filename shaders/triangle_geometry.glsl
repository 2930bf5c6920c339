// A triangle's geometry on the GPU as SearchContext holds it (vertices relative to the cube's
// centre, its plane and edge planes, texel_size_at) and crossing_candidate's first test
// (cpu_core/search/search_candidates.cpp), operation for operation in double precision: what
// the crossing test's pass (cube_refine.comp, mesh_refine.glsl) and the scan that walks
// (cube_scan_walks.comp) share.

// Per triangle its three vertices, as the scene's soup holds them (float x, y, z).
layout(std430, binding = CUBE_SCAN_POSITIONS_BINDING) readonly buffer Positions { float tri_positions[]; };

uniform dvec3 centre;  // the cube's centre, world space
uniform double on_triangle_texels;  // ON_TRIANGLE_TEXELS
uniform double tolerance_texels;    // SearchOptions::tolerance_texels

// SearchContext::vertex.
dvec3 tri_vertex(uint tri, uint k) {
  uint at = 9u * tri + 3u * k;
  precise dvec3 v = dvec3(double(tri_positions[at]), double(tri_positions[at + 1u]), double(tri_positions[at + 2u])) -
                    centre;
  return v;
}

// texel_size_at (cube_walk.hpp): 2 |x|_inf / n.
double texel_size_at(dvec3 x) {
  double m = std_max(std_max(abs(x.x), abs(x.y)), abs(x.z));
  precise double size = 2.0lf * m / double(face_resolution);
  return size;
}

// SearchContext::EdgePlanes, computed as compute_edge_planes does (zero when degenerate).
struct EdgePlanes {
  dvec3 normal;
  double offset;
  dvec3 edge_normal[3];
  double edge_offset[3];
};

EdgePlanes edge_planes(uint tri) {
  EdgePlanes e;
  e.normal = dvec3(0.0lf);
  e.offset = 0.0lf;
  for (int k = 0; k < 3; ++k) {
    e.edge_normal[k] = dvec3(0.0lf);
    e.edge_offset[k] = 0.0lf;
  }
  dvec3 v[3] = dvec3[3](tri_vertex(tri, 0u), tri_vertex(tri, 1u), tri_vertex(tri, 2u));
  precise dvec3 ab = v[1] - v[0];
  precise dvec3 ac = v[2] - v[0];
  dvec3 n = cross3(ab, ac);
  double len = length3(n);
  if (!(len > 0.0lf && !isinf(len) && !isnan(len))) return e;
  precise dvec3 unit = n / len;
  e.normal = unit;
  e.offset = dot3(unit, v[0]);
  for (int k = 0; k < 3; ++k) {
    precise dvec3 edge = v[(k + 1) % 3] - v[k];
    dvec3 m = cross3(unit, edge);
    double ml = length3(m);
    if (ml > 0.0lf) {
      precise dvec3 mn = m / ml;
      e.edge_normal[k] = mn;
    }
    e.edge_offset[k] = dot3(e.edge_normal[k], v[k]);
  }
  return e;
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

// crossing_candidate's first test of ray W + l D (self offset `self`, end l_max) against
// triangle `tri` with plane (normal, offset), from a texel walked over [l0, l1]: does the ray
// meet the plane inside the texel (to rounding), and if so at which l and how far from the
// triangle, in texels (outside)?
bool texel_crossing(uint tri, dvec3 normal, double offset, dvec3 w, dvec3 d, double self, double l_max, double l0,
                    double l1, out double l, out double outside) {
  double den = dot3(normal, d);
  precise double to_plane = offset - dot3(normal, w);
  precise double at = to_plane / den;
  l = den == 0.0lf ? inf() : at;
  outside = 0.0lf;
  precise double slack = 1e-9lf * (abs(l) + length3(w));
  precise double lo = l0 - slack;
  precise double hi = l1 + slack;
  if (!(den != 0.0lf && l >= self && l <= l_max && l >= lo && l <= hi)) return false;
  precise dvec3 x = w + l * d;
  dvec3 v[3] = dvec3[3](tri_vertex(tri, 0u), tri_vertex(tri, 1u), tri_vertex(tri, 2u));
  precise double o = distance_to_triangle(x, v, normal, offset) / texel_size_at(x);
  outside = o;
  return true;
}
