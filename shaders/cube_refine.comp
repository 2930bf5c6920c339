// The crossing test of each candidate the scan found (cube_scan.comp): crossing_candidate of
// cpu_core/search/search_candidates.cpp, the MESH REFINEMENT included (mesh_refine.glsl),
// operation for operation in double precision. An invocation a candidate.

layout(local_size_x = 64) in;

uniform uint groups_per_row;
uniform double tolerance_texels;  // SearchOptions::tolerance_texels
uniform bool refine_mesh;         // SearchOptions::refine is mesh

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

void answer(uint index, uint flags, double l, double outside, uint triangle, uint mesh_tested) {
  candidates[index].flags = flags;
  candidates[index].l = l;
  candidates[index].outside = outside;
  candidates[index].triangle = triangle;
  candidates[index].mesh_tested = mesh_tested;
}

void main() {
  uint index = (gl_WorkGroupID.y * groups_per_row + gl_WorkGroupID.x) * 64u + gl_LocalInvocationID.x;
  if (index >= candidate_count) return;
  CandidateOut c = candidates[index];
  ScanRay r = rays[c.ray];
  refine_w = r.w_lmax.xyz;
  refine_d = r.d_self.xyz;
  refine_self = r.d_self.w;
  refine_l_max = r.w_lmax.w;
  uint tri = c.id & ~BACK_FACE_BIT;
  double l0 = c.interval.x, l1 = c.interval.y;
  EdgePlanes p = edge_planes(tri);  // its plane is SearchContext::plane's
  double den = dot3(p.normal, refine_d);
  precise double to_plane = p.offset - dot3(p.normal, refine_w);
  precise double at = to_plane / den;
  double l = den == 0.0lf ? inf() : at;
  precise double slack = 1e-9lf * (abs(l) + length3(refine_w));
  precise double lo = l0 - slack;
  precise double hi = l1 + slack;
  bool in_texel = den != 0.0lf && l >= refine_self && l <= refine_l_max && l >= lo && l <= hi;
  bool tested = false, exact = false;
  double found_l = inf(), outside = 0.0lf;
  if (in_texel) {
    precise dvec3 x = refine_w + l * refine_d;
    dvec3 v[3] = dvec3[3](tri_vertex(tri, 0u), tri_vertex(tri, 1u), tri_vertex(tri, 2u));
    precise double o = distance_to_triangle(x, v, p.normal, p.offset) / texel_size_at(x);
    outside = o;
    found_l = l;
    exact = outside <= on_triangle_texels;
    tested = true;
  }
  uint mesh_tested = 0u;
  if (!exact && refine_mesh) {
    precise double mid = 0.5lf * (l0 + l1);
    double l_ref = isinf(l1) ? l0 : mid;
    precise dvec3 at_ref = refine_w + l_ref * refine_d;
    precise double radius = std_max(tolerance_texels, 1.0lf) * texel_size_at(at_ref);
    precise double l_lo = l0 - radius;
    precise double l_hi = l1 + radius;
    int result;
    uint crossed;
    double crossed_l;
    refine_on_mesh(tri, l_lo, l_hi, radius, result, crossed, crossed_l, mesh_tested);
    if (result == REFINED_HIT) {
      bool back = edge_planes(crossed).offset > 0.0lf;
      answer(index, 1u | 2u | 4u | (back ? 8u : 0u), crossed_l, 0.0lf, crossed, mesh_tested);
      return;
    }
    if (result == REFINED_MISS) {  // the mesh says the ray passes by: not a crossing
      answer(index, in_texel ? 1u : 0u, found_l, inf(), 0u, mesh_tested);
      return;
    }
  }
  if (!tested) {
    answer(index, 0u, inf(), 0.0lf, 0u, mesh_tested);
    return;
  }
  bool valid = outside <= tolerance_texels && (exact || l >= r.self_tolerance.x);
  bool back = (c.id & BACK_FACE_BIT) != 0u;
  answer(index, 1u | (exact ? 2u : 0u) | (valid ? 4u : 0u) | (back ? 8u : 0u), found_l, outside, tri, mesh_tested);
}
