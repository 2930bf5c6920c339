// THE RESOLVE PLAN on the GPU (host/gl/gl_resolve_plan.hpp), an invocation a pixel of the
// camera's A-buffer: Pack_Under_Mask (cpu_core/shading/resolve.cpp pack) run over the
// pixel's list with each fragment's opacity known, writing down what pack would shade, in
// its order, and the weights it would sum them with (ResolveStep). The weights and the
// EXACT PRIORITY MASKS are pack's double-precision expressions, operation for operation, so
// that the CPU's run of the steps gives pack's colour bit for bit.
//
// It runs twice: `writing` false counts each pixel's steps, `writing` true writes them from
// the pixel's start. A pixel whose stack would pass RESOLVE_STACK items or whose loops would
// pass `loop_budget` (llvmpipe ends an invocation's loops silently after 65535 passes) is
// left to the CPU (status bit 2). Each invocation ends with a loop bounded by the uniform
// `one`, which a GL that cut the loops short never runs: status bit 4 must be set.
layout(local_size_x = 64) in;

struct TriangleInfo {
  uint object;
  uint pad;
  double opacity;  // the material's, clamped to [0, 1]
};
struct ResolveStep {
  uint kind, at0, at1, mask0, mask1, pad;
  double weight0, weight1;
};

layout(std430, binding = RESOLVE_VIEW_BINDING) readonly buffer ViewBlock { View view; };
layout(std430, binding = RESOLVE_LISTS_BINDING) readonly buffer Lists { uint lists[]; };
layout(std430, binding = RESOLVE_FRAGMENTS_BINDING) readonly buffer Fragments { Fragment fragments[]; };
layout(std430, binding = RESOLVE_TRIANGLES_BINDING) readonly buffer Triangles { TriangleInfo triangle_info[]; };
layout(std430, binding = RESOLVE_POSITIONS_BINDING) readonly buffer Positions { float positions[]; };
layout(std430, binding = RESOLVE_COUNTS_BINDING) buffer Counts { uvec2 counts[]; };
layout(std430, binding = RESOLVE_STARTS_BINDING) readonly buffer Starts { uint starts[]; };
layout(std430, binding = RESOLVE_STEPS_BINDING) writeonly buffer Steps { ResolveStep steps[]; };

uniform uint groups_per_row;
uniform uint first_pixel;  // this dispatch's pixels: [first_pixel, first_pixel + pixel_count)
uniform uint pixel_count;  // counts and starts are indexed from first_pixel
uniform bool writing;
uniform bool exact_priority;
uniform dvec3 centre;         // the view's centre
uniform double tie_relative;  // scene/tie_rule.hpp TIE_RELATIVE
uniform uint loop_budget;
uniform uint one;

const uint BACK_FACE_BIT = 0x80000000u;
const uint FULL_MASK = 0xffffffffu;
const uint NONE = 0xffffffffu;
const uint STEP_SHADE = 0u, STEP_ADD = 1u, STEP_ADD_TWO = 2u, STEP_BACKGROUND = 3u;

uint triangle_of(Fragment f) { return f.id & ~BACK_FACE_BIT; }
double opacity_of(Fragment f) { return triangle_info[triangle_of(f)].opacity; }
uint object_of(Fragment f) { return triangle_info[triangle_of(f)].object; }

dvec3 vertex(uint t, uint k) {
  uint b = 9u * t + 3u * k;
  return dvec3(double(positions[b]), double(positions[b + 1u]), double(positions[b + 2u]));
}

// SampleDepth::t: where the ray centre + t d meets triangle t's plane; +inf along it.
double plane_t(uint t, dvec3 d) {
  dvec3 a = vertex(t, 0u), b = vertex(t, 1u), c = vertex(t, 2u);
  precise dvec3 ab = b - a, ac = c - a, from_centre = a - centre;
  dvec3 normal = cross3(ab, ac);
  double along = dot3(normal, d);
  if (along == 0.0lf) return inf();
  precise double at = dot3(normal, from_centre) / along;
  return at;
}

// scene/tie_rule.hpp: triangle_magnitude, tie_bound, tie_normal, same_distance, seen_before.
double magnitude(uint t) {
  uint b = 9u * t;
  float m = 0.0;
  m = max(m, max(abs(positions[b]), max(abs(positions[b + 1u]), abs(positions[b + 2u]))));
  m = max(m, max(abs(positions[b + 3u]), max(abs(positions[b + 4u]), abs(positions[b + 5u]))));
  m = max(m, max(abs(positions[b + 6u]), max(abs(positions[b + 7u]), abs(positions[b + 8u]))));
  return double(m);
}
double tie_bound(uint ta, uint tb) {
  precise double bound = tie_relative * std_max(magnitude(ta), magnitude(tb));
  return bound;
}
dvec3 tie_normal(uint t) {
  dvec3 a = vertex(t, 0u), b = vertex(t, 1u), c = vertex(t, 2u);
  precise dvec3 ab = b - a, ac = c - a;
  dvec3 n = cross3(ab, ac);
  double len = length3(n);
  if (!(len > 0.0lf)) return dvec3(0.0lf);
  precise dvec3 unit = n / len;
  return unit;
}
bool same_distance(dvec3 dir, uint ta, double at_a, uint tb, double at_b) {
  precise double gap = abs(at_a - at_b);
  double bound = tie_bound(ta, tb);
  precise double along = gap * length3(dir);
  precise bool near_along = along <= bound;
  if (near_along) return true;
  double cos_max = std_max(abs(dot3(tie_normal(ta), dir)), abs(dot3(tie_normal(tb), dir)));
  precise double across = gap * cos_max;
  precise bool near_across = across <= bound;
  return near_across;
}
bool ranks_above(uint tb, uint ta) {
  uint ob = triangle_info[tb].object, oa = triangle_info[ta].object;
  return ob != oa ? ob > oa : tb > ta;
}
// Whether b is seen before a along dir (THE RULE).
bool seen_before(dvec3 dir, uint tb, double at_b, uint ta, double at_a) {
  if (tb == ta) return false;
  if (same_distance(dir, ta, at_a, tb, at_b)) return ranks_above(tb, ta);
  precise bool nearer = at_b < at_a;
  return nearer;
}

// SampleDepth::nearer: the samples of `in_mask` where b's plane is seen before a's.
uint nearer(Fragment a, Fragment b, uint in_mask, uint x, uint y) {
  uint out_mask = 0u;
  for (uint m = in_mask; m != 0u; m &= m - 1u) {
    int k = findLSB(m);
    precise double sx = double(x) + sample_dx(k), sy = double(y) + sample_dy(k);
    dvec3 d = view_direction(view, sx, sy);
    if (seen_before(d, triangle_of(b), plane_t(triangle_of(b), d), triangle_of(a), plane_t(triangle_of(a), d))) {
      out_mask |= 1u << uint(k);
    }
  }
  return out_mask;
}

// resolve.cpp visible_fraction: the thesis' Vis_front estimate, std::clamp'ed to [0, 1].
double visible_fraction(Fragment front, Fragment next) {
  precise double denom = (double(front.zmax) - double(front.zmin)) + (double(next.zmax) - double(next.zmin));
  precise bool empty = !(denom > 0.0lf);
  if (empty) return 1.0lf;
  precise double v = (double(next.zmax) - double(front.zmin)) / denom;
  precise bool below = v < 0.0lf;
  precise bool above = 1.0lf < v;
  return below ? 0.0lf : above ? 1.0lf : v;
}

struct Item {
  uint position;
  uint mask;
  double weight;
};
Item stack_items[RESOLVE_STACK];
uint stack_size = 0u;
bool overflow = false;
uint step_count = 0u, step_base = 0u, step_room = 0u;
uint list_first = 0u, list_size = 0u;

void push(uint position, uint mask, double weight) {
  if (stack_size == RESOLVE_STACK) {
    overflow = true;
    return;
  }
  stack_items[stack_size++] = Item(position, mask, weight);
}

void emit(uint kind, uint at0, uint mask0, double weight0, uint at1, uint mask1, double weight1) {
  if (writing && step_count < step_room) {
    steps[step_base + step_count] = ResolveStep(kind, at0, at1, mask0, mask1, 0u, weight0, weight1);
  }
  ++step_count;
}

Fragment at(uint i) { return fragments[list_first + i]; }

// pack's shaded_over(i, seen) as a step's colour: the whole shade when seen covers the mask.
uint part_mask(Fragment f, uint seen) { return (f.mask & ~seen) == 0u ? 0u : seen; }

void main() {
  uint local = (gl_WorkGroupID.y * groups_per_row + gl_WorkGroupID.x) * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
  if (local >= pixel_count) return;
  uint p = first_pixel + local;
  uint x = p % uint(view.width), y = p / uint(view.width);
  list_first = lists[p];
  list_size = lists[p + 1u] - list_first;
  if (writing) {
    step_base = starts[local];
    step_room = starts[local + 1u] - step_base;
  }
  uint loops = 0u;
  overflow = list_size > loop_budget / 4u;  // one pass over it would take the budget's share
  push(0u, FULL_MASK, 1.0lf);
  while (stack_size > 0u && !overflow && loops <= loop_budget) {
    Item item = stack_items[--stack_size];
    loops += 2u;
    uint i = item.position;
    for (; i < list_size && (at(i).mask & item.mask) == 0u; ++i) ++loops;
    if (i == list_size) {  // nothing left under this mask
      emit(STEP_BACKGROUND, NONE, 0u, item.weight, NONE, 0u, 0.0lf);
      continue;
    }
    Fragment f = at(i);
    uint in_mask = item.mask & f.mask, out_mask = item.mask & ~f.mask;
    double total = double(bitCount(item.mask));
    if (out_mask != 0u) {
      precise double w_out = item.weight * (double(bitCount(out_mask)) / total);
      push(i + 1u, out_mask, w_out);
    }
    precise double w_in = item.weight * (double(bitCount(in_mask)) / total);
    emit(STEP_SHADE, i, 0u, 0.0lf, NONE, 0u, 0.0lf);
    double op_f = opacity_of(f);
    precise double alpha = op_f;
    uint j = i + 1u;
    for (; j < list_size && (at(j).mask & in_mask) == 0u; ++j) ++loops;
    bool intersecting = j < list_size && at(j).zmin <= f.zmax && object_of(at(j)) != object_of(f);
    if (intersecting && exact_priority) {
      Fragment g = at(j);
      uint both = in_mask & g.mask;
      loops += 8u * uint(bitCount(both));
      uint behind = nearer(f, g, both, x, y), front = in_mask & ~behind;
      double op_n = opacity_of(g);
      if (behind != 0u) {
        precise double w_b = w_in * (double(bitCount(behind)) / double(bitCount(in_mask)));
        precise double w_next = w_b * op_n;
        precise double w_own = w_b * (1.0lf - op_n) * op_f;
        emit(STEP_ADD_TWO, j, part_mask(g, behind), w_next, op_n < 1.0lf ? i : NONE, part_mask(f, behind), w_own);
        precise double through = w_b * (1.0lf - op_n) * (1.0lf - op_f);
        if (through > 0.0lf) push(j + 1u, behind, through);
      }
      if (front != 0u) {
        precise double w_f = w_in * (double(bitCount(front)) / double(bitCount(in_mask)));
        precise double w_seen = w_f * op_f;
        emit(STEP_ADD, i, part_mask(f, front), w_seen, NONE, 0u, 0.0lf);
        precise double w_on = w_f * (1.0lf - op_f);
        if (op_f < 1.0lf) push(i + 1u, front, w_on);
      }
      continue;
    }
    if (intersecting) {
      Fragment g = at(j);
      emit(STEP_SHADE, j, 0u, 0.0lf, NONE, 0u, 0.0lf);
      double vis = visible_fraction(f, g);
      alpha = op_f * (vis + (1.0lf - vis) * (1.0lf - opacity_of(g)));
    }
    precise double w_alpha = w_in * alpha;
    emit(STEP_ADD, i, 0u, w_alpha, NONE, 0u, 0.0lf);
    precise double w_behind = w_in * (1.0lf - alpha);
    if (alpha < 1.0lf) push(i + 1u, in_mask, w_behind);
  }
  uint status = stack_size > 0u || overflow ? 2u : 1u;
  for (uint k = 0u; k < one; ++k) status |= 4u;
  counts[local] = uvec2(step_count, status);
}
