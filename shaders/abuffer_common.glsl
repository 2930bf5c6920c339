// The A-buffers on the GPU (host/gl/gl_abuffer.hpp): the CPU raster's rules
// (cpu_core/raster/raster.cpp) in double precision, operation for operation, so that every
// coverage mask equals the CPU's bit for bit. `precise` keeps the compiler from fusing a
// multiply and an add (the CPU build rounds each); every dot product and matrix product is
// written out in the CPU's order (glm's), not left to the built-ins.

// One visible (triangle, view) pair, set up on the CPU (setup_triangle): GpuSetup in
// gl_abuffer.cpp is the same layout.
struct Setup {
  dvec4 edge[4];     // (a, b, c, -): edge functions in pixel coordinates, then the near line
  dvec4 edge3d[4];   // the same edges as planes through the centre
  dvec4 polygon[4];  // the triangle clipped to the near plane, minus the centre
  dvec4 vnormal[3];  // vertex normals
  dvec4 plane;       // plane normal (xyz) and offset (w)
  double plane_distance;
  int view, edge_count, ties, polygon_size;  // ties: bit k = edge k owns its ties
  int foot_x, foot_y, x0, y0;
  int x1, y1;
  uint id;  // triangle | back-face bit
};

layout(std430, binding = ABUFFER_SETUPS_BINDING) readonly buffer Setups { Setup setups[]; };
// The count and fill passes' work items: (setup, tile of its pixel bounds), an invocation each.
layout(std430, binding = ABUFFER_ITEMS_BINDING) readonly buffer Items { uvec2 items[]; };
layout(std430, binding = ABUFFER_VIEWS_BINDING) readonly buffer Views { View views[]; };

// The relative margin of the trivial accept and reject (raster.cpp TRIVIAL_REL).
uniform double trivial_rel;
// The workgroups of one dispatch row (the dispatch is two-dimensional above 65535 groups).
uniform uint groups_per_row;

const uint BACK_FACE_BIT = 0x80000000u;
const uint FULL_MASK = 0xffffffffu;

uint flat_group() { return gl_WorkGroupID.y * groups_per_row + gl_WorkGroupID.x; }

// Tile `tile` of setup s's pixel bounds (row by row, ABUFFER_TILE pixels square, the last
// ones cut): its first pixel and its size.
ivec4 setup_tile(Setup s, uint tile) {
  int across = (s.x1 - s.x0 + ABUFFER_TILE - 1) / ABUFFER_TILE;
  int x = s.x0 + int(tile) % across * ABUFFER_TILE, y = s.y0 + int(tile) / across * ABUFFER_TILE;
  return ivec4(x, y, min(ABUFFER_TILE, s.x1 - x), min(ABUFFER_TILE, s.y1 - y));
}

// pixel_mask (raster.cpp): the samples of pixel (x, y) the triangle covers.
uint pixel_mask(Setup s, int x, int y) {
  precise double x_lo = double(x) + sample_dx(0), x_hi = double(x) + sample_dx(MASK_COLUMNS - 1);
  precise double y_lo = double(y) + sample_dy(0), y_hi = double(y) + sample_dy(MASK_SAMPLES - 1);
  bool all_inside = true;
  for (int k = 0; k < s.edge_count; ++k) {
    dvec3 e = s.edge[k].xyz;
    precise double tol = trivial_rel * (abs(e.x) * (x_hi + 1.0lf) + abs(e.y) * (y_hi + 1.0lf) + abs(e.z));
    precise double e_max = e.x * (e.x > 0.0lf ? x_hi : x_lo) + e.y * (e.y > 0.0lf ? y_hi : y_lo) + e.z;
    if (e_max < -tol) return 0u;
    precise double e_min = e.x * (e.x > 0.0lf ? x_lo : x_hi) + e.y * (e.y > 0.0lf ? y_lo : y_hi) + e.z;
    all_inside = all_inside && e_min > tol;
  }
  if (all_inside) return FULL_MASK;
  uint mask = FULL_MASK;
  for (int k = 0; k < s.edge_count && mask != 0u; ++k) {
    dvec3 e = s.edge[k].xyz;
    bool ties = ((s.ties >> k) & 1) != 0;
    precise double ax[MASK_COLUMNS];
    for (int col = 0; col < MASK_COLUMNS; ++col) ax[col] = e.x * (double(x) + sample_dx(col));
    uint inside = 0u;
    for (int row = 0; row < MASK_ROWS; ++row) {
      precise double base = e.y * (double(y) + sample_dy(row * MASK_COLUMNS)) + e.z;
      for (int col = 0; col < MASK_COLUMNS; ++col) {
        precise double v = ax[col] + base;
        if (ties ? v >= 0.0lf : v > 0.0lf) inside |= 1u << uint(row * MASK_COLUMNS + col);
      }
    }
    mask &= inside;
  }
  return mask;
}

// mask_centroid (raster.cpp): offsets of the covered samples' centroid from the corner.
dvec2 mask_centroid(uint mask) {
  if (mask == 0u || mask == FULL_MASK) return dvec2(0.5lf, 0.5lf);
  int count = 0, column_sum = 0, row_sum = 0;
  for (int row = 0; row < MASK_ROWS; ++row) {
    uint bits = (mask >> uint(row * MASK_COLUMNS)) & 0xffu;
    int c = bitCount(bits);
    int cols = 0;
    for (uint b = bits; b != 0u; b &= b - 1u) cols += findLSB(b);
    count += c;
    column_sum += cols;
    row_sum += c * row;
  }
  precise double cx = (double(column_sum) / double(count) + 0.5lf) / double(MASK_COLUMNS);
  precise double cy = (double(row_sum) / double(count) + 0.5lf) / double(MASK_ROWS);
  return dvec2(cx, cy);
}

// encode_octahedral and decode_octahedral (base/normal_encoding.cpp).
uint snorm16(double v) {
  precise double q = floor(clamp(v, -1.0lf, 1.0lf) * 32767.0lf + 0.5lf);
  return uint(int(q)) & 0xffffu;
}
uint encode_octahedral(dvec3 n) {
  precise double l1 = abs(n.x) + abs(n.y) + abs(n.z);
  precise dvec2 p = l1 > 0.0lf ? dvec2(n.x / l1, n.y / l1) : dvec2(0.0lf);
  if (n.z < 0.0lf) {
    dvec2 sign_xy = dvec2(p.x >= 0.0lf ? 1.0lf : -1.0lf, p.y >= 0.0lf ? 1.0lf : -1.0lf);
    precise dvec2 folded = dvec2((1.0lf - abs(p.y)) * sign_xy.x, (1.0lf - abs(p.x)) * sign_xy.y);
    p = folded;
  }
  return snorm16(p.x) | (snorm16(p.y) << 16u);
}
double unsnorm16(uint bits) {
  return double(bitfieldExtract(int(bits), 0, 16)) / 32767.0lf;  // the low 16 bits, sign-extended
}
dvec3 normalize3(dvec3 v) {
  precise double inv = 1.0lf / sqrt(dot3(v, v));
  precise dvec3 r = v * inv;
  return r;
}
dvec3 decode_octahedral(uint code) {
  double px = unsnorm16(code & 0xffffu), py = unsnorm16(code >> 16u);
  precise dvec3 n = dvec3(px, py, 1.0lf - abs(px) - abs(py));
  if (n.z < 0.0lf) {
    double x = n.x;
    n.x = (1.0lf - abs(n.y)) * (x >= 0.0lf ? 1.0lf : -1.0lf);
    n.y = (1.0lf - abs(x)) * (n.y >= 0.0lf ? 1.0lf : -1.0lf);
  }
  return normalize3(n);
}
