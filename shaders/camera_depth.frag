// The depth passes of the exact camera pass (gl_camera_exact.cpp): the view's depth, the
// mirrors' marks in the stencil, their depth written back. No colour and no discard (the
// mirror a view is seen through is left out by scene.vert), so that the rasteriser tests
// and writes depth before any shading, and needs none.
layout(early_fragment_tests) in;

void main() {}
