#!/usr/bin/env bash
# What each method honours (docs/methods.md): every
# option given to a method that has no use for it is refused with one line naming it (exit
# 2, nothing written); the gpu method honours max_depth 0, --envmap-lookup, --fresnel,
# --plan everything and coverage transparency, draws glass shadows as the CPU does, and
# agrees with abuffer at max_depth 0 (>= 30 dB).
# Usage (ctest runs it so): bash method_options.sh /path/to/abcube /path/to/repo
set -u
ABCUBE=$1
CLI_TEST=method_options
. "$(dirname "$0")/lib/check.sh"

# A floor, a mirror box, a glass ball casting a shadow, one light.
cat > "$WORK/s.json" <<'JSON'
{ "version": 1,
  "camera": {"position": [0, 1.4, 3.2], "look_at": [0, 0.4, 0], "fov_y": 50, "width": 64, "height": 48},
  "background": [0.1, 0.1, 0.3], "ambient": [0.15, 0.15, 0.15],
  "lights": [{"type": "point", "position": [0.5, 3, 1], "color": [1, 1, 1]}],
  "materials": {"mirror": {"color": [0.1, 0.1, 0.1], "reflect": 0.8},
                "glass": {"color": [1, 0.8, 0.6], "diffuse": 0, "specular": 0.5, "transmit": 0.9, "ior": 1.5}},
  "objects": [
    {"type": "quad", "vertices": [[-3,0,-3],[-3,0,3],[3,0,3],[3,0,-3]]},
    {"type": "sphere", "center": [0.2, 0.6, 0.3], "radius": 0.4, "segments": 24, "material": "glass"},
    {"type": "box", "min": [-1.2, 0, -1], "max": [-0.6, 1, -0.4], "material": "mirror"}
  ],
  "render": {"cube_resolution": 128, "max_depth": 2} }
JSON
sed 's/"glass": {/"veil": {"color": [0.2, 0.4, 1], "opacity": 0.5}, "glass": {/; s/"material": "glass"/"material": "veil"/' \
  "$WORK/s.json" > "$WORK/veil.json"

# refused: METHOD OPTION... -> exit 2, one line naming the option, no output
refused() {
  local method=$1 name=$2; shift 2
  "$ABCUBE" render "$WORK/s.json" -o "$WORK/x.png" --method "$method" "$@" > /dev/null 2> "$WORK/err"
  local status=$?
  check "$method $* exits 2 (got $status)" [ $status -eq 2 ]
  check "$method $*: one line" [ "$(wc -l < "$WORK/err")" -eq 1 ]
  check "$method $*: names '$name' ($(cat "$WORK/err"))" grep -q -- "--$name: not used by method $method" "$WORK/err"
  check "$method $*: nothing written" [ ! -e "$WORK/x.png" ]
}
refused raytrace cube-res --cube-res 64
refused raytrace error-target --error-target 0.001
for m in zbuffer envmap gpu hybrid; do refused $m target-db --target-db 40; done
for m in abuffer zbuffer envmap gpu hybrid; do refused $m samples --samples 4; done
refused raytrace plan --plan everything
for m in raytrace gpu; do
  refused $m search --search thesis
  refused $m refine --refine plane
  refused $m theta-max --theta-max 3
  refused $m map-only --map-only
  refused $m resolve --resolve thesis
  refused $m max-layers --max-layers 2
  refused $m refraction --refraction thick_lens
done
refused envmap refraction --refraction thin_lens
refused raytrace envmap-lookup --envmap-lookup bisector
refused abuffer envmap-lookup --envmap-lookup bisector
refused zbuffer envmap-lookup --envmap-lookup position

# honoured by gpu: each option changes the image, or the plan
render() { "$ABCUBE" render "$WORK/s.json" --threads 2 "$@" > /dev/null 2> "$WORK/err" || bad "render $* ($(cat "$WORK/err"))"; }
differ() { ! "$ABCUBE" compare "$1" "$2" --exact > /dev/null 2>&1; }
render -o "$WORK/gpu.exr" --method gpu
render -o "$WORK/gpu_bisector.exr" --method gpu --envmap-lookup bisector
render -o "$WORK/gpu_fresnel.exr" --method gpu --fresnel
check "gpu honours --envmap-lookup" differ "$WORK/gpu.exr" "$WORK/gpu_bisector.exr"
check "gpu honours --fresnel" differ "$WORK/gpu.exr" "$WORK/gpu_fresnel.exr"
render -o "$WORK/gpu0.exr" --method gpu --max-depth 0 --stats "$WORK/g0.json"
render -o "$WORK/gpu0e.exr" --method gpu --max-depth 0 --plan everything --stats "$WORK/g0e.json"
check "gpu --max-depth 0 skips the environment map" grep -q '"pass": "environment_map"' "$WORK/g0.json"
check "gpu --plan everything builds it" grep -q '"environment_map (unused: --plan everything)"' "$WORK/g0e.json"
same() { "$ABCUBE" compare "$1" "$2" --exact > /dev/null 2>&1; }
check "gpu --plan everything: the same image" same "$WORK/gpu0.exr" "$WORK/gpu0e.exr"
check "gpu counts two translucent shadow layers" grep -q '"shadow_translucent_layers": 2' "$WORK/g0.json"

# gpu agrees with abuffer at max_depth 0 (issue 12: >= 30 dB), glass or veil (coverage
# transparency, peeled by the gpu camera pass)
render -o "$WORK/ab0.exr" --method abuffer --max-depth 0
at_least_30() {
  local psnr
  psnr=$("$ABCUBE" compare "$1" "$2" | awk '/PSNR/ {print $2}')
  check "$3: gpu vs abuffer at max_depth 0: $psnr dB >= 30" awk -v p="$psnr" 'BEGIN { exit !(p >= 30) }'
}
at_least_30 "$WORK/gpu0.exr" "$WORK/ab0.exr" "glass ball"
"$ABCUBE" render "$WORK/veil.json" -o "$WORK/veil_gpu0.exr" --method gpu --max-depth 0 --stats "$WORK/v.json" 2> "$WORK/err"
status=$?
check "gpu draws a veil ($(cat "$WORK/err"))" [ $status -eq 0 ]
check "gpu peels the veil's layers" grep -q '"camera_layers": [2-9]' "$WORK/v.json"
"$ABCUBE" render "$WORK/veil.json" -o "$WORK/veil_ab0.exr" --method abuffer --max-depth 0 2> /dev/null
at_least_30 "$WORK/veil_gpu0.exr" "$WORK/veil_ab0.exr" "veil ball"

echo "method_options: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
