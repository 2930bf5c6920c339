// The box filter of the 4x8 samples of each pixel (base/samples.hpp) on the GPU: the
// camera tile's sample grid (u_samples, 8 columns and 4 rows a pixel) into one texel a
// pixel, so that the exact camera pass reads back pixels, not samples. RGB: the mean of
// the 32 samples (as the CPU resolve weighs its masks); alpha: how many of them met a
// surface the GPU approximates (camera_exact.frag's alpha above 0; 0: the pixel is exact).
// With per-pixel shading (u_pixels, camera_groups.frag), a pixel whose weight's alpha is not
// -1 was shaded whole: C = color + weight * mean, and its samples are approximate where
// its colour is, or where what they show behind it is (weight.a 1).
uniform sampler2D u_samples;
uniform ivec2 u_margin;  // the tile's margin (gl_targets.hpp SampleTiles), not kept
uniform bool u_pixels;
uniform sampler2D u_pixel_color, u_pixel_weight;  // per pixel of the target, margins included
layout(location = 0) out vec4 o_pixel;

void main() {
  ivec2 base = u_margin + ivec2(gl_FragCoord.xy) * ivec2(MASK_COLUMNS, MASK_ROWS);
  vec4 weight = vec4(-1.0), color = vec4(0.0);
  if (u_pixels) {
    weight = texelFetch(u_pixel_weight, base / ivec2(MASK_COLUMNS, MASK_ROWS), 0);
    color = texelFetch(u_pixel_color, base / ivec2(MASK_COLUMNS, MASK_ROWS), 0);
    if (weight == vec4(0.0)) {  // shaded whole, nothing behind: no sample to read
      o_pixel = vec4(color.rgb, color.a != 0.0 ? float(MASK_SAMPLES) : 0.0);
      return;
    }
  }
  vec3 sum = vec3(0.0);
  float approximate = 0.0;
  for (int row = 0; row < MASK_ROWS; ++row) {
    for (int col = 0; col < MASK_COLUMNS; ++col) {
      vec4 s = texelFetch(u_samples, base + ivec2(col, row), 0);
      sum += s.rgb;
      approximate += s.a != 0.0 ? 1.0 : 0.0;
    }
  }
  o_pixel = vec4(sum / float(MASK_SAMPLES), approximate);
  if (weight.a < 0.0) return;  // per sample (or no per-pixel shading)
  o_pixel = vec4(color.rgb + weight.rgb * o_pixel.rgb, color.a != 0.0 ? float(MASK_SAMPLES) : weight.a != 0.0 ? approximate : 0.0);
}
