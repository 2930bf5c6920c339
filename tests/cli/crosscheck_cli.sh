#!/usr/bin/env bash
# `abcube crosscheck` on every repository scene, through both GL APIs: the GPU distance
# prepass against the CPU A-buffer texel by texel, and the GPU Z-buffer image against the
# CPU A-buffer image away from silhouettes, within the tolerances documented in
# host/render/crosscheck.hpp (the command exits 1 beyond them). Also --method abuffer renders.
# Usage (ctest runs it so): bash crosscheck_cli.sh /path/to/abcube /path/to/repo
# ABCUBE_CROSSCHECK_GL, when set (e.g. "osmesa"), is the list of GL APIs the repository's
# scenes go through, and its first the one every other run uses (else `--gl auto`): the ASan
# stage of tools/sanitize.sh checks the code of one API (the egl.* tests check EGL's).
set -u
ABCUBE=$1
REPO=$2
APIS=${ABCUBE_CROSSCHECK_GL:-egl osmesa}
# In the checked builds (ABCUBE_CHECKED_BUILD, tools/sanitize.sh) the same code runs on less:
# two repository scenes, the camera samples at 128 x 96, three generated scenes and no kept
# regressions (those are accuracy cases, which the ordinary build checks).
CHECKED=${ABCUBE_CHECKED_BUILD:-0}
SCENES="default hidden_point cornell shadows textured"
SAMPLES_SIZE=(512 384)
HARD_COUNT=11
if [ "$CHECKED" = 1 ]; then SCENES="hidden_point textured"; SAMPLES_SIZE=(128 96); HARD_COUNT=3; fi
GL=()
[ -n "${ABCUBE_CROSSCHECK_GL:-}" ] && GL=(--gl "${APIS%% *}")
WORK=$(mktemp -d "${TMPDIR:-/tmp}/abcube_crosscheck.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
passed=0
failed=0
# The repository's scenes at 256 x 192: every pass of the cross-check on fewer pixels than
# their own size (the camera samples are checked at 512 x 384 below).
for scene in $SCENES; do
  for gl in $APIS; do
    # The image shaded with the GPU's search candidates is the CPU searches', byte for byte;
    # the resolve's plan gives the CPU's colours, and the GL passed THE PROBE.
    if "$ABCUBE" crosscheck "$REPO/scenes/$scene.json" --cube-res 96 --size 256x192 --gl "$gl" --stats "$WORK/$scene.json" \
        > "$WORK/out" 2>&1 && grep -q '^GPU search image: 64x48, 0 pixels over 1/255 .* the same bytes' "$WORK/out" &&
      grep -q "^GPU resolve plan: \([0-9]*\) of \1 pixels .*; the probe: agrees$" "$WORK/out"; then
      passed=$((passed + 1))
      echo "ok   $scene ($gl): $(grep -E '^distance' "$WORK/out" | head -1); $(grep '^GPU search image' "$WORK/out")"
    else
      failed=$((failed + 1))
      echo "FAIL $scene ($gl):"
      cat "$WORK/out"
    fi
  done
done
# Visibility sample by sample (issue 19 part 1): the stats count every camera sample, the
# disagreement image has a value per pixel, and one scene of every hard-case template (seed 5)
# passes every tolerance of crosscheck.hpp (exit 0), its sample agreement and shadow volumes
# checked again from the stats. (Before interior pixels had to be one triangle over the
# whole pixel and its centre, and the nearest layer picked the triangle holding the texel
# centre between coplanar neighbours, the interior colour and the cube's same-object share
# failed on some templates: docs/design/gpu-cpu-crosscheck.md.)
scene=default
"$ABCUBE" crosscheck "$REPO/scenes/$scene.json" "${GL[@]}" --cube-res 96 --samples-image "$WORK/samples.exr" \
  --size "${SAMPLES_SIZE[0]}x${SAMPLES_SIZE[1]}" --stats "$WORK/samples.json" > /dev/null 2>&1
if python3 -c "import json,sys; s=json.load(open('$WORK/samples.json'))['camera_samples']; sys.exit(0 if s['samples'] == ${SAMPLES_SIZE[0]} * ${SAMPLES_SIZE[1]} * 32 and s['agreement'] >= 0.9999 and s['same_object'] + s['gpu_only'] + s['cpu_only'] + s['other_object'] + s['edge_ties_differing'] == s['samples'] else 1)" &&
   [ -s "$WORK/samples.exr" ]; then
  passed=$((passed + 1))
  echo "ok   camera samples of $scene counted, agreement image written"
else
  failed=$((failed + 1))
  echo "FAIL camera samples of $scene: $(cat "$WORK/samples.json" 2>/dev/null | head -c 600)"
fi
/usr/bin/python3 "$REPO/tools/hard_scenes.py" --seed 5 --count "$HARD_COUNT" --out "$WORK/hard" --size 96x64 --cube-res 96 > /dev/null
for scene in "$WORK"/hard/*.json; do
  if "$ABCUBE" crosscheck "$scene" "${GL[@]}" --stats "$WORK/hard.stats.json" > "$WORK/out" 2>&1 &&
     python3 -c "import json,sys; d=json.load(open('$WORK/hard.stats.json')); s=d['camera_samples']; v=d['shadows']['volumes']; sys.exit(0 if s['samples'] == 96 * 64 * 32 and s['agreement'] >= 0.9999 and v['interior_agreement'] >= 0.999 else 1)"; then
    passed=$((passed + 1))
    echo "ok   $(basename "$scene"): $(grep '^camera samples' "$WORK/out"); volumes $(grep 'GPU shadow volumes' "$WORK/out")"
  else
    failed=$((failed + 1))
    echo "FAIL $(basename "$scene"):"
    cat "$WORK/out"
  fi
done
# Generated scenes on which crosscheck once failed a valid render (tests/cli/crosscheck_regressions,
# tools/hard_scenes.py --seed 77, 128 x 96, N = 128): thin_features_77_16, interior max abs
# 0.60 (a wire between the 32 samples over the pixel centre the GPU image samples);
# nested_glass_77_29, same object 0.99257 (coplanar stripes meeting between the centre
# samples and the texel centre); seams_highlight (a seams scene without its box), interior
# max abs 0.0169 > 4/255 (a merged fragment's averaged normal in a sphere's highlight).
regressions=("$REPO"/tests/cli/crosscheck_regressions/*.json)
[ "$CHECKED" = 1 ] && regressions=()
for scene in "${regressions[@]}"; do
  if "$ABCUBE" crosscheck "$scene" "${GL[@]}" > "$WORK/out" 2>&1; then
    passed=$((passed + 1))
    echo "ok   $(basename "$scene"): $(grep -E '^camera interior' "$WORK/out")"
  else
    failed=$((failed + 1))
    echo "FAIL $(basename "$scene"):"
    cat "$WORK/out"
  fi
done
# Coplanar overlapping quads of two objects (THE TIE RULE, cpu_core/scene/tie_rule.hpp): on
# a wall facing the camera, and on a slope (float-rounded vertices), plus the coplanar hard
# case kept in tests/hard/regressions. The texels where both objects are at the same distance
# are counted as ties, and both paths must give them to the later object.
cat > "$WORK/coplanar.json" <<'JSON'
{"version": 1, "camera": {"position": [0.03, 0.6, 1.2], "look_at": [0, 0.4, -1], "width": 96, "height": 64},
 "lights": [{"type": "point", "position": [1, 3, 2], "color": [1, 1, 1]}],
 "materials": {"red": {"color": [0.9, 0.1, 0.1]}, "green": {"color": [0.1, 0.9, 0.1]}, "floor": {"color": [0.6, 0.6, 0.6]}},
 "objects": [
  {"type": "quad", "material": "floor", "vertices": [[-3, 0, -3], [-3, 0, 3], [3, 0, 3], [3, 0, -3]]},
  {"type": "quad", "material": "red", "vertices": [[-0.8, 0.1, -1], [0.4, 0.1, -1], [0.4, 1.0, -1], [-0.8, 1.0, -1]]},
  {"type": "quad", "material": "green", "vertices": [[-0.3, 0.3, -1], [0.8, 0.3, -1], [0.8, 1.2, -1], [-0.3, 1.2, -1]]},
  {"type": "quad", "material": "red", "vertices": [[1.1, 0.05, -0.2], [1.1, 0.35, -1.3], [2.1, 0.35, -1.3], [2.1, 0.05, -0.2]]},
  {"type": "quad", "material": "green", "vertices": [[1.3, 0.1, -0.38333333], [1.3, 0.3, -1.11666667], [2.3, 0.3, -1.11666667], [2.3, 0.1, -0.38333333]]}],
 "render": {"cube_resolution": 128}}
JSON
for scene in "$WORK/coplanar.json" "$REPO/tests/hard/regressions/coplanar_5000_85.json"; do
  name=$(basename "$scene" .json)
  for gl in $APIS; do
    if "$ABCUBE" crosscheck "$scene" --gl "$gl" --stats "$WORK/$name.stats.json" > "$WORK/out" 2>&1 &&
       python3 -c "import json,sys; c=json.load(open('$WORK/$name.stats.json'))['cube']; print('ties', c['tied'], 'alike', c['tied_agree']); sys.exit(0 if c['tied'] > 100 and c['tied_agree'] >= 0.99 * c['tied'] else 1)" \
         > "$WORK/ties" 2>&1; then
      passed=$((passed + 1))
      echo "ok   $name ($gl): $(cat "$WORK/ties")"
    else
      failed=$((failed + 1))
      echo "FAIL $name ($gl): $(cat "$WORK/ties" 2>/dev/null)"
      cat "$WORK/out"
    fi
  done
done
if "$ABCUBE" render "$REPO/scenes/hidden_point.json" -o "$WORK/ab.png" --method abuffer \
    --stats "$WORK/ab.json" 2> "$WORK/err" && grep -q '"bytes_per_fragment": 20' "$WORK/ab.json"; then
  passed=$((passed + 1))
else
  failed=$((failed + 1))
  echo "FAIL --method abuffer render: $(cat "$WORK/err")"
fi
if "$ABCUBE" render "$REPO/scenes/hidden_point.json" -o "$WORK/ab2.png" --method abuffer --max-memory 1 \
    > /dev/null 2> "$WORK/err"; then
  failed=$((failed + 1))
  echo "FAIL --max-memory 1 should refuse the A-buffer"
else
  status=$?
  if [ $status -eq 2 ] && grep -q "max-memory" "$WORK/err" && [ ! -e "$WORK/ab2.png" ]; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAIL --max-memory 1: status $status, $(cat "$WORK/err")"
  fi
fi
# The gpu method against the exact tracer on the repository scenes (full size, N = 256):
# measured 2026-11-21: hidden_point 25.0 dB, cornell 13.8, default 20.5, shadows 32.8;
# the floors are those less 2 dB (Blinn-Newell's parallax error is the method's own).
# Not in the checked builds (ABCUBE_CHECKED_BUILD, tools/sanitize.sh): these are accuracy
# figures at full size, whose code paths (the gpu method, the reference) the other tests
# run there; the ordinary build checks the figures.
cases="hidden_point:23.0 cornell:11.8 default:18.5 shadows:30.8"
[ "$CHECKED" = 1 ] && cases=""
for case in $cases; do
  scene=${case%%:*}
  floor=${case##*:}
  if "$ABCUBE" render "$REPO/scenes/$scene.json" -o "$WORK/g.png" --method gpu "${GL[@]}" --cube-res 256 --reference \
      --stats "$WORK/g.json" 2> "$WORK/err" &&
     python3 -c "import json,sys; p=json.load(open('$WORK/g.json'))['reference']['image_error']['psnr_db']; print('gpu $scene PSNR', p); sys.exit(0 if p >= $floor else 1)"; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAIL gpu $scene below $floor dB: $(cat "$WORK/err")"
  fi
done
# A small object at a low N: too few texels for a p99, and the verdict says so and what to do.
"$ABCUBE" crosscheck "$REPO/scenes/meshes/octahedron.obj" --cube-res 64 "${GL[@]}" --size 160x120 > "$WORK/few" 2>&1
if [ $? -eq 1 ] && tail -n 1 "$WORK/few" | grep -q "over few texels (.* covered on both, .*): raise --cube-res"; then
  passed=$((passed + 1))
else
  failed=$((failed + 1))
  echo "FAIL crosscheck at a low N does not say why: $(tail -n 1 "$WORK/few")"
fi
# A plane through the cube's centre: rays starting on it met their first texel at l = -0 on
# the GPU and +0 on the CPU, until the walk's max and min kept their comparison exact. Every
# walk is now identical, not only within rounding.
/usr/bin/python3 "$REPO/tools/hard_scenes.py" --seed 7171 --count 3 --out "$WORK/zero" > /dev/null
if "$ABCUBE" crosscheck "$WORK/zero/plane_through_camera_7171_2.json" "${GL[@]}" --stats "$WORK/zero.json" \
    > "$WORK/out" 2>&1 &&
   python3 -c "import json,sys; w=json.load(open('$WORK/zero.json'))['cube_walks']; sys.exit(0 if w['rays'] > 1000 and w['identical'] == w['rays'] else 1)"; then
  passed=$((passed + 1))
  echo "ok   signed zeros: $(grep '^GPU cube walks' "$WORK/out")"
else
  failed=$((failed + 1))
  echo "FAIL signed zeros: $(grep '^GPU cube walks' "$WORK/out")"
fi
echo "cli crosscheck_cli: $passed passed, $failed failed"
[ $failed -eq 0 ]
