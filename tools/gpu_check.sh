#!/bin/sh
# The prepared check of a GPU machine: one run, a markdown report. It needs only the bundle
# (tools/bundle.sh) and a POSIX shell: no package, no network.
#   sh tools/gpu_check.sh BUNDLE REPORT.md [--quick]
# BUNDLE: the bundle's folder (OUT/abcube), or its archive OUT/abcube.tar.xz (unpacked
# beside the report first). --quick: small sizes and counts, for a rehearsal.
# Sections, each timed, each run on the EGL device (a GPU) and again on llvmpipe (Mesa's
# software rasteriser, the same machine's CPUs), for a side by side ratio; where no GPU is
# found, the GPU rows say "no device":
#   1. abcube info: the EGL devices found, GL_RENDERER and the driver's version
#   2. the GL tests (the bundle's test_gl, on EGL and OSMesa)
#   3. crosscheck of every repository scene, with the tolerances used on llvmpipe, the GPU's
#      A-buffer lists against the CPU's among them
#   4. the race: raytrace, abuffer, gpu, hybrid and gpu_abuffer at 640x480 and 1920x1080,
#      per-pass times
#   4b. gpu_abuffer against abuffer on every repository scene: the same bytes, build times
#   4c. gpu_abuffer with its searches on the GPU against them on the CPU (the GPU only)
#   5. the cube passes and the A-buffer build at N = 512, 1024, 2048, 4096
#   6. 1000 renders in one process (abcube batch): time per render and peak memory
# A section that fails is reported as failed and the check goes on; the exit status is 1
# when any did. The whole stays within GPU_CHECK_BUDGET_S (default 420 s): past it, the
# remaining runs are listed as skipped, so that one device session holds the check.
set -u
[ $# -ge 2 ] || { echo "usage: sh tools/gpu_check.sh BUNDLE REPORT.md [--quick]" >&2; exit 2; }
BUNDLE=$1
REPORT=$2
QUICK=${3:-}
mkdir -p "$(dirname "$REPORT")"
OUT=$(cd "$(dirname "$REPORT")" && pwd)/gpu_check_work
mkdir -p "$OUT"
case $BUNDLE in
  *.tar.xz)
    tar -C "$OUT" -xJf "$BUNDLE" || { echo "gpu_check: cannot unpack $BUNDLE" >&2; exit 2; }
    BUNDLE=$OUT/abcube
    ;;
esac
A=$BUNDLE/bin/abcube
SCENES=$BUNDLE/scenes
[ -x "$A" ] || { echo "gpu_check: no $A" >&2; exit 2; }
failures=0
start=$(date +%s)
BUDGET=${GPU_CHECK_BUDGET_S:-420}
over_budget() { [ $(($(date +%s) - start)) -ge "$BUDGET" ]; }
say() { printf '%s\n' "$*" >> "$REPORT"; }
elapsed() { echo $(($(date +%s) - start)); }
# fenced OUTPUT: the output of a command in a code block
fenced() { say '```text'; cat "$1" >> "$REPORT"; say '```'; }
# json_ms FILE KEY: a time from a stats file's timings_ms ("KEY": value), or "-"
json_ms() { sed -n '/"timings_ms"/,/}/p' "$1" | sed -n "s/.*\"$2\": \([0-9][0-9.e+-]*\).*/\1/p" | head -n 1 | awk '{ v = $1 } END { if (v == "") print "-"; else printf "%.1f", v }'; }

if [ "$QUICK" = --quick ]; then
  SIZES="160x120"; NS="64 128"; RENDERS=20
else
  SIZES="640x480 1920x1080"; NS="512 1024 2048 4096"; RENDERS=1000
fi

: > "$REPORT"
say "# GPU check"
say ""
say "\`sh tools/gpu_check.sh\` $QUICK, $(date -u +%Y-%m-%dT%H:%MZ), $(uname -m), $(nproc) cores."
say ""

# 1. What is here.
say "## 1. abcube info"
"$A" info > "$OUT/info.txt" 2>&1 || failures=$((failures + 1))
fenced "$OUT/info.txt"
device=none
if grep -q "egl-device [0-9]* *yes" "$OUT/info.txt" && ! grep -q "software device" "$OUT/info.txt"; then
  device=egl-device
fi
renderer=$(sed -n 's/ *GL_RENDERER: *//p' "$OUT/info.txt" | head -n 1)
say ""
if [ $device = none ]; then
  say "No GPU found through EGL's device platform: the GPU rows below say \"no device\"."
else
  say "GPU: $renderer (EGL device)."
fi
say ""

# PATHS: each GL path a section runs on, its label and its --gl.
paths() {
  if [ $device = none ]; then echo "llvmpipe:egl-surfaceless"; else echo "gpu:egl-device llvmpipe:osmesa"; fi
}

# 2. The GL tests.
say "## 2. The GL tests"
say ""
for api in egl osmesa; do
  ABCUBE_TEST_GL=$api "$BUNDLE/bin/test_gl" > "$OUT/gl_$api.txt" 2>&1
  status=$?
  [ $status -eq 0 ] || failures=$((failures + 1))
  say "- $api: $(grep -E '^\[  (PASSED|FAILED) ' "$OUT/gl_$api.txt" | tr '\n' ' ') (exit $status)"
done
say ""

# 3. crosscheck.
say "## 3. crosscheck of every repository scene"
say ""
say "| scene | path | result | seconds |"
say "|---|---|---|---|"
for scene in "$SCENES"/*.json; do
  name=$(basename "$scene" .json)
  if over_budget; then say "| $name | | skipped: over the time budget | |"; continue; fi
  for p in $(paths); do
    label=${p%%:*}; gl=${p#*:}
    t0=$(date +%s)
    "$A" crosscheck "$scene" --gl "$gl" --cube-res 128 > "$OUT/cc_${name}_$label.txt" 2>&1
    status=$?
    [ $status -eq 0 ] || failures=$((failures + 1))
    result=passed; [ $status -eq 0 ] || result="**failed** ($(tail -n 1 "$OUT/cc_${name}_$label.txt"))"
    say "| $name | $label | $result | $(($(date +%s) - t0)) |"
  done
  [ $device = none ] && say "| $name | gpu | no device | |"
done
say ""

# 4. The race.
say "## 4. The race (cornell.json)"
say ""
say "| size | method | path | total ms | passes (ms) |"
say "|---|---|---|---|---|"
for size in $SIZES; do
  for method in raytrace abuffer gpu hybrid gpu_abuffer; do
    for p in $(paths); do
      label=${p%%:*}; gl=${p#*:}
      [ "$method" = raytrace ] || [ "$method" = abuffer ] && [ "$label" = gpu ] && continue
      if over_budget; then say "| $size | $method | $label | skipped: over the time budget | |"; continue; fi
      stats=$OUT/race_${size}_${method}_$label.json
      n=""; [ $method = raytrace ] || n="--cube-res 512"
      "$A" render "$SCENES/cornell.json" -o "$OUT/race.png" --size "$size" --method "$method" --gl "$gl" $n \
        --stats "$stats" > "$OUT/race.log" 2>&1 || { failures=$((failures + 1)); say "| $size | $method | $label | **failed** | |"; continue; }
      passes=$(sed -n '/"timings_ms"/,/}/p' "$stats" | grep -v timings_ms | tr -d ' "},' | awk -F: 'NF == 2 {printf "%s%s %.0f", sep, $1, $2; sep = ", "}')
      say "| $size | $method | $label | $(json_ms "$stats" total) | $passes |"
    done
    if [ $device = none ] && [ $method != raytrace ] && [ $method != abuffer ]; then say "| $size | $method | gpu | no device | |"; fi
  done
done
say ""

# 4b. gpu_abuffer against abuffer: the A-buffers built by the GPU must give abuffer's image.
say "## 4b. gpu_abuffer against abuffer (${SIZES%% *}, N = 512)"
say ""
say "| scene | path | the same bytes | camera A-buffer ms (CPU) | cube A-buffer ms (CPU) |"
say "|---|---|---|---|---|"
for scene in "$SCENES"/*.json; do
  name=$(basename "$scene" .json)
  if over_budget; then say "| $name | | skipped: over the time budget | | |"; continue; fi
  "$A" render "$scene" -o "$OUT/ab_cpu.exr" --size "${SIZES%% *}" --cube-res 512 --method abuffer \
    --stats "$OUT/ab_cpu.json" > "$OUT/ab.log" 2>&1 || { failures=$((failures + 1)); say "| $name | cpu | **failed** | | |"; continue; }
  for p in $(paths); do
    label=${p%%:*}; gl=${p#*:}
    if ! "$A" render "$scene" -o "$OUT/ab_gpu.exr" --size "${SIZES%% *}" --cube-res 512 --method gpu_abuffer --gl "$gl" \
        --stats "$OUT/ab_gpu.json" > "$OUT/ab.log" 2>&1; then
      failures=$((failures + 1)); say "| $name | $label | **failed** ($(tail -n 1 "$OUT/ab.log")) | | |"; continue
    fi
    same=yes
    cmp -s "$OUT/ab_cpu.exr" "$OUT/ab_gpu.exr" || same="no: $("$A" compare "$OUT/ab_gpu.exr" "$OUT/ab_cpu.exr" | tr '\n' ' ')"
    say "| $name | $label | $same | $(json_ms "$OUT/ab_gpu.json" camera_abuffer) ($(json_ms "$OUT/ab_cpu.json" camera_abuffer)) | $(json_ms "$OUT/ab_gpu.json" cube_abuffer) ($(json_ms "$OUT/ab_cpu.json" cube_abuffer)) |"
  done
  [ $device = none ] && say "| $name | gpu | no device | | |"
done
say ""

# 4c. The searches on the GPU, and the resolve planned there: gpu_abuffer --search-on gpu
# --resolve-on gpu against both on the CPU, on the GPU only (llvmpipe's scan of a 640x480 image takes minutes; bench/gpu_searches.py measures it).
say "## 4c. gpu_abuffer --search-on gpu --resolve-on gpu against both on the CPU (${SIZES%% *}, N = 512)"
say ""
say "| scene | the same bytes | total ms, on the GPU | GPU scan ms | GPU resolve plan ms | searches.deferred | total ms, on the CPU |"
say "|---|---|---|---|---|---|---|"
for scene in "$SCENES"/*.json; do
  name=$(basename "$scene" .json)
  if [ $device = none ]; then say "| $name | no device | | | | | |"; continue; fi
  if over_budget; then say "| $name | skipped: over the time budget | | | | | |"; continue; fi
  ok=yes
  for on in cpu gpu; do
    "$A" render "$scene" -o "$OUT/so_$on.exr" --size "${SIZES%% *}" --cube-res 512 --method gpu_abuffer \
      --search-on $on --resolve-on $on --gl egl-device --stats "$OUT/so_$on.json" > "$OUT/so.log" 2>&1 || ok=no
  done
  if [ $ok = no ]; then failures=$((failures + 1)); say "| $name | **failed** ($(tail -n 1 "$OUT/so.log")) | | | | | |"; continue; fi
  same=yes
  cmp -s "$OUT/so_cpu.exr" "$OUT/so_gpu.exr" || same="no: $("$A" compare "$OUT/so_gpu.exr" "$OUT/so_cpu.exr" | tr '\n' ' ')"
  deferred=$(tr -d ' \n' < "$OUT/so_gpu.json" | sed -n 's/.*"deferred":{\([^}]*\)}.*/\1/p' | tr ',' ' ')
  say "| $name | $same | $(json_ms "$OUT/so_gpu.json" total) | $(json_ms "$OUT/so_gpu.json" gpu_search_scan) | $(json_ms "$OUT/so_gpu.json" gpu_resolve_plan) | $deferred | $(json_ms "$OUT/so_cpu.json" total) |"
done
say ""

# 5. The cube passes against N.
say "## 5. The cube passes and the A-buffer build against N (cornell.json, 160x120)"
say ""
say "| N | path | gpu: environment map ms | gpu: shadow maps ms | abuffer: cube A-buffer ms |"
say "|---|---|---|---|---|"
for n in $NS; do
  if over_budget; then say "| $n | | skipped: over the time budget | | |"; continue; fi
  "$A" render "$SCENES/cornell.json" -o "$OUT/n.png" --size 160x120 --cube-res "$n" --method abuffer \
    --stats "$OUT/n_abuffer.json" > "$OUT/n.log" 2>&1 || failures=$((failures + 1))
  for p in $(paths); do
    label=${p%%:*}; gl=${p#*:}
    "$A" render "$SCENES/cornell.json" -o "$OUT/n.png" --size 160x120 --cube-res "$n" --method gpu --gl "$gl" \
      --gpu-mirrors envmap --gpu-shadows maps --stats "$OUT/n_$label.json" > "$OUT/n.log" 2>&1 || failures=$((failures + 1))
    say "| $n | $label | $(json_ms "$OUT/n_$label.json" environment_map) | $(json_ms "$OUT/n_$label.json" shadow_maps) | $(json_ms "$OUT/n_abuffer.json" cube_abuffer) |"
  done
done
say ""

# 6. Many renders in one process.
say "## 6. $RENDERS renders in one process (abcube batch, cornell.json at 64x48)"
say ""
say "| path | wall s | per render ms | peak RSS MB |"
say "|---|---|---|---|"
for p in $(paths); do
  label=${p%%:*}; gl=${p#*:}
  if over_budget; then say "| $label | skipped: over the time budget | | |"; continue; fi
  jobs=$OUT/jobs_$label.jsonl
  : > "$jobs"
  i=0
  while [ $i -lt "$RENDERS" ]; do
    last=""
    [ $i -eq $((RENDERS - 1)) ] && last=", \"stats\": \"$OUT/batch_$label.json\""
    echo "{\"scene\": \"$SCENES/cornell.json\", \"out\": \"$OUT/batch_$label/$((i % 4)).png\", \"method\": \"gpu\", \"width\": 64, \"height\": 48, \"cube_res\": 64$last}" >> "$jobs"
    i=$((i + 1))
  done
  t0=$(date +%s)
  "$A" batch "$jobs" --gl "$gl" > "$OUT/batch_$label.txt" 2>&1 || failures=$((failures + 1))
  wall=$(($(date +%s) - t0))
  per=$(sed -n 's/.*; \([0-9.]*\) ms per render.*/\1/p' "$OUT/batch_$label.txt")
  rss=$(sed -n 's/.*"peak_rss_bytes": \([0-9]*\).*/\1/p' "$OUT/batch_$label.json" 2>/dev/null | head -n 1)
  say "| $label | $wall | ${per:--} | $( [ -n "$rss" ] && echo $((rss / 1048576)) || echo -) |"
done
say ""
say "Whole check: $(elapsed) s, $failures failed section(s)."
echo "gpu_check: $REPORT ($(elapsed) s, $failures failed)"
[ $failures -eq 0 ]
