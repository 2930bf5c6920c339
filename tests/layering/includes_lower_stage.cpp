// Compiled as a raster file (tests/CMakeLists.txt): raster may include what comes before it
// in the flow, here the scene and the exact tracer's triangle test.
#include "reference/triangle_test.hpp"
#include "scene/scene_data.hpp"

int layering_probe_lower() { return 0; }
