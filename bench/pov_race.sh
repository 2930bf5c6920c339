#!/usr/bin/env bash
# The race: abcube's `abuffer` method against POV-Ray 3.7 on the same scene, triangles,
# resolution, samples and threads, wall clock side by side in one run, each image's PSNR
# against our exact tracer (`--method raytrace`).
#
#   bash bench/pov_race.sh [--runs K] [--threads T] [--cube-res N] [--out DIR] [--fresh] [SCENE[:N] ...]
#
# Default scenes: scenes/bench/spheres_terrain.json scenes/cornell.json scenes/default.json.
# SCENE:N sets the cube resolution for that scene (else --cube-res, else the scene's own).
#
# WHAT IS TIMED. Whole processes, wall clock (`date +%s.%N` around each), median of K runs
# (default 5) with [min, max]:
#   abuffer  `abcube render SCENE -o A.png --method abuffer --threads T --cube-res N --stats S.json`
#            (load, cube and camera A-buffers, searches, resolve, PNG write). The PSNR run is
#            separate and untimed: `--reference-image REF.exr` also builds the exact tracer to
#            measure the reflection rays' Error_CP / Error_Parallax, which is not rendering.
#   POV-Ray  `povray +I S.pov +O P.ppm +FP16 File_Gamma=1.0 +W8W +H4H -A -D -P +WT T` on
#            `abcube export-pov` output (parse, bounding, trace, write).
# SAMPLES. POV-Ray renders at 8 W x 4 H without antialiasing: its pixel centres are then
# exactly our 32 samples per pixel (the trick of tests/core/test_pov.cpp), and each 8 x 4
# block mean (oiiotool --resize:filter=box, untimed) is our box-filtered pixel. Linear
# 16-bit output (File_Gamma=1.0) is averaged linearly and written as float EXR, which
# `abcube compare` reads as linear (it sRGB-decodes 8/16-bit files only).
# REFERENCE. REF.exr = `abcube render --method raytrace --threads T`, rendered once per scene
# and kept in DIR (--fresh renders it again).
# POV-Ray's PSNR includes the residual model differences of cpu_core/io/pov_export.hpp (glass:
# POV-Ray scales ambient and diffuse by 1 - T; uncoloured shadows through glass; Phong).
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ABCUBE=${ABCUBE:-$ROOT/build/abcube}
RUNS=5
THREADS=2
CUBE_RES=""
OUT=${TMPDIR:-/tmp}/abcube-pov-race
FRESH=0
SCENES=()

usage() { sed -n '6,9p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' >&2; exit 2; }
while [ $# -gt 0 ]; do
  case "$1" in
    --runs) RUNS=$2; shift 2 ;;
    --threads) THREADS=$2; shift 2 ;;
    --cube-res) CUBE_RES=$2; shift 2 ;;
    --out) OUT=$2; shift 2 ;;
    --fresh) FRESH=1; shift ;;
    -h|--help) usage ;;
    -*) echo "pov_race.sh: unknown option $1" >&2; usage ;;
    *) SCENES+=("$1"); shift ;;
  esac
done
[ ${#SCENES[@]} -gt 0 ] || SCENES=(scenes/bench/spheres_terrain.json scenes/cornell.json scenes/default.json)
for tool in "$ABCUBE" povray oiiotool python3; do
  command -v "$tool" > /dev/null || { echo "pov_race.sh: $tool not found" >&2; exit 1; }
done
mkdir -p "$OUT"

now() { date +%s.%N; }

# "median [min, max]" in ms of the seconds given as arguments.
summary_ms() {
  printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 * 1000 }
    END { m = NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2;
          printf "%.0f [%.0f, %.0f]", m, v[1], v[NR] }'
}
median_of() { printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 } END { print NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

psnr_of() {  # PSNR in dB of image $1 against $2 (abcube compare; "inf" when identical)
  "$ABCUBE" compare "$1" "$2" 2> /dev/null | awk '/^PSNR/ { print $2 }' || true
}

json_get() {  # json_get FILE a.b.c
  python3 -c 'import json, sys
d = json.load(open(sys.argv[1]))
for k in sys.argv[2].split("."): d = d[k]
print(d)' "$1" "$2"
}

ROWS=()
for spec in "${SCENES[@]}"; do
  scene=${spec%%:*}
  n=$CUBE_RES
  [ "$spec" != "$scene" ] && n=${spec#*:}
  case "$scene" in /*) ;; *) scene=$ROOT/$scene ;; esac
  name=$(basename "$scene" .json)
  dir=$OUT/$name
  mkdir -p "$dir"
  ref=$dir/ref.exr
  if [ "$FRESH" = 1 ] || [ ! -s "$ref" ]; then
    echo "[$name] reference: raytrace, $THREADS threads" >&2
    "$ABCUBE" render "$scene" -o "$ref" --method raytrace --threads "$THREADS" 2> /dev/null
  fi
  nargs=()
  [ -n "$n" ] && nargs=(--cube-res "$n")
  # Untimed run: the stats with the image error against the reference.
  "$ABCUBE" render "$scene" -o "$dir/abuffer.png" --method abuffer --threads "$THREADS" "${nargs[@]}" \
    --stats "$dir/abuffer_ref.json" --reference-image "$ref" 2> /dev/null
  width=$(json_get "$dir/abuffer_ref.json" size.width)
  height=$(json_get "$dir/abuffer_ref.json" size.height)
  n=$(json_get "$dir/abuffer_ref.json" size.cube_resolution)
  ab_psnr=$(psnr_of "$dir/abuffer.png" "$ref")

  "$ABCUBE" export-pov "$scene" -o "$dir/scene.pov"
  ab_times=() pov_times=() shade=()
  for ((k = 0; k < RUNS; ++k)); do  # interleaved, so drifts in machine load hit both
    echo "[$name] run $((k + 1))/$RUNS" >&2
    t0=$(now)
    "$ABCUBE" render "$scene" -o "$dir/abuffer_timed.png" --method abuffer --threads "$THREADS" "${nargs[@]}" \
      --stats "$dir/abuffer.json" 2> /dev/null
    t1=$(now)
    ab_times+=("$(echo "$t1 - $t0" | bc -l)")
    shade+=("$(json_get "$dir/abuffer.json" timings_ms.shade_and_resolve)")
    t0=$(now)
    (cd "$dir" && povray +Iscene.pov +Opov.ppm +FP16 File_Gamma=1.0 +W$((8 * width)) +H$((4 * height)) \
       -A -D -P +WT"$THREADS" > pov.log 2>&1)
    t1=$(now)
    pov_times+=("$(echo "$t1 - $t0" | bc -l)")
  done
  oiiotool "$dir/pov.ppm" --resize:filter=box "${width}x${height}" -d float -o "$dir/pov.exr"
  pov_psnr=$(psnr_of "$dir/pov.exr" "$ref")
  ratio=$(echo "$(median_of "${ab_times[@]}") / $(median_of "${pov_times[@]}")" | bc -l)
  ROWS+=("$(printf '| %s | %dx%d | %s | %s | %s | %s | %s | %s | %.2f | %.0f |' "$name" "$width" "$height" "$n" \
    "$THREADS" "$(summary_ms "${ab_times[@]}")" "$ab_psnr" "$(summary_ms "${pov_times[@]}")" "$pov_psnr" \
    "$ratio" "$(median_of "${shade[@]}")")")
done

echo
echo "abcube abuffer against POV-Ray 3.7 (8W x 4H, no AA = our 32 samples/pixel); wall ms median [min, max] of $RUNS;"
echo "PSNR dB against our exact tracer; $(nproc) cores, $(date -u +%Y-%m-%dT%H:%MZ)"
echo
echo "| scene | size | N | threads | abuffer ms | abuffer PSNR | POV-Ray ms | POV-Ray PSNR | abuffer/POV | shade+resolve ms (median) |"
echo "|---|---|---|---|---|---|---|---|---|---|"
printf '%s\n' "${ROWS[@]}"
