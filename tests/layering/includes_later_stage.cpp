// Compiled as a raster file (tests/CMakeLists.txt): shading comes after raster in the flow,
// so this include must not be found.
#include "shading/resolve.hpp"

int layering_probe_later() { return 0; }
