#!/usr/bin/env bash
# The exact camera pass shaded once a pixel and surface (--gpu-shading pixels, the default;
# camera_groups.frag) against once a sample (--gpu-shading samples): on one scene of each
# flat-mirror template and of each hard-case template, for fixed seeds and for one seed new
# each run (printed), rendered small (128 x 96, where a pixel is widest), the gpu image shaded
# by pixels must be as near the exact tracer as the one shaded by samples, less 0.5 dB, or
# reach 60 dB (the shading point of a pixel is its samples' mean, a second-order change; the
# environment map's term is the mean of the samples' lookups, and a group seen too obliquely
# is shaded once a sample: docs/performance.md has the figures over
# many seeds); and the two images must agree to 40 dB. Then the stats name the technique, and a
# scene of 33 shadow-casting lights (a sample's key holds 32) falls back to samples, saying
# why. Usage (ctest runs it so): bash gpu_shading.sh /path/to/abcube /path/to/repo
# ABCUBE_SHADING_SEED=S repeats a run's new seed.
set -u
ABCUBE=$1
REPO=$2
CLI_TEST=gpu_shading
. "$(dirname "$0")/lib/check.sh"
. "$(dirname "$0")/lib/generated.sh"
SEED=${ABCUBE_SHADING_SEED:-$RANDOM}
echo "seeds: 1, 5, 11322, 11106 and $SEED (ABCUBE_SHADING_SEED=$SEED repeats this run)"
require_gl
for seed in 1 "$SEED"; do generate flat_mirror_scenes "$seed" 5 "$WORK/scenes"; done
# 11322 and 11106 failed before (found by the new seed in CI rehearsals): seams_11322_10
# when a curved mirror's environment was looked up once a group, km_scale_11106_9 when a
# floor's pixels at its horizon were shaded once (FORESHORTENING, camera_groups.frag).
for seed in 5 11322 11106 "$SEED"; do generate hard_scenes "$seed" 11 "$WORK/scenes"; done
# render_all NAME ARGS...: every scene in one batch, into $WORK/NAME/.
render_all() {
  local name=$1 scene
  shift
  : > "$WORK/$name.jsonl"
  for scene in "$WORK"/scenes/*.json; do
    echo "{\"scene\": \"$scene\", \"out\": \"$name/$(basename "$scene" .json).exr\"}" >> "$WORK/$name.jsonl"
  done
  "$ABCUBE" batch "$WORK/$name.jsonl" "$@" > /dev/null 2> "$WORK/$name.err"
  status=$?
  check "$name renders every scene ($(head -c 300 "$WORK/$name.err"))" [ $status -eq 0 ]
}
render_all raytrace --method raytrace
render_all samples --method gpu --gpu-shading samples
render_all pixels --method gpu
psnr() { "$ABCUBE" compare "$1" "$2" | awk '/^PSNR/ {print $2}'; }
for scene in "$WORK"/scenes/*.json; do
  stem=$(basename "$scene" .json)
  s=$(psnr "$WORK/samples/$stem.exr" "$WORK/raytrace/$stem.exr")
  p=$(psnr "$WORK/pixels/$stem.exr" "$WORK/raytrace/$stem.exr")
  a=$(psnr "$WORK/pixels/$stem.exr" "$WORK/samples/$stem.exr")
  echo "$stem: samples $s dB, pixels $p dB, apart $a dB"
  check "$stem: pixels as near the tracer as samples ($p against $s)" \
    awk -v p="$p" -v s="$s" 'BEGIN { exit !(p != "" && s != "" && (p == "inf" || p + 0 >= 60 || p + 0 >= s - 0.5)) }'
  check "$stem: pixels and samples agree to 40 dB ($a)" awk -v a="$a" 'BEGIN { exit !(a == "inf" || a + 0 >= 40) }'
done
# A textured scene under hybrid (textures point-sampled at each sample, as the CPU does): a
# pixel's texels are its samples' mean, not one texel at their centre (that gave 50.5 dB
# against the samples' 60.3).
for args in "raytrace" "hybrid" "hybrid --gpu-shading samples"; do
  # shellcheck disable=SC2086
  "$ABCUBE" render "$REPO/scenes/textured.json" -o "$WORK/textured_$(echo "$args" | tr -d ' -').exr" --method $args \
    2> /dev/null
done
s=$(psnr "$WORK/textured_hybridgpushadingsamples.exr" "$WORK/textured_raytrace.exr")
p=$(psnr "$WORK/textured_hybrid.exr" "$WORK/textured_raytrace.exr")
echo "textured (hybrid): samples $s dB, pixels $p dB"
check "textured: hybrid by pixels as near the tracer as by samples ($p against $s)" \
  awk -v p="$p" -v s="$s" 'BEGIN { exit !(p != "" && s != "" && p + 0 >= s - 0.5) }'
# technique NAME STATS WANT [WHY]: the stats' gpu_paths.shading.
technique() {
  check "$1: shading $3" /usr/bin/python3 -c "
import json, sys
s = json.load(open(sys.argv[1]))['gpu_paths']['shading']
sys.exit(not (s['technique'] == sys.argv[2] and sys.argv[3] in s['why']))" "$2" "$3" "${4:-}"
}
one="$WORK/scenes/$(ls "$WORK/scenes" | head -1)"
"$ABCUBE" render "$one" -o "$WORK/one.exr" --method gpu --stats "$WORK/one_pixels.json" 2> /dev/null
technique "default" "$WORK/one_pixels.json" pixels "once a pixel"
"$ABCUBE" render "$one" -o "$WORK/one.exr" --method gpu --gpu-shading samples --stats "$WORK/one_samples.json" 2> /dev/null
technique "asked for samples" "$WORK/one_samples.json" samples "asked"
"$ABCUBE" render "$one" -o "$WORK/one.exr" --method gpu --gpu-shading texels 2> "$WORK/err"
status=$?
check "an unknown shading is refused with exit 2 ($(head -c 200 "$WORK/err"))" [ $status -eq 2 ]
check "an unknown shading names itself" grep -q "gpu-shading" "$WORK/err"
# 33 shadow-casting lights round a quad with a box on it.
/usr/bin/python3 - "$WORK/lights33.json" <<'EOF'
import json, math, sys
lights = [{"type": "point", "position": [4 * math.cos(k / 33 * 2 * math.pi), 3, 4 * math.sin(k / 33 * 2 * math.pi)],
           "color": [0.03, 0.03, 0.03], "cast_shadows": True} for k in range(33)]
scene = {"version": 1,
         "camera": {"position": [0, 4, 6], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y": 45, "width": 64, "height": 48},
         "lights": lights, "materials": {"m": {"color": [0.8, 0.8, 0.8]}},
         "objects": [{"type": "quad", "vertices": [[-4, 0, -4], [-4, 0, 4], [4, 0, 4], [4, 0, -4]], "material": "m"},
                     {"type": "box", "min": [-0.5, 0, -0.5], "max": [0.5, 1, 0.5], "material": "m"}]}
json.dump(scene, open(sys.argv[1], "w"))
EOF
"$ABCUBE" render "$WORK/lights33.json" -o "$WORK/lights33.exr" --method gpu --stats "$WORK/lights33_stats.json" 2> "$WORK/err"
status=$?
check "33 lights render ($(head -c 200 "$WORK/err"))" [ $status -eq 0 ]
technique "33 volume lights" "$WORK/lights33_stats.json" samples "33 volume counts"
echo "gpu_shading: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
