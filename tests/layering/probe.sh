#!/usr/bin/env bash
# The build enforces cpu_core's layering (cpu_core/CMakeLists.txt): a file compiled as part
# of the raster stage builds when it includes earlier stages, and fails, naming the header,
# when it includes a later one.
# Usage (ctest runs it so): bash probe.sh CMAKE BUILD_DIR
set -u
CMAKE=$1
BUILD=$2
log=$(mktemp)
trap 'rm -f "$log"' EXIT
failed=0
if ! "$CMAKE" --build "$BUILD" --target layering_probe_lower > "$log" 2>&1; then
  echo "FAIL a raster file including scene and reference headers did not build:"
  cat "$log"
  failed=1
fi
if "$CMAKE" --build "$BUILD" --target layering_probe_later > "$log" 2>&1; then
  echo "FAIL a raster file including a shading header built: the layering is not enforced"
  failed=1
elif ! grep -q 'shading/resolve.hpp: No such file' "$log"; then
  echo "FAIL the raster file including a shading header failed for another reason:"
  cat "$log"
  failed=1
fi
[ "$failed" -eq 0 ] && echo "PASS the raster stage sees earlier stages and not later ones"
exit "$failed"
