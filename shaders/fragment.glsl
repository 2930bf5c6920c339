// A fragment of an A-buffer's lists as the CPU stores it (raster/abuffer.hpp Fragment, 20
// bytes): what the A-buffer passes write and the candidate scans read.
struct Fragment {
  float zmin, zmax;
  uint mask, id, normal;
};
