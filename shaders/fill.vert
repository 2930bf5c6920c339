// A triangle covering the whole viewport, at the far plane (reversed Z: depth 0): the fills
// and full-screen passes of gl_camera_exact.cpp, restricted by the stencil test.
void main() {
  const vec2 corner[3] = vec2[3](vec2(-1.0, -1.0), vec2(3.0, -1.0), vec2(-1.0, 3.0));
  gl_Position = vec4(corner[gl_VertexID], 0.0, 1.0);
}
