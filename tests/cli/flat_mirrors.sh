#!/usr/bin/env bash
# The gpu method on scenes whose mirrors are all flat (issue 19; tools/flat_mirror_scenes.py:
# a mirror whose plane holds the camera, a floor mirror showing a hidden quad, mirror boxes,
# grazing water, a light on a mirror), one scene of each template for a fixed seed and for
# one seed new each run (printed): against the exact tracer it must reach 35 dB and come
# within 1 dB of abuffer or better; hybrid must be no less accurate than abuffer but for
# shadow-edge samples the GPU decides in float (lib/shadow_flips.py). Rendered
# small (128 x 96, abuffer at N = 128) in one batch per method. Then hybrid against abuffer
# on the repository's scenes, where it sends to the CPU the pixels the GPU approximates. Usage (ctest runs it so): bash flat_mirrors.sh /path/to/abcube /path/to/repo
# ABCUBE_FLAT_SEED=S repeats a run's new seed.
set -u
ABCUBE=$1
REPO=$2
CLI_TEST=flat_mirrors
. "$(dirname "$0")/lib/check.sh"
. "$(dirname "$0")/lib/generated.sh"
SEED=${ABCUBE_FLAT_SEED:-$RANDOM}
echo "seeds: 1 and $SEED (ABCUBE_FLAT_SEED=$SEED repeats this run)"
require_gl
for seed in 1 "$SEED"; do generate flat_mirror_scenes "$seed" 5 "$WORK/scenes"; done
# batch_all DIR PREFIX METHOD...: every scene of DIR rendered by each method in one batch,
# into $WORK/PREFIX$method/; raytrace writes the shadowed AOV beside its image.
batch_all() {
  local dir=$1 prefix=$2 method scene
  shift 2
  for method in "$@"; do
    : > "$WORK/$prefix$method.jsonl"
    for scene in "$dir"/*.json; do
      aovs=""
      [ "$method" = raytrace ] && aovs=', "aovs": ["shadowed"]'
      echo "{\"scene\": \"$scene\", \"out\": \"$prefix$method/$(basename "$scene" .json).exr\", \"method\": \"$method\"$aovs}" \
        >> "$WORK/$prefix$method.jsonl"
    done
    "$ABCUBE" batch "$WORK/$prefix$method.jsonl" > /dev/null 2> "$WORK/$prefix$method.err"
    status=$?
    check "$prefix$method renders every scene ($(head -c 300 "$WORK/$prefix$method.err"))" [ $status -eq 0 ]
  done
}
batch_all "$WORK/scenes" "" raytrace abuffer gpu hybrid
psnr() { "$ABCUBE" compare "$1" "$2" | awk '/^PSNR/ {print $2}'; }
# at_least A B [SLACK]: PSNR A >= B - SLACK, both capped at 100 dB (RMSE 1e-5): above that
# the two differ by float rounding alone (the GPU shades in float, the CPU in double; a
# scene abuffer renders exactly, inf, came out of the GPU at 152.65 dB).
at_least() {
  awk -v x="$1" -v y="$2" -v slack="${3:-0}" \
    'function cap(v) { return (v == "inf" || v + 0 > 100) ? 100 : v + 0 }
     BEGIN { exit !(x != "" && y != "" && cap(x) >= cap(y) - slack) }'
}
# hybrid_no_worse NAME REFERENCE ABUFFER HYBRID: hybrid's PSNR against the reference is at
# least abuffer's, both capped at 75 dB (RMSE 1.8e-4). The cap: hybrid's GPU passes shade once
# a pixel and surface (--gpu-shading pixels), whose error inside a pixel is about 80 dB on
# plane_through_camera_5_2 at 128x96, where abuffer searching a mirror's samples one by one
# reaches 86 (at 64x48: hybrid 77.3, abuffer 76.5, and hybrid with --gpu-shading samples
# 137.0). Below abuffer, every pixel of the excess must be a shadow-edge sample the GPU
# decided in float (lib/shadow_flips.py, from REFERENCE's shadowed AOV beside it): a volume's
# side meeting the surface within float rounding of a sample (camera_inside_16334_3: 3
# pixels a sample off, 56.19 against 56.21 dB; coplanar_21883_1: 7 pixels along a grazing
# shadow edge, 70.14 against 76.29). A lost shadow, as in the tiles below, is neither.
hybrid_no_worse() {
  local ab hy
  ab=$(psnr "$3" "$2")
  hy=$(psnr "$4" "$2")
  echo "$1: hybrid $hy dB, abuffer $ab dB"
  if at_least "$(cap75 "$hy")" "$(cap75 "$ab")"; then
    check "$1: hybrid no less accurate than abuffer ($hy against $ab)" true
  else
    check "$1: hybrid below abuffer ($hy against $ab) only by shadow-edge flips" \
      env PYTHONPATH="$(dirname "$ABCUBE")/python" /usr/bin/python3 "$(dirname "$0")/lib/shadow_flips.py" "$2" "$3" "$4" \
      "${2%.exr}.shadowed.exr"
  fi
}
cap75() { awk -v v="$1" 'BEGIN { print (v == "inf" || v + 0 > 75) ? 75 : v }'; }
for scene in "$WORK"/scenes/*.json; do
  stem=$(basename "$scene" .json)
  gpu=$(psnr "$WORK/gpu/$stem.exr" "$WORK/raytrace/$stem.exr")
  ab=$(psnr "$WORK/abuffer/$stem.exr" "$WORK/raytrace/$stem.exr")
  echo "$stem: gpu $gpu dB, abuffer $ab dB"
  check "$stem: gpu reaches 35 dB ($gpu)" awk -v g="$gpu" 'BEGIN { exit !(g == "inf" || g >= 35) }'
  # capped at 75 dB as hybrid_no_worse (floor_mirror_hidden_16334_1: gpu 78.93, abuffer 80.80)
  check "$stem: gpu within 1 dB of abuffer or better ($gpu against $ab)" \
    at_least "$(cap75 "$gpu")" "$(cap75 "$ab")" 1
  hybrid_no_worse "$stem" "$WORK/raytrace/$stem.exr" "$WORK/abuffer/$stem.exr" "$WORK/hybrid/$stem.exr"
done
# One scene of each hard-case template (km-wide ground, a camera inside a room, nested
# glass, ...) for seed 5, for seed 103 (seams_103_10: a mirror's top edge 0.0008 of a sample
# above a sample row's centres, which GL's snapped vertices put on the other side: a line of
# wrong pixels, 51.0 against abuffer's 54.1 dB, before edge_ties.hpp) and for this run's new
# seed: hybrid no less accurate than abuffer there either.
for seed in 5 103 "$SEED"; do generate hard_scenes "$seed" 11 "$WORK/hard"; done
batch_all "$WORK/hard" hard_ raytrace abuffer hybrid
"$ABCUBE" render "$WORK/hard/seams_103_10.json" -o "$WORK/seams_103_10.exr" --method hybrid --stats "$WORK/seams.json" \
  2> "$WORK/err"
check "seams_103_10: the pixels at the mirror's edge are traced" /usr/bin/python3 -c "
import json, sys
s = json.load(open(sys.argv[1]))['hybrid']
sys.exit(not (s['pixels_traced_edge_ties'] >= 21 and s['pixels_gpu'] + s['pixels_cpu'] + s['pixels_traced_edge_ties'] == s['pixels']))" \
  "$WORK/seams.json"
for scene in "$WORK"/hard/*.json; do
  stem=$(basename "$scene" .json)
  hybrid_no_worse "$stem" "$WORK/hard_raytrace/$stem.exr" "$WORK/hard_abuffer/$stem.exr" "$WORK/hard_hybrid/$stem.exr"
done
# Many camera tiles (640x480: 5 x 2 tiles of 1024 samples). light_on_mirror_3_4: the light
# 1e-6 above the mirror table's top. Casting from a closed object's light-facing faces alone
# when the light is outside it (tried, docs/design/gpu-exact-paths.md) lost the shadow in lines
# along the tiles' seams there: hybrid 34.0 dB against abuffer's 55.3 (at N = 512; one tile,
# 128x96, showed nothing). light_on_open_mirror: the light on, or 1e-6 above or below, an
# open mirror quad, whose volume's sides and far caps reach infinity nearly in its plane and
# behind the eye. Clipped by the GL at each tile's edges they lost their counts in wedges
# along the seams: seed 3 gave hybrid 37.17 dB against abuffer's 58.34, 88.93 once those
# faces are clipped in double on the CPU (shadow_volume.hpp).
for seed in 3 "$SEED"; do
  /usr/bin/python3 "$REPO/tools/flat_mirror_scenes.py" --seed "$seed" --count 1 --out "$WORK/tiles" --size 640x480 \
    --cube-res 128 --templates light_on_open_mirror > /dev/null ||
    { echo "FAIL: tools/flat_mirror_scenes.py --seed $seed --templates light_on_open_mirror (640x480)"; exit 1; }
done
/usr/bin/python3 "$REPO/tools/flat_mirror_scenes.py" --seed 3 --count 5 --out "$WORK/tiles" --size 640x480 \
  --cube-res 128 > /dev/null || { echo "FAIL: tools/flat_mirror_scenes.py --seed 3 (640x480)"; exit 1; }
for scene in "$WORK/tiles/light_on_mirror_3_4.json" "$WORK"/tiles/light_on_open_mirror_*.json; do
  stem=$(basename "$scene" .json)
  for method in raytrace abuffer hybrid; do
    aovs=""
    [ $method = raytrace ] && aovs="--aovs shadowed"
    # shellcheck disable=SC2086
    "$ABCUBE" render "$scene" -o "$WORK/tiles_${stem}_$method.exr" --method $method $aovs 2> "$WORK/err"
    status=$?
    check "$stem (640x480): $method renders ($(head -c 200 "$WORK/err"))" [ $status -eq 0 ]
  done
  hybrid_no_worse "$stem (640x480)" "$WORK/tiles_${stem}_raytrace.exr" "$WORK/tiles_${stem}_abuffer.exr" \
    "$WORK/tiles_${stem}_hybrid.exr"
done
# The repository's scenes (glass, a curved mirror, coverage transparency: pixels for the CPU),
# at 256 x 192: the same surfaces on fewer pixels than their own size.
for name in cornell default hidden_point shadows textured; do
  for method in raytrace abuffer hybrid; do
    extra="--cube-res 128 --size 256x192"
    [ $method = raytrace ] && extra="--aovs shadowed --size 256x192"
    # shellcheck disable=SC2086
    "$ABCUBE" render "$REPO/scenes/$name.json" -o "$WORK/repo_${name}_$method.exr" --method $method $extra 2> "$WORK/err"
    status=$?
    check "$name: $method renders ($(head -c 200 "$WORK/err"))" [ $status -eq 0 ]
  done
  hybrid_no_worse "$name" "$WORK/repo_${name}_raytrace.exr" "$WORK/repo_${name}_abuffer.exr" "$WORK/repo_${name}_hybrid.exr"
done
# Coverage transparency (default.json's veil) rules the exact pass out: hybrid is abuffer,
# byte for byte, and draws no GPU camera pass at all.
"$ABCUBE" render "$REPO/scenes/default.json" -o "$WORK/default_hybrid_stats.exr" --method hybrid --cube-res 128 \
  --size 256x192 --stats "$WORK/default_hybrid.json" 2> "$WORK/err"
check "default: hybrid equals abuffer" cmp -s <("$ABCUBE" compare --exact "$WORK/default_hybrid_stats.exr" "$WORK/repo_default_abuffer.exr") <(echo IDENTICAL)
check "default: hybrid draws no camera pass" /usr/bin/python3 -c "
import json, sys
s = json.load(open(sys.argv[1]))
sys.exit(not ('camera_raster' not in s['timings_ms'] and s['plan']['passes'] == ['cpu abuffer for every pixel']
              and s['hybrid']['pixels_cpu'] == s['hybrid']['pixels'] and 'coverage' in s['hybrid']['why_all_cpu']))" \
  "$WORK/default_hybrid.json"
echo "flat_mirrors: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
