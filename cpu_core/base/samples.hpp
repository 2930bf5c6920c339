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

// The sides of a pixel, as bits, and those that sample k lies on (its column 0 or 7, its
// row 0 or 3): where what a sample sees touches the next pixel.
constexpr uint8_t SIDE_LEFT = 1, SIDE_RIGHT = 2, SIDE_TOP = 4, SIDE_BOTTOM = 8;
constexpr uint8_t sample_sides(int k) {
  const int col = k % MASK_COLUMNS, row = k / MASK_COLUMNS;
  return static_cast<uint8_t>((col == 0 ? SIDE_LEFT : 0) | (col == MASK_COLUMNS - 1 ? SIDE_RIGHT : 0) |
                              (row == 0 ? SIDE_TOP : 0) | (row == MASK_ROWS - 1 ? SIDE_BOTTOM : 0));
}

}  // namespace abcube
