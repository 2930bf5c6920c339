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

echo "gpu_abuffer: ${#scenes[@]} scenes; $passed passed, $failed failed"
[ "$failed" -eq 0 ]
