#!/usr/bin/env bash
# The abcube program end to end: render through each GL path, stats, forced-path failures,
# atomic outputs, compare's exit codes and heatmap, export-pov, info (cli.md).
# Usage (ctest runs it so): bash render_cli.sh /path/to/abcube /path/to/repo
set -u
ABCUBE=$1
REPO=$2
CLI_TEST=render_cli
. "$(dirname "$0")/lib/check.sh"

# A small scene: a mirror, a red and a green triangle, a floor, one light.
cat > "$WORK/small.json" <<'JSON'
{ "version": 1,
  "camera": {"position": [0, 1, 4], "look_at": [0, 0.5, 0], "fov_y": 50, "width": 48, "height": 36},
  "background": [0.1, 0.1, 0.3], "ambient": [0.2, 0.2, 0.2],
  "lights": [{"type": "point", "position": [2, 4, 3], "color": [1, 1, 1]}],
  "materials": {"red": {"color": [0.9, 0.1, 0.1]}, "mirror": {"color": [0.1, 0.1, 0.1], "reflect": 0.8}},
  "objects": [
    {"type": "quad", "vertices": [[-3,0,-3],[-3,0,3],[3,0,3],[3,0,-3]]},
    {"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5, "segments": 16, "material": "red"},
    {"type": "box", "min": [0.8, 0, -1], "max": [1.2, 1, 0], "material": "mirror"}
  ] }
JSON

# --- render through each forced GL path; stats name the path and renderer
for gl in egl osmesa egl-surfaceless auto; do
  out="$WORK/gpu_$gl.png"
  "$ABCUBE" render "$WORK/small.json" -o "$out" --method gpu --gl "$gl" --stats "$WORK/s_$gl.json" 2> "$WORK/err"
  status=$?
  check "gpu --gl $gl exits 0 ($(cat "$WORK/err"))" [ $status -eq 0 ]
  check "gpu --gl $gl writes the image" [ -s "$out" ]
  check "stats of --gl $gl name a GL path" grep -q '"path": "egl\|"path": "osmesa' "$WORK/s_$gl.json"
  check "stats of --gl $gl hold the renderer" grep -q '"renderer": "' "$WORK/s_$gl.json"
  check "stats of --gl $gl hold per-pass ms" grep -q '"camera_raster"' "$WORK/s_$gl.json"
done
check "--gl osmesa stats say osmesa" grep -q '"path": "osmesa"' "$WORK/s_osmesa.json"

# --- progress on a terminal (a pseudo-terminal from script(1)) for every method, each pass to
# 100%; none when stderr is a file
for m in abuffer gpu hybrid raytrace envmap; do
  n="--cube-res 32"
  [ $m = raytrace ] && n=""
  script -qec "'$ABCUBE' render '$WORK/small.json' -o '$WORK/p_$m.png' --method $m $n" /dev/null \
    > "$WORK/tty_$m" 2>&1
  check "$m on a terminal exits 0" [ $? -eq 0 ]
  check "$m shows its progress on a terminal ($(tr '\r' '|' < "$WORK/tty_$m" | head -c 300))" grep -q "100%" "$WORK/tty_$m"
done
check "abuffer's progress names its passes" grep -q "shading 100%" "$WORK/tty_abuffer"
check "abuffer's progress names its passes" grep -q "cube A-buffer 100%" "$WORK/tty_abuffer"
check "gpu's progress names its passes" grep -q "gpu passes 100%" "$WORK/tty_gpu"
"$ABCUBE" render "$WORK/small.json" -o "$WORK/p_file.png" --cube-res 32 2> "$WORK/quiet"
check "no progress when stderr is a file" [ ! -s "$WORK/quiet" ]

# --- the two APIs draw the same picture
"$ABCUBE" compare "$WORK/gpu_egl.png" "$WORK/gpu_osmesa.png" --fail 0.004 > "$WORK/cmp" 2>&1
status=$?
check "egl and osmesa images agree ($(tail -1 "$WORK/cmp"))" [ $status -eq 0 ]

# --- a forced path that fails is an error naming the reason, and leaves old outputs alone
printf 'old image' > "$WORK/keep.png"
"$ABCUBE" render "$WORK/small.json" -o "$WORK/keep.png" --method gpu --gl egl-device --gl-device 99 \
  > /dev/null 2> "$WORK/err"
status=$?
check "forced EGL device 99 exits 1 (got $status)" [ $status -eq 1 ]
check "forced failure says why on one line" [ "$(wc -l < "$WORK/err")" -eq 1 ]
check "forced failure names the device" grep -q "device 99" "$WORK/err"
check "failed render keeps the old output" [ "$(cat "$WORK/keep.png")" = "old image" ]
check "no temporary file left behind" [ -z "$(ls -A "$WORK" | grep '\.tmp')" ]
"$ABCUBE" render "$WORK/small.json" -o "$WORK/x.png" --method gpu --gl none > /dev/null 2> "$WORK/err"
check "--method gpu with --gl none exits 2" [ $? -eq 2 ]
ABCUBE_EGL_DEVICE=abc "$ABCUBE" render "$WORK/small.json" -o "$WORK/x.png" --method gpu > /dev/null 2> "$WORK/err"
check "bad ABCUBE_EGL_DEVICE exits 2" [ $? -eq 2 ]
check "nothing written on error" [ ! -e "$WORK/x.png" ]

"$ABCUBE" render "$WORK/small.json" -o "$WORK/x.png" --method gpu --gl osmesa --gl-device 0 > /dev/null 2> "$WORK/err"
check "--gl-device with --gl osmesa exits 2" [ $? -eq 2 ]
"$ABCUBE" > /dev/null 2> "$WORK/err"
check "no command exits 2" [ $? -eq 2 ]
check "no command: one line" [ "$(wc -l < "$WORK/err")" -eq 1 ]
# Missing folders are made (render and batch share the rule), once the render is done.
"$ABCUBE" render "$WORK/small.json" -o "$WORK/x.png" --method gpu --stats "$WORK/no/such/s.json" > /dev/null 2> "$WORK/err"
check "--stats into a missing folder: made, exit 0" [ $? -eq 0 ]
check "--stats into a missing folder: the stats in it" [ -s "$WORK/no/such/s.json" ]
rm -f "$WORK/x.png"
# A file where a folder should be is refused before any work.
"$ABCUBE" render "$WORK/small.json" -o "$WORK/x.png" --method gpu --stats "$WORK/small.json/s.json" > /dev/null 2> "$WORK/err"
check "--stats under a file exits 2 before any work" [ $? -eq 2 ]
check "--stats error leaves no image" [ ! -e "$WORK/x.png" ]

# --- the exact tracer with --reference, no GL needed
"$ABCUBE" render "$WORK/small.json" -o "$WORK/rt.exr" --method raytrace --gl none --threads 2 \
  --reference --stats "$WORK/rt.json" 2> "$WORK/err"
status=$?
check "raytrace exits 0 ($(cat "$WORK/err"))" [ $status -eq 0 ]
check "raytrace writes EXR" [ -s "$WORK/rt.exr" ]
check "raytrace stats count rays" grep -q '"primary_rays": 55296' "$WORK/rt.json"
check "reference of raytrace is itself" grep -q '"psnr_db": "inf"' "$WORK/rt.json"
"$ABCUBE" render "$WORK/small.json" -o "$WORK/rt.png" --method raytrace --gl none 2> /dev/null
"$ABCUBE" render "$WORK/small.json" -o "$WORK/gpu_ref.png" --method gpu --reference --stats "$WORK/g.json" 2> /dev/null
check "gpu --reference reports an image error" grep -q '"share_over_2_255"' "$WORK/g.json"

# --- the cube-map methods and their options; stats count the searches
for v in "abuffer" "abuffer --search thesis --theta-max 1" "zbuffer" "envmap --envmap-lookup bisector" \
         "abuffer --refraction thin_lens" "abuffer --fresnel" "abuffer --refine plane"; do
  set -- $v
  name=$(echo "$v" | tr ' ' '_')
  "$ABCUBE" render "$WORK/small.json" -o "$WORK/m_$name.png" --method $v --cube-res 64 --stats "$WORK/m_$name.json" \
    --reference 2> "$WORK/err"
  status=$?
  check "--method $v exits 0 ($(cat "$WORK/err"))" [ $status -eq 0 ]
  check "--method $v counts shadow searches" grep -q '"shadow": {' "$WORK/m_$name.json"
  check "--method $v reports Error_Parallax" grep -q '"error_parallax"' "$WORK/m_$name.json"
done
# --- the plan: --plan everything changes the time, never the image; --error-target picks N
"$ABCUBE" render "$WORK/small.json" -o "$WORK/p1.png" --cube-res 64 --stats "$WORK/p1.json" 2> /dev/null
"$ABCUBE" render "$WORK/small.json" -o "$WORK/p2.png" --cube-res 64 --plan everything 2> /dev/null
"$ABCUBE" compare "$WORK/p1.png" "$WORK/p2.png" --fail 0 > /dev/null
check "--plan everything gives the same image" [ $? -eq 0 ]
"$ABCUBE" render "$WORK/small.json" -o "$WORK/p3.png" --error-target 1.25e-5 --stats "$WORK/p3.json" 2> /dev/null
check "--error-target 1.25e-5 picks N = 200 (thesis 9.3.4)" grep -q '"cube_resolution": 200' "$WORK/p3.json"
# --target-db: the stats name the N chosen, and that N rendered directly is the same image;
# the scene's render.target_db does the same; --cube-res beside it is a contradiction.
"$ABCUBE" render "$WORK/small.json" -o "$WORK/t1.png" --target-db 35 --stats "$WORK/t1.json" 2> "$WORK/err"
status=$?
check "--target-db 35 renders ($(cat "$WORK/err"))" [ $status -eq 0 ]
tn=$(/usr/bin/python3 -c 'import json,sys; t=json.load(open(sys.argv[1]))["target_db"]; print(t["cube_resolution"], t["shading_points"], t["shadow_edges"], t["secondary_edges"])' "$WORK/t1.json")
read -r t_n t_points t_shadow t_secondary <<< "$tn"
"$ABCUBE" render "$WORK/small.json" -o "$WORK/t2.png" --cube-res "$t_n" --shading-points "$t_points" \
  --shadow-edges "$t_shadow" --secondary-edges "$t_secondary" 2> /dev/null
check "--target-db's chosen plan ($tn) rendered directly is the same image" \
  "$ABCUBE" compare "$WORK/t1.png" "$WORK/t2.png" --exact
sed 's/"objects": \[/"render": {"target_db": 35}, "objects": [/' "$WORK/small.json" > "$WORK/target.json"
"$ABCUBE" render "$WORK/target.json" -o "$WORK/t3.png" 2> /dev/null
check "render.target_db in the scene is --target-db" "$ABCUBE" compare "$WORK/t1.png" "$WORK/t3.png" --exact
"$ABCUBE" render "$WORK/small.json" -o "$WORK/t4.png" --target-db 35 --cube-res 64 > /dev/null 2> "$WORK/err"
status=$?
check "--target-db with --cube-res exits 2 ($(cat "$WORK/err"))" [ $status -eq 2 ]
check "--target-db with --cube-res: says why" grep -q -- "--target-db: chooses the cube map's N, and so does" "$WORK/err"
check "--target-db with --cube-res: nothing written" [ ! -e "$WORK/t4.png" ]
sed 's/"objects": \[/"render": {"target_db": 0}, "objects": [/' "$WORK/small.json" > "$WORK/target0.json"
"$ABCUBE" render "$WORK/target0.json" -o "$WORK/t5.png" > /dev/null 2> "$WORK/err"
status=$?
check "render.target_db 0 exits 2 ($(cat "$WORK/err"))" [ $status -eq 2 ]
check "render.target_db 0 names it" grep -q "render.target_db: must be" "$WORK/err"
"$ABCUBE" render "$WORK/small.json" -o "$WORK/rt.exr" --method raytrace 2> /dev/null
"$ABCUBE" render "$WORK/small.json" -o "$WORK/p4.png" --cube-res 64 --reference-image "$WORK/rt.exr" \
  --stats "$WORK/p4.json" 2> /dev/null
check "--reference-image gives the image error" grep -q '"psnr_db"' "$WORK/p4.json"
check "--reference-image reports the bound share" grep -q '"error_parallax_within_bound"' "$WORK/p4.json"
oiiotool "$WORK/rt.exr" --resize 20x10 -o "$WORK/tiny.exr" 2> /dev/null
"$ABCUBE" render "$WORK/small.json" -o "$WORK/x.png" --reference-image "$WORK/tiny.exr" > /dev/null 2> "$WORK/err"
check "--reference-image of another size exits 2" [ $? -eq 2 ]
check "--reference-image size message names the file" grep -q "tiny.exr: is 20x10" "$WORK/err"
"$ABCUBE" render "$WORK/small.json" -o "$WORK/x.png" --search sideways > /dev/null 2> "$WORK/err"
check "--search sideways exits 2" [ $? -eq 2 ]
"$ABCUBE" render "$WORK/small.json" -o "$WORK/x.png" --refine polygon > /dev/null 2> "$WORK/err"
check "--refine polygon exits 2" [ $? -eq 2 ]
check "--refine polygon names the option" grep -q -- "--refine: must be one of mesh, plane, got \"polygon\"" "$WORK/err"
"$ABCUBE" render "$WORK/small.json" -o "$WORK/x.png" --refraction prism > /dev/null 2> "$WORK/err"
check "--refraction prism exits 2" [ $? -eq 2 ]
"$ABCUBE" render "$WORK/small.json" -o "$WORK/x.png" --envmap-lookup up > /dev/null 2> "$WORK/err"
check "--envmap-lookup up exits 2" [ $? -eq 2 ]

# --- compare: exit 0 within, 1 beyond, 2 for bad input; heatmap
"$ABCUBE" compare "$WORK/rt.png" "$WORK/rt.png" > "$WORK/cmp"
check "identical images compare 0" [ $? -eq 0 ]
check "identical images: PSNR inf" grep -q "PSNR        inf" "$WORK/cmp"
# (The gpu method's exact camera pass now draws this scene as the tracer does: its old
# techniques, the cube texture and shadow maps, give an image that differs.)
"$ABCUBE" render "$WORK/small.json" -o "$WORK/gpu_old.png" --method gpu --gpu-mirrors envmap --gpu-shadows maps 2> /dev/null
"$ABCUBE" compare "$WORK/rt.png" "$WORK/gpu_old.png" --diff "$WORK/heat.png" > "$WORK/cmp"
check "different images compare 1" [ $? -eq 1 ]
check "heatmap written" [ -s "$WORK/heat.png" ]
check "the worst pixel located" grep -qE "^max abs .* at \([0-9]+, [0-9]+, [RGB]\)" "$WORK/cmp"
check "linear figures" grep -q "^linear      RMSE" "$WORK/cmp"
"$ABCUBE" compare "$WORK/rt.png" "$WORK/gpu_old.png" --json > "$WORK/cmp.json"
check "--json: exit 1 as the text" [ $? -eq 1 ]
check "--json: every figure" /usr/bin/python3 -c "
import json, sys
j = json.load(open('$WORK/cmp.json'))
assert j['pass'] is False and j['psnr_db'] > 0 and 0 <= j['worst_pixel']['x'] < j['width'], j
assert set(j['linear']) == {'rmse', 'max_abs', 'relative_mean', 'hdr'} and j['share_over_8_255'] >= 0, j
"
"$ABCUBE" compare "$WORK/rt.png" "$WORK/gpu_egl.png" --fail 1 > /dev/null
check "--fail 1 lets everything pass" [ $? -eq 0 ]
"$ABCUBE" compare "$WORK/rt.png" "$WORK/gpu_egl.png" --failpercent 100 > /dev/null
check "--failpercent 100 lets everything pass" [ $? -eq 0 ]
"$ABCUBE" compare "$WORK/rt.png" "$WORK/nothing.png" > /dev/null 2> "$WORK/err"
check "unreadable image compares 2" [ $? -eq 2 ]
check "unreadable image named" grep -q "nothing.png" "$WORK/err"
oiiotool "$WORK/rt.png" --resize 20x10 -o "$WORK/small.png" 2> /dev/null
"$ABCUBE" compare "$WORK/rt.png" "$WORK/small.png" > /dev/null 2> "$WORK/err"
check "size mismatch compares 2" [ $? -eq 2 ]
check "size mismatch on one line" [ "$(wc -l < "$WORK/err")" -eq 1 ]

# --- export-pov and info
"$ABCUBE" export-pov "$WORK/small.json" -o "$WORK/small.pov"
check "export-pov exits 0" [ $? -eq 0 ]
check "export-pov writes mesh2" grep -q "mesh2" "$WORK/small.pov"
"$ABCUBE" info > "$WORK/info"
check "info exits 0" [ $? -eq 0 ]
check "info lists egl-surfaceless" grep -q "egl-surfaceless" "$WORK/info"
check "info lists osmesa" grep -q "osmesa" "$WORK/info"
check "info prints GL_RENDERER" grep -q "GL_RENDERER" "$WORK/info"

# --- outputs are byte-reproducible: the same render written twice, by two processes more
# than a second apart, gives the same bytes (no time stamp, no temporary name, no stray
# header bytes). The only sleep of the suite: a DateTime attribute has one-second steps.
# DPX and SGI go through the image module (OpenImageIO, loaded when first needed). In the
# checked builds (ABCUBE_CHECKED_BUILD, tools/sanitize.sh) their renders run without
# LeakSanitizer: its tracer crashes at exit on the dynamic TLS that loading brings (gcc 12's
# libasan; docs/robustness.md), in every dpx and sgi render of one fresh clone's CI run. The
# built-in codecs' renders (exr, tif, png) keep it.
repro_env() {  # FORMAT: the environment's changes for its renders, if any
  if [ "${ABCUBE_CHECKED_BUILD:-0}" = 1 ] && { [ "$1" = dpx ] || [ "$1" = sgi ]; }; then
    echo "ASAN_OPTIONS=${ASAN_OPTIONS:-}:detect_leaks=0"
  fi
}
mkdir -p "$WORK/repro"
for e in exr tif dpx sgi png; do
  env $(repro_env $e) "$ABCUBE" render "$WORK/small.json" -o "$WORK/repro/r.$e" --method raytrace 2> "$WORK/err" &&
    mv "$WORK/repro/r.$e" "$WORK/repro/first.$e"
  check "reproducible $e: first render ($(head -c 200 "$WORK/err"))" [ -s "$WORK/repro/first.$e" ]
done
sleep 1.1
for e in exr tif dpx sgi png; do
  env $(repro_env $e) "$ABCUBE" render "$WORK/small.json" -o "$WORK/repro/r.$e" --method raytrace 2> /dev/null
  check "reproducible $e: same bytes a second later" cmp -s "$WORK/repro/r.$e" "$WORK/repro/first.$e"
done

echo "cli render_cli: $passed passed, $failed failed"
[ $failed -eq 0 ]
