// Count pass of the GPU A-buffer (host/gl/gl_abuffer.cpp): one invocation a work item, a
// tile of a (triangle, view) setup's pixel bounds; it walks the tile's pixels and counts, per
// pixel, the triangles that cover a sample there.
layout(local_size_x = 64) in;
layout(std430, binding = ABUFFER_OFFSETS_BINDING) buffer Counts { uint counts[]; };  // the scan makes them offsets
uniform uint item_count;

void main() {
  uint index = flat_group() * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
  if (index >= item_count) return;
  uvec2 item = items[index];
  Setup s = setups[item.x];
  ivec4 tile = setup_tile(s, item.y);
  uint first = uint(views[s.view].first_pixel), width = uint(views[s.view].width);
  for (int y = tile.y; y < tile.y + tile.w; ++y) {
    for (int x = tile.x; x < tile.x + tile.z; ++x) {
      if (pixel_mask(s, x, y) != 0u) atomicAdd(counts[first + uint(y) * width + uint(x)], 1u);
    }
  }
}
