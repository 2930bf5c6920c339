// Exclusive prefix sum of the GPU A-buffer's per-pixel counts (host/gl/gl_abuffer.cpp),
// one level: each workgroup scans ABUFFER_SCAN_BLOCK values in place and writes their sum
// to `sums`; the host scans the sums the same way, a level up, and add_block_sums adds each
// block's offset back.
layout(local_size_x = ABUFFER_SCAN_BLOCK) in;
layout(std430, binding = ABUFFER_SCAN_VALUES_BINDING) buffer Values { uint values[]; };
layout(std430, binding = ABUFFER_SCAN_SUMS_BINDING) buffer Sums { uint sums[]; };
uniform uint value_count;
uniform uint groups_per_row;
uniform bool add_block_sums;  // false: scan each block; true: add sums[block] to its values

shared uint partial[ABUFFER_SCAN_BLOCK];

void main() {
  uint block = gl_WorkGroupID.y * groups_per_row + gl_WorkGroupID.x;
  uint i = block * ABUFFER_SCAN_BLOCK + gl_LocalInvocationID.x;
  if (add_block_sums) {
    if (i < value_count) values[i] += sums[block];
    return;
  }
  uint own = i < value_count ? values[i] : 0u;
  partial[gl_LocalInvocationID.x] = own;
  barrier();
  // Hillis-Steele inclusive scan in shared memory.
  for (uint step = 1u; step < ABUFFER_SCAN_BLOCK; step <<= 1u) {
    uint add = gl_LocalInvocationID.x >= step ? partial[gl_LocalInvocationID.x - step] : 0u;
    barrier();
    partial[gl_LocalInvocationID.x] += add;
    barrier();
  }
  if (i < value_count) values[i] = partial[gl_LocalInvocationID.x] - own;
  if (gl_LocalInvocationID.x == ABUFFER_SCAN_BLOCK - 1u) sums[block] = partial[gl_LocalInvocationID.x];
}
