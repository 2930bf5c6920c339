// The 4x8 subpixel sample positions, defined once (Carpenter 1984; thesis 5.2, fig. 5.1).
//
// A pixel is split into 4 rows of 8 columns; sample k = row * 8 + col sits at the centre
// of its cell: offset ((col + 0.5)/8, (row + 0.5)/4) from the pixel's corner, measured
// along the raster's column and row directions (s and t on a cube face; x right and y
// down in the camera image). Bit k of a CoverageMask is sample k.
// A GL image rendered at 8x the columns and 4x the rows has its pixel centres exactly at
// these samples, which is how the GL-vs-CPU test checks them.
#pragma once
#include <cstdint>

namespace abcube {

using CoverageMask = uint32_t;
constexpr int MASK_COLUMNS = 8;
constexpr int MASK_ROWS = 4;
constexpr int MASK_SAMPLES = MASK_COLUMNS * MASK_ROWS;
constexpr CoverageMask FULL_MASK = 0xffffffffu;

constexpr double sample_dx(int k) { return ((k % MASK_COLUMNS) + 0.5) / MASK_COLUMNS; }
constexpr double sample_dy(int k) { return ((k / MASK_COLUMNS) + 0.5) / MASK_ROWS; }
constexpr int sample_index(int col, int row) { return row * MASK_COLUMNS + col; }

inline int mask_count(CoverageMask m) { return __builtin_popcount(m); }

// THE SAMPLE LADDER: the exact tracer's rungs of S = 1, 2, 4, 8, 16, 32 camera samples a
// pixel. Rung 1 is the pixel's centre, the best single estimate of a box filter (no cell
// centre is the pixel's centre). Rung S > 1 is the first S samples of SAMPLE_LADDER, so each
// rung holds the one below it:
//   - the samples come in point-symmetric pairs about the pixel's centre ((col, row) then
//     (7 - col, 3 - row)): every rung's mean position is the centre, the image is not shifted;
//   - every rung of 2^m samples is stratified: one sample in each of the 2^m cells of every
//     split of the pixel into 2^a columns by 2^b rows (a + b = m, a <= 3, b <= 2): rung 4 has
//     one sample in each row, each quarter of the columns and each quadrant; rung 8 one in
//     each column, each half-row;
//   - among the orders with both properties (32 of them), this one has the least mean squared
//     difference, summed over the rungs, between a rung's coverage of a random straight edge
//     and the 32 samples' coverage of it: the error against the reference where images differ.
// tests/core/test_samples.cpp checks each property.
constexpr int SAMPLE_LADDER[MASK_SAMPLES] = {17, 14, 2,  29, 8, 23, 27, 4, 24, 7,  1,  30, 18, 13, 11, 20,
                                             0,  31, 16, 15, 9, 22, 25, 6, 10, 21, 26, 5,  3,  28, 19, 12};
// Whether S is a rung of the ladder.
constexpr bool is_sample_rung(int s) { return s == 1 || s == 2 || s == 4 || s == 8 || s == 16 || s == 32; }

// The sides of a pixel, as bits, and those that sample k lies on (its column 0 or 7, its
// row 0 or 3): where what a sample sees touches the next pixel.
constexpr uint8_t SIDE_LEFT = 1, SIDE_RIGHT = 2, SIDE_TOP = 4, SIDE_BOTTOM = 8;
constexpr uint8_t sample_sides(int k) {
  const int col = k % MASK_COLUMNS, row = k / MASK_COLUMNS;
  return static_cast<uint8_t>((col == 0 ? SIDE_LEFT : 0) | (col == MASK_COLUMNS - 1 ? SIDE_RIGHT : 0) |
                              (row == 0 ? SIDE_TOP : 0) | (row == MASK_ROWS - 1 ? SIDE_BOTTOM : 0));
}

}  // namespace abcube
