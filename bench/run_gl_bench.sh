#!/usr/bin/env bash
# The GL passes benchmark on the bench scene, through each GL API (docs/performance.md).
# Usage: bash bench/run_gl_bench.sh [BUILD_DIR]   (after building)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
for gl in egl osmesa; do
  "$BUILD/bench/bench_gl_passes" scenes/bench/spheres_terrain.json --runs 5 --gl "$gl" \
    --sizes 256,512,1024,2048 --error-samples 200000
  echo
done
