// MESH REFINEMENT on the GPU (cpu_core/search/search_refine.cpp refine_on_mesh, with
// SearchContext::compute_bounding_sphere): the exact crossing of a ray with the mesh around a
// fragment's triangle, first straight across the edges, then breadth-first, operation for
// operation in double precision, over triangle_geometry.glsl's triangles. The ray is set in
// refine_w, refine_d, refine_self and refine_l_max.
//
// An invocation's loops are bounded well inside llvmpipe's 65535 passes: the straight walk's
// GPU_REFINE_MAX_STEPS steps, then a flood of at most GPU_REFINE_MAX_TRIANGLES triangles, each with
// its three neighbours, and the emptying of its set (TAKEN_SLOTS).

// Per triangle the triangle across each edge (MeshNeighbours; NO_NEIGHBOUR on a border).
layout(std430, binding = CUBE_REFINE_NEIGHBOURS_BINDING) readonly buffer Neighbours { uint tri_neighbours[]; };

const uint NO_NEIGHBOUR = 0xffffffffu;
const int NOT_TESTED = 3;
const int REFINED_HIT = 0, REFINED_MISS = 1, REFINED_UNKNOWN = 2;

dvec3 refine_w, refine_d;
double refine_self, refine_l_max;

// compute_bounding_sphere: (middle, radius); zero when degenerate.
dvec4 bounding_sphere(uint tri) {
  dvec3 v[3] = dvec3[3](tri_vertex(tri, 0u), tri_vertex(tri, 1u), tri_vertex(tri, 2u));
  precise dvec3 ab = v[1] - v[0];
  precise dvec3 ac = v[2] - v[0];
  double len = length3(cross3(ab, ac));
  if (!(len > 0.0lf && !isinf(len) && !isnan(len))) return dvec4(0.0lf);
  precise dvec3 sum = v[0] + v[1] + v[2];
  precise dvec3 middle = sum / 3.0lf;
  double farthest2 = 0.0lf;
  for (int k = 0; k < 3; ++k) {
    precise dvec3 off = v[k] - middle;
    farthest2 = std_max(farthest2, dot3(off, off));
  }
  return dvec4(middle, sqrt(farthest2));
}

// near_ray: does the sphere come within `radius` of the ray's stretch [l_lo, l_hi]?
bool near_ray(dvec4 b, double l_lo, double l_hi, double radius) {
  precise dvec3 to_centre = b.xyz - refine_w;
  double along = std_min(std_max(dot3(to_centre, refine_d), l_lo), l_hi);
  precise dvec3 foot = refine_w + along * refine_d;
  precise dvec3 off = b.xyz - foot;
  precise double reach = b.w + radius;
  precise double reach2 = reach * reach;
  return dot3(off, off) <= reach2;
}

// plane_crossing: (l, outside_edge) of the ray with triangle `tri`'s plane.
void plane_crossing(uint tri, double l_lo, double l_hi, out double l, out int outside_edge) {
  l = inf();
  outside_edge = -1;
  EdgePlanes e = edge_planes(tri);
  double den = dot3(e.normal, refine_d);
  if (den == 0.0lf) return;
  precise double to_plane = e.offset - dot3(e.normal, refine_w);
  precise double at = to_plane / den;
  l = at;
  if (!(l >= l_lo && l <= l_hi)) {
    outside_edge = NOT_TESTED;
    return;
  }
  precise dvec3 x = refine_w + l * refine_d;
  double worst = 0.0lf;
  int edge = -1;
  for (int k = 0; k < 3; ++k) {
    precise double outside = dot3(e.edge_normal[k], x) - e.edge_offset[k];
    if (outside < worst) {
      worst = outside;
      edge = k;
    }
  }
  if (edge < 0) return;
  double m = std_max(std_max(abs(x.x), abs(x.y)), abs(x.z));
  precise double far_bound = -2.000001lf * on_triangle_texels * m;
  precise double near_bound = -on_triangle_texels * texel_size_at(x);
  if (worst < far_bound || worst < near_bound) outside_edge = edge;
}

// The flood's set of triangles taken: open addressing over TAKEN_SLOTS (a flood takes at most
// GPU_REFINE_MAX_TRIANGLES), emptied at each flood's start.
const uint TAKEN_SLOTS = 512u;
const uint EMPTY_SLOT = 0xffffffffu;
uint taken[TAKEN_SLOTS];

// Whether `tri` was taken; takes it when `take`.
bool was_taken(uint tri, bool take) {
  uint h = (tri * 2654435761u) & (TAKEN_SLOTS - 1u);
  while (taken[h] != EMPTY_SLOT && taken[h] != tri) h = (h + 1u) & (TAKEN_SLOTS - 1u);
  if (taken[h] == tri) return true;
  if (take) taken[h] = tri;
  return false;
}

// refine_on_mesh: (result, triangle, l, tested).
void refine_on_mesh(uint start, double l_lo, double l_hi, double radius, out int result, out uint triangle,
                    out double l_hit, out uint tested) {
  result = REFINED_UNKNOWN;
  triangle = 0u;
  l_hit = inf();
  tested = 0u;
  bool start_near = near_ray(bounding_sphere(start), l_lo, l_hi, radius);
  uint walker = start;
  for (uint step = 0u; step < GPU_REFINE_MAX_STEPS; ++step) {
    double l;
    int edge;
    plane_crossing(walker, -inf(), inf(), l, edge);
    ++tested;
    if (isinf(l) && l > 0.0lf) break;
    if (edge < 0) {
      if (l >= refine_self && l <= refine_l_max && (start_near || (l >= l_lo && l <= l_hi))) {
        result = REFINED_HIT;
        triangle = walker;
        l_hit = l;
        return;
      }
      break;
    }
    uint nb = tri_neighbours[3u * walker + uint(edge)];
    if (nb == NO_NEIGHBOUR || (start_near && !near_ray(bounding_sphere(nb), l_lo, l_hi, radius))) break;
    walker = nb;
  }
  if (!start_near) return;
  for (uint s = 0u; s < TAKEN_SLOTS; ++s) taken[s] = EMPTY_SLOT;
  uint seen[GPU_REFINE_MAX_TRIANGLES];
  uint count = 0u, next = 0u;
  seen[count++] = start;
  was_taken(start, true);
  bool overflow = false;
  while (next < count) {
    uint tri = seen[next++];
    double l;
    int edge;
    plane_crossing(tri, refine_self, refine_l_max, l, edge);
    if (edge >= 0) l = inf();  // exact_crossing
    ++tested;
    if (l < l_hit) {
      l_hit = l;
      triangle = tri;
      if (tri == start) break;
    }
    for (int k = 0; k < 3; ++k) {
      uint nb = tri_neighbours[3u * tri + uint(k)];
      if (nb == NO_NEIGHBOUR || was_taken(nb, false)) continue;
      if (!near_ray(bounding_sphere(nb), l_lo, l_hi, radius)) continue;
      if (count == GPU_REFINE_MAX_TRIANGLES) {
        overflow = true;
        continue;
      }
      seen[count++] = nb;
      was_taken(nb, true);
    }
  }
  result = !isinf(l_hit) ? REFINED_HIT : (overflow ? REFINED_UNKNOWN : REFINED_MISS);
}
