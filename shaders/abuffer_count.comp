// Count pass of the GPU cube A-buffer (host/gl/gl_abuffer.cpp): one workgroup a (triangle,
// face) setup; its invocations walk the setup's pixel bounds and count, per pixel, the
// triangles that cover a sample there.
layout(local_size_x = 64) in;
layout(std430, binding = ABUFFER_OFFSETS_BINDING) buffer Counts { uint counts[]; };  // the scan makes them offsets
uniform uint setup_count;

void main() {
  uint index = flat_group();
  if (index >= setup_count) return;
  Setup s = setups[index];
  int w = s.x1 - s.x0, h = s.y1 - s.y0;
  uint first = uint(views[s.view].first_pixel), size = uint(views[s.view].size);
  for (int i = int(gl_LocalInvocationID.x); i < w * h; i += int(gl_WorkGroupSize.x)) {
    int x = s.x0 + i % w, y = s.y0 + i / w;
    if (pixel_mask(s, x, y) != 0u) atomicAdd(counts[first + uint(y) * size + uint(x)], 1u);
  }
}
