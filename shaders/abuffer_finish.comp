// Finish pass of the GPU A-buffer (host/gl/gl_abuffer.cpp), one invocation a pixel:
// its list sorted front to back (zmin, then triangle and facing: a total order, so the fill's
// order does not matter), merged and capped as finish_fragment_list does (raster/abuffer.hpp,
// MERGE); the kept count goes back into the pixel's cursor. A list longer than
// ABUFFER_GPU_LIST_MAX is left as filled, for the CPU's finish: its sort and merge would take
// more loop iterations than llvmpipe runs in one invocation (glsl_shared.hpp).
layout(local_size_x = 64) in;
layout(std430, binding = ABUFFER_OFFSETS_BINDING) readonly buffer Offsets { uint offsets[]; };
layout(std430, binding = ABUFFER_CURSORS_BINDING) buffer Cursors { uint cursors[]; };
layout(std430, binding = ABUFFER_FRAGMENTS_BINDING) buffer Fragments { Fragment fragments[]; };
layout(std430, binding = ABUFFER_TRIANGLES_BINDING) readonly buffer Triangles { uvec2 object_material[]; };
layout(std430, binding = ABUFFER_STATS_BINDING) buffer Stats { uint max_list; uint dropped; };
uniform uint pixel_count;
uniform uint centre_samples;     // abuffer.hpp CENTRE_SAMPLES
uniform double merge_min_cos;    // abuffer.hpp MERGE_MIN_NORMAL_COS
uniform bool merge;
uniform uint max_layers;         // 0: every layer

bool before(Fragment a, Fragment b) { return a.zmin < b.zmin || (a.zmin == b.zmin && a.id < b.id); }

void sort_list(uint first, uint count) {
  for (uint i = 1u; i < count; ++i) {
    Fragment f = fragments[first + i];
    uint j = i;
    for (; j > 0u && before(f, fragments[first + j - 1u]); --j) fragments[first + j] = fragments[first + j - 1u];
    fragments[first + j] = f;
  }
}

bool mergeable(Fragment a, Fragment b) {
  uint ta = a.id & ~BACK_FACE_BIT, tb = b.id & ~BACK_FACE_BIT;
  return (a.id & BACK_FACE_BIT) == (b.id & BACK_FACE_BIT) && (a.mask & b.mask) == 0u && b.zmin <= a.zmax &&
         a.zmin <= b.zmax && object_material[ta] == object_material[tb] &&
         dot3(decode_octahedral(a.normal), decode_octahedral(b.normal)) >= merge_min_cos;
}

Fragment merge_into(Fragment into, Fragment f) {
  double a1 = double(bitCount(into.mask)), a2 = double(bitCount(f.mask));
  precise dvec3 n = a1 * decode_octahedral(into.normal) + a2 * decode_octahedral(f.normal);
  double len = sqrt(dot3(n, n));
  if (len > 0.0lf) into.normal = encode_octahedral(n / len);
  int c1 = bitCount(into.mask & centre_samples), c2 = bitCount(f.mask & centre_samples);
  bool take = c2 != c1 ? c2 > c1 : a2 > a1 || (a2 == a1 && f.id < into.id);
  if (take) into.id = f.id;
  into.mask |= f.mask;
  into.zmin = min(into.zmin, f.zmin);
  into.zmax = max(into.zmax, f.zmax);
  return into;
}

void main() {
  uint p = flat_group() * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
  if (p >= pixel_count) return;
  uint first = offsets[p], count = cursors[p];
  if (count > ABUFFER_GPU_LIST_MAX) return;
  sort_list(first, count);
  uint kept = 0u;
  bool merged_any = false;
  float reach = -1.0;
  for (uint i = 0u; i < count; ++i) {
    Fragment f = fragments[first + i];
    bool merged = false;
    bool may_merge = merge && f.zmin <= reach;
    for (uint j = 0u; may_merge && j < kept && !merged; ++j) {
      Fragment g = fragments[first + j];
      if (mergeable(g, f)) {
        fragments[first + j] = merge_into(g, f);
        merged = merged_any = true;
      }
    }
    reach = max(reach, f.zmax);
    if (!merged) fragments[first + kept++] = f;
  }
  if (merged_any) sort_list(first, kept);
  if (max_layers > 0u && kept > max_layers) {
    atomicAdd(dropped, kept - max_layers);
    kept = max_layers;
  }
  atomicMax(max_list, kept);
  cursors[p] = kept;
}
