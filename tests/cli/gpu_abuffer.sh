#!/usr/bin/env bash
# The gpu_abuffer method (its A-buffers built by GL compute shaders) against abuffer (built by
# the CPU core): on every repository scene and on generated hard cases (tools/hard_scenes.py,
# every template for a fixed seed and for one seed new each run, printed: 24 scenes), one
# batch per method at 80 x 60 with a 64-texel cube map, each image byte for byte the
# abuffer's. The lists are the CPU's bit for bit where GL's doubles round as IEEE 754 says
# (llvmpipe does), so the searches, the shading and the resolve over them are too: a
# difference is a wrong list, never a tolerance. Then the doors: `abcube render --method
# gpu_abuffer` with its stats (the GL it built on, both A-buffers' figures), a scene file's
# render.method, Python's render(method=...), and its options: abuffer's, others refused.
# Then the same with the searches on the GPU (--search-on gpu) and the resolve planned there
# (--resolve-on gpu), on the same scenes at 40 x 30, through the command line, batch and Python (a scene file names the method alone, as for
# every method's options), and under a memory budget its answers fill.
# In the checked builds (ABCUBE_CHECKED_BUILD, tools/sanitize.sh) the same commands run on
# cornell and three generated scenes, and Python is left out (those builds make no module).
# Usage (ctest runs it so): bash gpu_abuffer.sh /path/to/abcube /path/to/repo
# ABCUBE_GPU_ABUFFER_SEED=S repeats a run's new seed.
set -u
ABCUBE=$1
REPO=$2
CLI_TEST=gpu_abuffer
. "$(dirname "$0")/lib/check.sh"
. "$(dirname "$0")/lib/generated.sh"
PY=/usr/bin/python3
SEED=${ABCUBE_GPU_ABUFFER_SEED:-$RANDOM}
echo "generated scenes: seeds 7 and $SEED (ABCUBE_GPU_ABUFFER_SEED=$SEED repeats this run)"
require_gl

CHECKED=${ABCUBE_CHECKED_BUILD:-0}
scenes=("$REPO"/scenes/*.json "$REPO"/scenes/models/*.json)
seeds=(7 "$SEED")
count=12
if [ "$CHECKED" = 1 ]; then scenes=("$REPO/scenes/cornell.json"); seeds=(7); count=3; fi
for seed in "${seeds[@]}"; do
  $PY "$REPO/tools/hard_scenes.py" --seed "$seed" --count "$count" --out "$WORK/gen_$seed" > /dev/null ||
    { echo "FAIL: tools/hard_scenes.py --seed $seed"; exit 1; }
  scenes+=("$WORK/gen_$seed"/*.json)
done
echo "scenes: ${#scenes[@]}"

for method in abuffer gpu_abuffer; do
  : > "$WORK/$method.jsonl"
  for s in "${scenes[@]}"; do
    stem=$(basename "$(dirname "$s")")_$(basename "$s" .json)
    echo "{\"scene\": \"$s\", \"out\": \"$method/$stem.exr\", \"method\": \"$method\", \"cube_res\": 64, \"camera\": {\"width\": 80, \"height\": 60}}" \
      >> "$WORK/$method.jsonl"
  done
  (cd "$WORK" && "$ABCUBE" batch "$method.jsonl" > "$method.out" 2> "$method.err")
  check "batch of $method exits 0 ($(grep -v warning "$WORK/$method.err" | head -2))" [ $? -eq 0 ]
done
differ=0
for f in "$WORK"/abuffer/*.exr; do
  name=$(basename "$f")
  if ! cmp -s "$f" "$WORK/gpu_abuffer/$name"; then
    differ=$((differ + 1))
    echo "differs: $name: $("$ABCUBE" compare "$WORK/gpu_abuffer/$name" "$f" | tr '\n' ' ')"
  fi
done
written=$(ls "$WORK"/gpu_abuffer/*.exr 2> /dev/null | wc -l)
check "every scene rendered by gpu_abuffer ($written of ${#scenes[@]})" [ "$written" -eq "${#scenes[@]}" ]
check "every gpu_abuffer image is abuffer's, byte for byte ($differ differ)" [ "$differ" -eq 0 ]

# The CLI's render and its stats: the GL it ran on, both A-buffers' figures.
CORNELL=$REPO/scenes/cornell.json
check "render --method gpu_abuffer" "$ABCUBE" render "$CORNELL" --method gpu_abuffer --size 64x48 --cube-res 48 \
  -o "$WORK/c.exr" --stats "$WORK/c.json"
check "its stats: the GL path, both A-buffers" $PY -c 'import json, sys
s = json.load(open(sys.argv[1]))
assert s["method"] == "gpu_abuffer", s["method"]
assert s["gl"]["path"] != "none", s["gl"]
assert s["abuffer"]["fragments"] > 0 and s["cube_abuffer"]["fragments"] > 0' "$WORK/c.json"
check "abuffer renders it alike" "$ABCUBE" render "$CORNELL" --method abuffer --size 64x48 --cube-res 48 \
  -o "$WORK/a.exr"
check "the same bytes as abuffer" cmp "$WORK/c.exr" "$WORK/a.exr"
"$ABCUBE" render "$CORNELL" --method gpu_abuffer --gl none -o "$WORK/x.exr" 2> "$WORK/err"
status=$?
check "with --gl none: exit 2 ($status), one line naming GL ($(cat "$WORK/err"))" \
  bash -c "[ $status -eq 2 ] && [ \$(wc -l < '$WORK/err') -eq 1 ] && grep -q 'needs OpenGL' '$WORK/err'"
check "and no image" [ ! -e "$WORK/x.exr" ]
"$ABCUBE" render "$CORNELL" --method gpu_abuffer --samples 4 -o "$WORK/x.exr" 2> "$WORK/err"
status=$?
check "--samples refused: exit 2 ($status), naming the method ($(cat "$WORK/err"))" \
  bash -c "[ $status -eq 2 ] && grep -q -- '--samples: not used by method gpu_abuffer' '$WORK/err'"
check "--target-db taken" "$ABCUBE" render "$CORNELL" --method gpu_abuffer --size 48x36 --target-db 30 -o "$WORK/t.exr"

# A scene file's render.method.
$PY -c 'import json, sys
s = json.load(open(sys.argv[1]))
s["render"]["method"] = "gpu_abuffer"
json.dump(s, open(sys.argv[2], "w"))' "$CORNELL" "$WORK/scene.json"
check "render.method gpu_abuffer" "$ABCUBE" render "$WORK/scene.json" --size 64x48 --cube-res 48 -o "$WORK/s.exr"
check "the same image as --method gpu_abuffer" cmp "$WORK/s.exr" "$WORK/c.exr"

# Python.
[ "$CHECKED" = 1 ] || check "Python: render(method=\"gpu_abuffer\") is the CLI's image" \
  env PYTHONPATH="$(dirname "$ABCUBE")/python" $PY -c 'import sys, abcube
import numpy as np
img = abcube.Renderer().render(abcube.load_scene(sys.argv[1]), method="gpu_abuffer", width=64, height=48,
                               cube_res=48)
assert np.array_equal(img, abcube.read_image(sys.argv[2])), "differs"' "$CORNELL" "$WORK/c.exr"

# The searches on the GPU (--search-on gpu: GL's candidate scans, answered by the deferred
# searches): the same scenes, smaller (each render runs its passes, and llvmpipe walks
# slowly), one batch through both methods; each image abuffer's byte for byte. Then its
# stats, the other doors, and what it refuses.
gpu_scenes=("${scenes[@]}")
[ "$CHECKED" = 1 ] && gpu_scenes=("$REPO/scenes/cornell.json")
: > "$WORK/searches.jsonl"
for s in "${gpu_scenes[@]}"; do
  stem=searches/$(basename "$(dirname "$s")")_$(basename "$s" .json)
  for m in abuffer gpu; do
    method=$([ $m = gpu ] && echo gpu_abuffer || echo abuffer)
    on=$([ $m = gpu ] && echo ', "search_on": "gpu", "resolve_on": "gpu"')
    echo "{\"scene\": \"$s\", \"out\": \"${stem}_$m.exr\", \"method\": \"$method\"$on, \"cube_res\": 32, \"camera\": {\"width\": 40, \"height\": 30}}" \
      >> "$WORK/searches.jsonl"
  done
done
(cd "$WORK" && "$ABCUBE" batch searches.jsonl > searches.out 2> searches.err)
check "batch with search_on gpu exits 0 ($(grep -v warning "$WORK/searches.err" | head -2))" [ $? -eq 0 ]
differ=0
for s in "${gpu_scenes[@]}"; do
  stem=$WORK/searches/$(basename "$(dirname "$s")")_$(basename "$s" .json)
  cmp -s "${stem}_abuffer.exr" "${stem}_gpu.exr" || { differ=$((differ + 1)); echo "differs: $stem"; }
done
check "every image with the searches on the GPU is abuffer's, byte for byte (${#gpu_scenes[@]} scenes, $differ differ)" \
  [ "$differ" -eq 0 ]
check "render --search-on gpu --resolve-on gpu" "$ABCUBE" render "$CORNELL" --method gpu_abuffer --search-on gpu \
  --resolve-on gpu --size 40x30 --cube-res 32 -o "$WORK/g.exr" --stats "$WORK/g.json"
check "the batch's image" cmp "$WORK/g.exr" "$WORK/searches/scenes_cornell_gpu.exr"
check "its stats: searches on the GPU, in passes, every answer from a scan; every pixel's resolve planned there" \
  $PY -c 'import json, sys
s = json.load(open(sys.argv[1]))
assert s["plan"]["searches_on"] == {"where": "gpu", "why": "asked: --search-on gpu"}, s["plan"]["searches_on"]
assert s["plan"]["resolve_on"] == {"where": "gpu", "why": "asked: --resolve-on gpu"}, s["plan"]["resolve_on"]
p = s["resolve_plan"]
assert p["pixels"] == 1200 and p["planned"] == 1200 and p["steps"] >= 1200, p
d = s["searches"]["deferred"]
assert d["passes"] >= 2 and d["rays"] > 1000 and d["answers_used"] > 1000, d
assert s["timings_ms"]["gpu_search_scan"] > 0, s["timings_ms"]' "$WORK/g.json"
check "--search-on auto on llvmpipe: the CPU, and why" bash -c "'$ABCUBE' render '$CORNELL' --method gpu_abuffer \
  --size 40x30 --cube-res 32 -o '$WORK/u.exr' --stats '$WORK/u.json' &&
  [ \$(grep -c 'GL is software' '$WORK/u.json') -eq 2 ] &&
  cmp '$WORK/u.exr' '$WORK/g.exr'"
[ "$CHECKED" = 1 ] || check "Python: render(search_on=\"gpu\") is the CLI's image" \
  env PYTHONPATH="$(dirname "$ABCUBE")/python" $PY -c 'import sys, abcube
import numpy as np
img = abcube.Renderer().render(abcube.load_scene(sys.argv[1]), method="gpu_abuffer", search_on="gpu",
                               resolve_on="gpu", width=40,
                               height=30, cube_res=32)
assert np.array_equal(img, abcube.read_image(sys.argv[2])), "differs"' "$CORNELL" "$WORK/g.exr"
check "--max-memory 20 (MiB): the scan's batches smaller, the answers' store full, the rest walked on the CPU, \
the same image" bash -c "
  '$ABCUBE' render '$CORNELL' --method gpu_abuffer --search-on gpu --resolve-on gpu --size 40x30 --cube-res 32 \
    --max-memory 20 -o '$WORK/m.exr' --stats '$WORK/m.json' && cmp '$WORK/m.exr' '$WORK/g.exr' &&
  $PY -c 'import json, sys
d = json.load(open(sys.argv[1]))[\"searches\"][\"deferred\"]
assert d[\"walked_now\"] > 0 and d[\"bytes\"] + d[\"scan_bytes\"] <= 20 << 20, d' '$WORK/m.json'"
check "hybrid --search-on gpu --resolve-on gpu: hybrid's image with both on the CPU" bash -c "'$ABCUBE' render \
  '$CORNELL' --method hybrid --search-on gpu --resolve-on gpu --size 40x30 --cube-res 32 -o '$WORK/h_gpu.exr' \
  --stats '$WORK/h.json' &&
  '$ABCUBE' render '$CORNELL' --method hybrid --search-on cpu --resolve-on cpu --size 40x30 --cube-res 32 \
    -o '$WORK/h_cpu.exr' &&
  cmp '$WORK/h_gpu.exr' '$WORK/h_cpu.exr' && [ \$(grep -c '\"where\": *\"gpu\"' '$WORK/h.json') -ge 2 ]"
check "abcube report: gpu_abuffer with its searches on the GPU, a method beside abuffer, the same error" bash -c "
  '$ABCUBE' report '$CORNELL' -o '$WORK/report' --methods abuffer,gpu_abuffer --search-on gpu --size 32x24 \
    --cube-res 24 --no-crosscheck > /dev/null &&
  $PY -c 'import json, sys
r = json.load(open(sys.argv[1] + \"/report.json\"))
a, g = r[\"methods\"][\"abuffer\"], r[\"methods\"][\"gpu_abuffer\"]
assert a[\"error\"] == g[\"error\"], (a[\"error\"], g[\"error\"])
s = json.load(open(sys.argv[1] + \"/\" + g[\"stats\"]))
assert s[\"plan\"][\"searches_on\"][\"where\"] == \"gpu\", s[\"plan\"]' '$WORK/report'"
refused() {  # WHAT PATTERN ARGS...: exit 2, one line matching PATTERN, no image
  local what=$1 pattern=$2 status
  shift 2
  rm -f "$WORK/r.exr"
  "$ABCUBE" render "$CORNELL" "$@" -o "$WORK/r.exr" 2> "$WORK/err"
  status=$?
  check "$what refused: exit 2 ($status), one line ($(cat "$WORK/err"))" \
    bash -c "[ $status -eq 2 ] && [ \$(wc -l < '$WORK/err') -eq 1 ] && grep -q -- '$pattern' '$WORK/err' &&
      [ ! -e '$WORK/r.exr' ]"
}
refused "--search-on gpu with the thesis mode" "--search-on: gpu takes the crossing mode only" --method gpu_abuffer --search-on gpu --search thesis
refused "--search-on with abuffer" "--search-on: not used by method abuffer" --method abuffer --search-on gpu
refused "--search-on elsewhere" "--search-on" --method gpu_abuffer --search-on gpus
refused "--resolve-on with abuffer" "--resolve-on: not used by method abuffer" --method abuffer --resolve-on gpu
refused "--resolve-on gpu in too little memory" "GPU resolve plan: its .* steps .* over the memory budget" \
  --method gpu_abuffer --resolve-on gpu --search-on cpu --size 320x240 --cube-res 32 --max-memory 24
refused "--search-on gpu in too little memory" "search scan needs .* above --max-memory 8 MiB" \
  --method gpu_abuffer --search-on gpu --size 40x30 --cube-res 32 --max-memory 8

echo "gpu_abuffer: ${#scenes[@]} scenes; $passed passed, $failed failed"
[ "$failed" -eq 0 ]
