// Fill pass of the GPU A-buffer (host/gl/gl_abuffer.cpp): the count pass's walk again (an
// invocation a tile),
// each covered pixel's fragment written at its list's next slot with its geometry
// (fragment_geometry, raster.cpp): zmin and zmax over the triangle's part in the pixel,
// rounded outward to float, and the interpolated normal at the covered samples' centroid.
// The slots of one list fill in any order; the finish pass sorts them.
layout(local_size_x = 64) in;
layout(std430, binding = ABUFFER_OFFSETS_BINDING) readonly buffer Offsets { uint offsets[]; };
layout(std430, binding = ABUFFER_CURSORS_BINDING) buffer Cursors { uint cursors[]; };
layout(std430, binding = ABUFFER_FRAGMENTS_BINDING) writeonly buffer Fragments { Fragment fragments[]; };
uniform uint item_count;

// Whether the whole pixel square is inside every edge function, with the trivial margin.
bool pixel_inside(Setup s, int x, int y) {
  for (int k = 0; k < s.edge_count; ++k) {
    dvec3 e = s.edge[k].xyz;
    precise double tol = trivial_rel * (abs(e.x) * (double(x) + 2.0lf) + abs(e.y) * (double(y) + 2.0lf) + abs(e.z));
    precise double v = e.x * (e.x > 0.0lf ? double(x) : double(x) + 1.0lf) +
                       e.y * (e.y > 0.0lf ? double(y) : double(y) + 1.0lf) + e.z;
    if (!(v > tol)) return false;
  }
  return true;
}

// Sutherland-Hodgman against a plane through the centre: keeps dot(plane, v) >= 0.
int clip_polygon(dvec3 src[8], int count, dvec3 plane, out dvec3 dst[8]) {
  int m = 0;
  for (int i = 0; i < count; ++i) {
    dvec3 a = src[i], b = src[(i + 1) % count];
    precise double fa = dot3(plane, a), fb = dot3(plane, b);
    if (fa >= 0.0lf) dst[m++] = a;
    if ((fa >= 0.0lf) != (fb >= 0.0lf)) {
      precise dvec3 p = a + (fa / (fa - fb)) * (b - a);
      dst[m++] = p;
    }
  }
  return m;
}

// The triangle (in front of the near plane) clipped to the frustum of pixel (x, y).
int pixel_polygon(View v, Setup s, int x, int y, out dvec3 poly[8]) {
  if (pixel_inside(s, x, y)) {
    const double cx[4] = double[4](0.0lf, 1.0lf, 1.0lf, 0.0lf), cy[4] = double[4](0.0lf, 0.0lf, 1.0lf, 1.0lf);
    for (int i = 0; i < 4; ++i) {
      dvec3 d = view_direction(v, double(x) + cx[i], double(y) + cy[i]);
      precise dvec3 p = (s.plane.w / dot3(s.plane.xyz, d)) * d;
      poly[i] = p;
    }
    return 4;
  }
  dvec3 a[8], b[8];
  for (int i = 0; i < s.polygon_size; ++i) a[i] = s.polygon[i].xyz;
  precise dvec3 p0 = v.row_x.xyz - double(x) * v.row_w.xyz;
  precise dvec3 p1 = double(x + 1) * v.row_w.xyz - v.row_x.xyz;
  precise dvec3 p2 = v.row_y.xyz - double(y) * v.row_w.xyz;
  precise dvec3 p3 = double(y + 1) * v.row_w.xyz - v.row_y.xyz;
  int m = clip_polygon(a, s.polygon_size, p0, b);
  m = clip_polygon(b, m, p1, a);
  m = clip_polygon(a, m, p2, b);
  return clip_polygon(b, m, p3, poly);
}

// Squared distance from the centre (the origin) to segment ab.
double segment_distance2(dvec3 a, dvec3 b) {
  precise dvec3 ab = b - a;
  precise double len2 = dot3(ab, ab);
  precise double t = len2 > 0.0lf ? clamp(-dot3(a, ab) / len2, 0.0lf, 1.0lf) : 0.0lf;
  precise dvec3 p = a + t * ab;
  return dot3(p, p);
}

// Distances (>= 0) to float, rounded outward: the next float below or above is one step of
// a positive float's bit pattern.
float round_down(double z) {
  float f = float(z);
  return double(f) > z && f > 0.0 ? uintBitsToFloat(floatBitsToUint(f) - 1u) : f;
}
float round_up(double z) {
  float f = float(z);
  return double(f) < z ? uintBitsToFloat(floatBitsToUint(f) + 1u) : f;
}

Fragment make_fragment(View v, Setup s, int x, int y, uint mask) {
  dvec2 c = mask_centroid(mask);
  dvec3 d = view_direction(v, double(x) + c.x, double(y) + c.y);
  // Perspective-correct barycentrics: edge k's function weighs the opposite vertex k + 2.
  double lambda[3];
  for (int k = 0; k < 3; ++k) lambda[(k + 2) % 3] = max(dot3(s.edge3d[k].xyz, d), 0.0lf);
  precise dvec3 n = dvec3(0.0lf);
  for (int k = 0; k < 3; ++k) n += lambda[k] * s.vnormal[k].xyz;
  double len = sqrt(dot3(n, n));
  dvec3 normal = len > 0.0lf && !isinf(len) && !isnan(len) ? n / len : normalize3(s.plane.xyz);

  double zmin, zmax;
  dvec3 poly[8];
  int m = pixel_polygon(v, s, x, y, poly);
  if (m == 0) {  // only rounding empties it when samples are covered: the centroid's point
    precise double denom = dot3(s.plane.xyz, d);
    zmin = zmax = denom != 0.0lf ? abs(s.plane.w / denom) * sqrt(dot3(d, d)) : s.plane_distance;
  } else {
    double zmax2 = 0.0lf, zmin2 = 0.0lf;  // zmin2 starts at the first segment's (the CPU's +inf)
    bool foot_inside = x == s.foot_x && y == s.foot_y;
    for (int i = 0; i < m; ++i) {
      zmax2 = max(zmax2, dot3(poly[i], poly[i]));
      if (foot_inside) continue;
      double d2 = segment_distance2(poly[i], poly[i + 1 < m ? i + 1 : 0]);
      zmin2 = i == 0 ? d2 : min(zmin2, d2);
    }
    zmax = sqrt(zmax2);
    zmin = min(foot_inside ? s.plane_distance : sqrt(zmin2), zmax);
  }
  return Fragment(round_down(zmin), round_up(zmax), mask, s.id, encode_octahedral(normal));
}

void main() {
  uint index = flat_group() * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
  if (index >= item_count) return;
  uvec2 item = items[index];
  Setup s = setups[item.x];
  View v = views[s.view];
  ivec4 tile = setup_tile(s, item.y);
  for (int i = 0; i < tile.z * tile.w; ++i) {
    int x = tile.x + i % tile.z, y = tile.y + i / tile.z;
    uint mask = pixel_mask(s, x, y);
    if (mask == 0u) continue;
    uint p = uint(v.first_pixel) + uint(y) * uint(v.width) + uint(x);
    fragments[offsets[p] + atomicAdd(cursors[p], 1u)] = make_fragment(v, s, x, y, mask);
  }
}
