// The crossing test of each candidate the scan found (cube_scan.comp): crossing_candidate of
// cpu_core/search/search_candidates.cpp, the MESH REFINEMENT included (mesh_refine.glsl),
// operation for operation in double precision. An invocation a candidate.

layout(local_size_x = 64) in;

uniform uint groups_per_row;
uniform bool refine_mesh;  // SearchOptions::refine is mesh

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
  double l, outside;
  bool tested = texel_crossing(tri, p.normal, p.offset, refine_w, refine_d, refine_self, refine_l_max, l0, l1, l, outside);
  bool exact = tested && outside <= on_triangle_texels;
  double found_l = tested ? l : inf();
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
      answer(index, tested ? 1u : 0u, found_l, inf(), 0u, mesh_tested);
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
