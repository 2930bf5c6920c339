#!/usr/bin/env bash
# Faults survived (docs/robustness.md): a full disk, an output folder
# that is missing or read-only, SIGINT and SIGTERM during a render and during a batch, no EGL
# library (and no GL at all), EGL with no usable display, a render over --max-memory, a mesh
# that disappears or changes while a batch runs. Each must end with its exit status and one
# line naming the problem, leave every old output intact and no temporary file behind.
#
# The full disk, the read-only folder and the missing libraries need a private mount
# namespace (unshare --mount: root, or user namespaces): the script runs itself again inside
# one, where its tmpfs and bind mounts vanish with it. Where that is impossible those parts
# are reported as SKIPPED and the rest runs.
# Usage (ctest runs it so): bash faults_cli.sh /path/to/abcube /path/to/repo
set -u
if [ -z "${ABCUBE_FAULTS_IN_NAMESPACE:-}" ] && unshare --mount --propagation private true 2>/dev/null; then
  exec env ABCUBE_FAULTS_IN_NAMESPACE=1 unshare --mount --propagation private bash "$0" "$@"
fi
ABCUBE=$1
REPO=$2
CLI_TEST=faults_cli
. "$(dirname "$0")/lib/check.sh"
MOUNTS=no
[ -n "${ABCUBE_FAULTS_IN_NAMESPACE:-}" ] && MOUNTS=yes
skipped=0
PY_FOR_SCENES=/usr/bin/python3
skip() { skipped=$((skipped + 1)); echo "SKIPPED: $*"; }

# No temporary file of an atomic write (.NAME.tmpPID.EXT) anywhere under $1.
no_temporaries() { [ -z "$(find "$1" -name '.*.tmp*' -print -quit)" ]; }
# Exactly one line on stderr ($WORK/err); and that it matches the pattern $1.
one_line() { [ "$(wc -l < "$WORK/err")" -eq 1 ]; }
line_has() { one_line && grep -q -- "$1" "$WORK/err"; }

# The batches that are stopped part-way render their jobs at W x H: smaller in the checked
# builds (ABCUBE_CHECKED_BUILD, tools/sanitize.sh), where each render is many times slower
# and the jobs left after the stop still take seconds.
JOB_SIZE='"width": 160, "height": 120'
MESH_JOB_SIZE='"width": 320, "height": 240'
if [ "${ABCUBE_CHECKED_BUILD:-0}" = 1 ]; then
  JOB_SIZE='"width": 96, "height": 72'
  MESH_JOB_SIZE=$JOB_SIZE
fi

# A quick scene (48x36) and a slow one (cornell at 512x512 under raytrace: seconds).
cat > "$WORK/small.json" <<'JSON'
{ "version": 1,
  "camera": {"position": [0, 1, 4], "look_at": [0, 0.5, 0], "fov_y": 50, "width": 48, "height": 36},
  "lights": [{"type": "point", "position": [2, 4, 3], "color": [1, 1, 1]}],
  "materials": {"red": {"color": [0.9, 0.1, 0.1]}},
  "objects": [
    {"type": "quad", "vertices": [[-3,0,-3],[-3,0,3],[3,0,3],[3,0,-3]]},
    {"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5, "segments": 16, "material": "red"}
  ] }
JSON
SLOW="$REPO/scenes/cornell.json"

# --- 1. A full disk: a 64 KiB tmpfs, filled up but for a few KiB ----------------------------
if [ $MOUNTS = yes ] && mkdir -p "$WORK/full" && mount -t tmpfs -o size=64k tmpfs "$WORK/full" 2>/dev/null; then
  printf 'old' > "$WORK/full/old.exr"
  printf 'old' > "$WORK/full/old.json"
  dd if=/dev/zero of="$WORK/full/filler" bs=1k count=58 status=none 2>/dev/null
  "$ABCUBE" render "$WORK/small.json" -o "$WORK/full/old.exr" --method raytrace > /dev/null 2> "$WORK/err"
  status=$?
  check "full disk: image write exits 1 (got $status: $(cat "$WORK/err"))" [ $status -eq 1 ]
  check "full disk: one line" one_line
  check "full disk: the line names the output" grep -q "full/old.exr" "$WORK/err"
  check "full disk: the old image is intact" [ "$(cat "$WORK/full/old.exr")" = old ]
  check "full disk: no temporary left" no_temporaries "$WORK/full"
  "$ABCUBE" render "$WORK/small.json" -o "$WORK/fine.png" --method raytrace --stats "$WORK/full/old.json" \
    > /dev/null 2> "$WORK/err"
  status=$?
  check "full disk: stats write exits 1 (got $status: $(cat "$WORK/err"))" [ $status -eq 1 ]
  check "full disk: stats failure is one line" one_line
  check "full disk: the old stats are intact" [ "$(cat "$WORK/full/old.json")" = old ]
  check "full disk: no temporary left after the stats" no_temporaries "$WORK/full"
  # A batch: the job that cannot be written fails with its line, the others render.
  printf '%s\n' "{\"scene\": \"$WORK/small.json\", \"out\": \"$WORK/b1.png\", \"method\": \"raytrace\"}" \
    "{\"scene\": \"$WORK/small.json\", \"out\": \"$WORK/full/b2.exr\", \"method\": \"raytrace\"}" \
    "{\"scene\": \"$WORK/small.json\", \"out\": \"$WORK/b3.png\", \"method\": \"raytrace\"}" > "$WORK/full_jobs.jsonl"
  "$ABCUBE" batch "$WORK/full_jobs.jsonl" > /dev/null 2> "$WORK/err"
  status=$?
  check "full disk: batch exits 1 (got $status)" [ $status -eq 1 ]
  check "full disk: batch names the job's line" grep -q "full_jobs.jsonl:2: " "$WORK/err"
  check "full disk: the batch's other jobs rendered" test -s "$WORK/b1.png" -a -s "$WORK/b3.png"
  check "full disk: no temporary left by the batch" no_temporaries "$WORK/full"
  umount "$WORK/full"
else
  skip "full disk (no private mount namespace with tmpfs here)"
fi

# --- 2. Output folders: missing, read-only, a file on the path --------------------------------
printf 'keep' > "$WORK/keep.png"
# A missing folder is made (as batch makes it), once the render is done.
"$ABCUBE" render "$WORK/small.json" -o "$WORK/no/such/x.png" --method raytrace > /dev/null 2> "$WORK/err"
status=$?
check "missing folder: made, exit 0 (got $status)" [ $status -eq 0 ]
check "missing folder: made, the image in it" [ -s "$WORK/no/such/x.png" ]
"$ABCUBE" render "$SLOW" -o "$WORK/keep.png/x.png" --method raytrace > /dev/null 2> "$WORK/err"
check "a file where the folder should be: exit 2" [ $? -eq 2 ]
mkdir -p "$WORK/ro"
read_only=no
if [ $MOUNTS = yes ] && mount --bind "$WORK/ro" "$WORK/ro" 2>/dev/null && mount -o remount,bind,ro "$WORK/ro" 2>/dev/null; then
  read_only=yes
elif [ "$(id -u)" -ne 0 ]; then
  chmod 555 "$WORK/ro" && read_only=yes
fi
if [ $read_only = yes ]; then
  "$ABCUBE" render "$SLOW" -o "$WORK/ro/x.png" --method raytrace > /dev/null 2> "$WORK/err"
  status=$?
  check "read-only folder: exit 2 before rendering (got $status)" [ $status -eq 2 ]
  check "read-only folder: one line, not writable" line_has "is not writable"
  # A batch checks every output's folder before anything renders.
  printf '%s\n' "{\"scene\": \"$WORK/small.json\", \"out\": \"$WORK/first.png\"}" \
    "{\"scene\": \"$WORK/small.json\", \"out\": \"$WORK/ro/deeper/second.png\"}" > "$WORK/ro_jobs.jsonl"
  "$ABCUBE" batch "$WORK/ro_jobs.jsonl" > /dev/null 2> "$WORK/err"
  status=$?
  check "read-only folder in a batch: exit 2 (got $status)" [ $status -eq 2 ]
  check "read-only folder in a batch: JOBS:LINE" line_has 'ro_jobs.jsonl:2: "out": '
  check "read-only folder in a batch: nothing rendered" [ ! -e "$WORK/first.png" ]
  [ $MOUNTS = yes ] && umount "$WORK/ro"
  chmod 755 "$WORK/ro"
else
  skip "read-only folder (root without a private mount namespace)"
fi

# --- 3. SIGINT and SIGTERM --------------------------------------------------------------
# During a render: exit 128 + signal, one line, the old output intact, no temporary.
for sig in INT TERM; do
  printf 'old' > "$WORK/sig.png"
  "$ABCUBE" render "$SLOW" -o "$WORK/sig.png" --method raytrace 2> "$WORK/err" > /dev/null &
  pid=$!
  sleep 1.5
  kill -s $sig $pid
  wait $pid
  status=$?
  want=$([ $sig = INT ] && echo 130 || echo 143)
  check "SIG$sig during a render: exit $want (got $status)" [ $status -eq $want ]
  check "SIG$sig during a render: one line ($(cat "$WORK/err"))" line_has "SIG$sig"
  check "SIG$sig during a render: the old output intact" [ "$(cat "$WORK/sig.png")" = old ]
  check "SIG$sig during a render: no temporary" no_temporaries "$WORK"
done
# During a batch: stops between or inside jobs, every written output whole, resumable.
mkdir -p "$WORK/batch"
: > "$WORK/batch/jobs.jsonl"
for i in 1 2 3 4 5 6; do
  echo "{\"scene\": \"$SLOW\", \"out\": \"out/$i.png\", \"method\": \"raytrace\", \"camera\": {$JOB_SIZE, \"position\": [0.$i, 1, 3.5]}}" \
    >> "$WORK/batch/jobs.jsonl"
done
"$ABCUBE" batch "$WORK/batch/jobs.jsonl" > /dev/null 2> "$WORK/err" &
pid=$!
for _ in $(seq 1 600); do [ -e "$WORK/batch/out/1.png" ] && break; sleep 0.05; done
kill -s TERM $pid
wait $pid
status=$?
check "SIGTERM during a batch: exit 143 (got $status)" [ $status -eq 143 ]
check "SIGTERM during a batch: says how to resume" grep -q "rerun with --skip-existing" "$WORK/err"
check "SIGTERM during a batch: no temporary" no_temporaries "$WORK/batch"
written=$(ls "$WORK/batch/out" | wc -l)
check "SIGTERM during a batch: stopped before the end ($written of 6 written)" [ "$written" -lt 6 ]
"$ABCUBE" batch "$WORK/batch/jobs.jsonl" --skip-existing > "$WORK/out" 2> "$WORK/err"
status=$?
check "the batch resumes with --skip-existing: exit 0 ($(cat "$WORK/err"))" [ $status -eq 0 ]
check "the resumed batch skipped what was written" grep -q ", $written skipped;" "$WORK/out"
mkdir -p "$WORK/whole"
sed 's|"out/|"../whole/|' "$WORK/batch/jobs.jsonl" > "$WORK/batch/whole.jsonl"
"$ABCUBE" batch "$WORK/batch/whole.jsonl" > /dev/null 2>&1
same=0
for i in 1 2 3 4 5 6; do cmp -s "$WORK/batch/out/$i.png" "$WORK/whole/$i.png" && same=$((same + 1)); done
check "interrupted + resumed outputs equal an uninterrupted batch byte for byte ($same of 6)" [ $same -eq 6 ]

# --- 4. No EGL library, no GL at all, EGL with no usable display -------------------------
hidden=()
hide() {  # bind /dev/null over the library file the loader would open (unhide: undo)
  local real
  real=$(readlink -f "$(ldconfig -p | awk -v n="$1" '$1 == n {print $NF; exit}')")
  [ -f "$real" ] && mount --bind /dev/null "$real" && hidden+=("$real")
}
unhide() { for f in "${hidden[@]}"; do umount "$f"; done; hidden=(); }
if [ $MOUNTS = yes ] && hide libEGL.so.1; then
  "$ABCUBE" info > "$WORK/info" 2> "$WORK/err"
  check "no libEGL: info exits 0" [ $? -eq 0 ]
  check "no libEGL: info says so" grep -q "egl-surfaceless  no: libEGL.so.1 not found or not loadable" "$WORK/info"
  "$ABCUBE" render "$WORK/small.json" -o "$WORK/x.png" --method gpu --gl egl > /dev/null 2> "$WORK/err"
  status=$?
  check "no libEGL: --gl egl exits 1 (got $status)" [ $status -eq 1 ]
  check "no libEGL: one line naming libEGL" line_has "libEGL.so.1"
  "$ABCUBE" render "$WORK/small.json" -o "$WORK/x.png" --method gpu > /dev/null 2> "$WORK/err"
  status=$?
  check "no libEGL: --gl auto falls back to OSMesa ($(cat "$WORK/err"))" [ $status -eq 0 ]
  if hide libOSMesa.so.8; then
    "$ABCUBE" info > "$WORK/info" 2> "$WORK/err"
    check "no GL: info exits 0" [ $? -eq 0 ]
    check "no GL: info says auto picks none" grep -q "auto picks: none" "$WORK/info"
    rm -f "$WORK/x.png"
    "$ABCUBE" render "$WORK/small.json" -o "$WORK/x.png" --method gpu > /dev/null 2> "$WORK/err"
    status=$?
    check "no GL: gpu exits 1 (got $status)" [ $status -eq 1 ]
    check "no GL: one line naming each path" line_has "egl-surfaceless: .*osmesa: libOSMesa"
    check "no GL: nothing written" [ ! -e "$WORK/x.png" ]
    "$ABCUBE" crosscheck "$WORK/small.json" > /dev/null 2> "$WORK/err"
    status=$?
    check "no GL: crosscheck exits 1 (got $status)" [ $status -eq 1 ]
    check "no GL: crosscheck says so in one line" line_has "needs OpenGL"
    for m in abuffer zbuffer envmap raytrace; do
      "$ABCUBE" render "$WORK/small.json" -o "$WORK/$m.png" --method $m > /dev/null 2> "$WORK/err"
      status=$?
      check "no GL: $m still renders ($(cat "$WORK/err"))" test $status -eq 0 -a -s "$WORK/$m.png"
    done
  else
    skip "no GL at all (libOSMesa.so.8 not found to hide)"
  fi
  unhide
else
  skip "no EGL library (no private mount namespace, or libEGL.so.1 not found)"
fi
# glvnd with no vendor: libEGL loads but offers no display.
__EGL_VENDOR_LIBRARY_FILENAMES="$WORK/no-vendor.json" "$ABCUBE" info > "$WORK/info" 2> "$WORK/err"
check "EGL without a vendor: info exits 0" [ $? -eq 0 ]
check "EGL without a vendor: info says why" grep -q "egl-surfaceless  no: " "$WORK/info"
__EGL_VENDOR_LIBRARY_FILENAMES="$WORK/no-vendor.json" "$ABCUBE" render "$WORK/small.json" -o "$WORK/x.png" \
  --method gpu --gl egl > /dev/null 2> "$WORK/err"
status=$?
check "EGL without a vendor: --gl egl exits 1 (got $status)" [ $status -eq 1 ]
check "EGL without a vendor: one line" line_has "gl egl failed: "

# --- 5. Over --max-memory: refused before work with the estimate ---------------------------
printf 'keep' > "$WORK/keep.png"
"$ABCUBE" render "$SLOW" -o "$WORK/keep.png" --method abuffer --cube-res 4096 --max-memory 512 > /dev/null 2> "$WORK/err"
status=$?
check "over --max-memory: exit 2 (got $status)" [ $status -eq 2 ]
check "over --max-memory: one line with the estimate" line_has "estimated [0-9]* MiB .*above --max-memory 512 MiB"
check "over --max-memory: the old output intact" [ "$(cat "$WORK/keep.png")" = keep ]

# --- 6. A mesh that disappears or changes while a batch runs ------------------------------
# Two scenes alternate and --scene-cache 1 reloads each for every job. After the first
# output the batch is paused (SIGSTOP), the mesh changed, and the batch resumed: every later
# job of the mesh's scene fails with its line naming the mesh, the other scene's jobs
# render, nothing is half-written.
mkdir -p "$WORK/mesh"
cp "$REPO/scenes/meshes/octahedron.mtl" "$WORK/mesh/"
cat > "$WORK/mesh/a.json" <<'JSON'
{ "version": 1, "camera": {"position": [0, 1, 4], "look_at": [0, 0, 0], "width": 64, "height": 48},
  "lights": [{"type": "point", "position": [2, 4, 3], "color": [1, 1, 1]}],
  "objects": [{"type": "mesh", "file": "m.obj"}] }
JSON
for change in remove garbage; do
  : > "$WORK/mesh/jobs.jsonl"
  for i in 1 2 3 4 5 6 7 8; do
    scene=$([ $((i % 2)) -eq 1 ] && echo a.json || echo "$WORK/small.json")
    echo "{\"scene\": \"$scene\", \"out\": \"$change/$i.png\", \"method\": \"raytrace\", \"camera\": {$MESH_JOB_SIZE}}" \
      >> "$WORK/mesh/jobs.jsonl"
  done
  cp "$REPO/scenes/meshes/octahedron.obj" "$WORK/mesh/m.obj"
  "$ABCUBE" batch "$WORK/mesh/jobs.jsonl" --scene-cache 1 > /dev/null 2> "$WORK/err" &
  pid=$!
  for _ in $(seq 1 600); do [ -e "$WORK/mesh/$change/1.png" ] && break; sleep 0.02; done
  kill -STOP $pid
  if [ $change = remove ]; then rm "$WORK/mesh/m.obj"; else printf 'v 0 0 0\nf 1 2 3\n' > "$WORK/mesh/m.obj"; fi
  kill -CONT $pid
  wait $pid
  status=$?
  check "mesh $change during a batch: exit 1 (got $status)" [ $status -eq 1 ]
  check "mesh $change during a batch: the last job of its scene fails naming the mesh" \
    grep -q "jobs.jsonl:7: .*m\.obj" "$WORK/err"
  check "mesh $change during a batch: every failure is one line naming its job" \
    [ "$(grep -vc '^[^ ]*jobs.jsonl:[0-9]*: ' "$WORK/err")" -eq 0 ]
  check "mesh $change during a batch: the other scene's jobs rendered" \
    test -s "$WORK/mesh/$change/2.png" -a -s "$WORK/mesh/$change/8.png"
  check "mesh $change during a batch: no temporary" no_temporaries "$WORK/mesh"
  whole=0
  for f in "$WORK/mesh/$change"/*.png; do "$ABCUBE" compare "$f" "$f" > /dev/null 2>&1 && whole=$((whole + 1)); done
  check "mesh $change during a batch: every written image is whole ($whole of $(ls "$WORK/mesh/$change" | wc -l))" \
    [ $whole -eq "$(ls "$WORK/mesh/$change" | wc -l)" ]
done

# --- 7. More shadow-casting lights than GL holds (gpu): refused up front, not a GL error ----
if "$ABCUBE" info 2>/dev/null | grep -q 'auto picks: egl\|auto picks: osmesa'; then
  limit=$("$ABCUBE" info 2>/dev/null | sed -n 's/.*shadow-casting lights (gpu): *\([0-9]*\).*/\1/p' | head -1)
  check "info gives the gpu method's shadow-light limit ($limit)" [ -n "$limit" ]
  for n in "$limit" $((limit + 1)); do
    $PY_FOR_SCENES - "$WORK/lights_$n.json" "$n" <<'PY'
import json, sys
n = int(sys.argv[2])
json.dump({"version": 1, "camera": {"position": [0, 1, -3], "look_at": [0, 0, 0], "width": 32, "height": 24},
           "objects": [{"type": "quad", "vertices": [[-2, 0, -2], [2, 0, -2], [2, 0, 2], [-2, 0, 2]]},
                       {"type": "sphere", "center": [0, 0.5, 0], "radius": 0.4, "segments": 8}],
           "lights": [{"type": "point", "position": [0.01 * i - 2, 3, 0.5], "color": [0.003] * 3} for i in range(n)],
           "render": {"cube_resolution": 16}}, open(sys.argv[1], "w"))
PY
  done
  "$ABCUBE" render "$WORK/lights_$limit.json" -o "$WORK/lights.png" --method gpu > /dev/null 2> "$WORK/err"
  status=$?
  check "gpu renders $limit shadow-casting lights ($(cat "$WORK/err"))" [ $status -eq 0 ]
  "$ABCUBE" render "$WORK/lights_$((limit + 1)).json" -o "$WORK/lights_over.png" --method gpu > /dev/null 2> "$WORK/err"
  status=$?
  check "gpu refuses $((limit + 1)) shadow-casting lights with exit 2 (got $status)" [ $status -eq 2 ]
  check "the refusal names the count and the limit" line_has "lights: $((limit + 1)) cast shadows; .* at most $limit here (GL_MAX_ARRAY_TEXTURE_LAYERS"
  check "nothing written" test ! -e "$WORK/lights_over.png"
  "$ABCUBE" render "$WORK/lights_$((limit + 1)).json" -o "$WORK/lights_cpu.png" --method abuffer > /dev/null 2> "$WORK/err"
  status=$?
  check "abuffer renders them ($(cat "$WORK/err"))" [ $status -eq 0 ]
else
  skip "GL limits (no GL path here)"
fi

[ -n "${ABCUBE_FAULTS_DEBUG:-}" ] && cat "$WORK/err"
echo "faults_cli: $passed passed, $failed failed, $skipped skipped (private mounts: $MOUNTS)"
[ "$failed" -eq 0 ]
