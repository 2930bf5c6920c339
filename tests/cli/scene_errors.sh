#!/usr/bin/env bash
# Bad scenes and bad command lines end the program cleanly (cli.md, scene-format.md):
# exit status 2, exactly one line on stderr that names the place (FILE:LINE:COL for JSON
# syntax, the field path for values), nothing on stdout, no output file created, and an
# output file that was already there left byte for byte as it was.
#
# Usage (ctest runs it so): bash scene_errors.sh /path/to/abcube /path/to/repo
set -u

if [ $# -ne 2 ]; then
  echo "usage: bash scene_errors.sh /path/to/abcube /path/to/repo" >&2
  exit 2
fi
ABCUBE=$1
REPO=$2
if [ ! -x "$ABCUBE" ]; then
  echo "cli scene_errors: program not found or not executable: $ABCUBE"
  exit 1
fi

WORK=$(mktemp -d "${TMPDIR:-/tmp}/abcube_scene_errors.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
passed=0
failed=0

# A valid scene, so that command-line cases fail on the command line only.
GOOD="$REPO/scenes/hidden_point.json"

# Writes scene NAME.json into $WORK from the text on stdin.
scene() { cat > "$WORK/$1.json"; }

# The top of a valid scene, for cases that break only what follows it.
HEAD='"version": 1, "camera": {"position": [0, 1, 5], "look_at": [0, 0, 0], "width": 32, "height": 24}'

# expect_rejected NAME EXPECTED ARGS...: runs `abcube ARGS... -o OUT`, once with OUT absent
# and once with OUT already there, and checks every promise of cli.md for a bad input.
expect_rejected() {
  local name=$1 expected=$2
  shift 2
  local dir="$WORK/out_$name"
  mkdir -p "$dir"
  printf 'an earlier image\n\x89PNG\x00\x01\x02' > "$dir/existing.png"
  cp "$dir/existing.png" "$WORK/reference_$name"
  local before
  before=$(ls -A "$dir")
  local problems=()

  local target status lines
  for target in new.png existing.png; do
    "$ABCUBE" "$@" -o "$dir/$target" > "$WORK/stdout" 2> "$WORK/stderr"
    status=$?
    [ "$status" -eq 2 ] || problems+=("$target: exit status $status, expected 2")
    lines=$(wc -l < "$WORK/stderr")
    if [ "$lines" -ne 1 ] || [ "$(tail -c 1 "$WORK/stderr" | od -An -c | tr -d ' ')" != '\n' ]; then
      problems+=("$target: stderr has $lines lines, expected exactly one")
    fi
    grep -qF -- "$expected" "$WORK/stderr" || problems+=("$target: stderr does not name '$expected'")
    # Short whatever the input held, and nothing a terminal would act on (ESC, BEL, ...).
    [ "$(wc -c < "$WORK/stderr")" -le 600 ] || problems+=("$target: stderr is $(wc -c < "$WORK/stderr") bytes long")
    [ -z "$(tr -d '\n' < "$WORK/stderr" | LC_ALL=C tr -d '[:print:]')" ] ||
      problems+=("$target: stderr holds control bytes")
    [ -s "$WORK/stdout" ] && problems+=("$target: wrote to stdout")
  done
  [ -e "$dir/new.png" ] && problems+=("new.png: output file was created")
  cmp -s "$dir/existing.png" "$WORK/reference_$name" || problems+=("existing.png: output file was changed")
  [ "$(ls -A "$dir")" = "$before" ] || problems+=("files left behind: $(ls -A "$dir" | tr '\n' ' ')")

  if [ ${#problems[@]} -eq 0 ]; then
    passed=$((passed + 1))
    echo "ok   $name: $(head -n 1 "$WORK/stderr")"
  else
    failed=$((failed + 1))
    echo "FAIL $name: stderr was: $(head -c 300 "$WORK/stderr" | tr '\n' '|')"
    local p
    for p in "${problems[@]}"; do echo "       $p"; done
  fi
}

# Runs a bad scene the way cli.md's contract is phrased: GPU method, no GL at all.
expect_bad_scene() {
  local name=$1 expected=$2
  expect_rejected "$name" "$expected" render "$WORK/$name.json" --method gpu --gl none
}

# ---- Bad scenes -------------------------------------------------------------------------

printf '{\n  "version": 1,\n  "camera": {,\n}\n' | scene syntax
expect_bad_scene syntax "syntax.json:3:14: "

printf '{\n  "version": 1,\n  "objects": [1e999]\n}\n' | scene infinite
expect_bad_scene infinite "infinite.json:3:15: "

echo "{$HEAD, \"objects\": [{\"type\": \"sphere\", \"center\": [0,0,0], \"radius\": -1}]}" | scene radius
expect_bad_scene radius "radius.json: objects[0].radius: must be > 0, got -1"

echo '{"version": 1, "camera": {"position": [0, 1, 5], "look_at": [0, 0, 0], "fov": 60}, "objects": []}' | scene unknown_field
expect_bad_scene unknown_field "unknown_field.json: camera.fov: unknown field"

echo '{"version": 1, "camera": {"position": [0, 5, 0], "look_at": [0, 0, 0], "up": [0, 1, 0]}, "objects": []}' | scene up_parallel
expect_bad_scene up_parallel "up_parallel.json: camera.up: must not be parallel"

echo '{"version": 1, "camera": {"position": [0, 1, 5], "look_at": [0, 1, 5]}, "objects": []}' | scene no_view
expect_bad_scene no_view "no_view.json: camera.look_at: must differ"

echo '{"version": 1, "camera": {"position": [0, 1, 5], "look_at": [0, 0, 0], "fov_y": 180}, "objects": []}' | scene fov
expect_bad_scene fov "fov.json: camera.fov_y: must be > 0 and < 180"

echo "{$HEAD, \"objects\": [{\"type\": \"mesh\", \"file\": \"meshes/missing.obj\"}]}" | scene missing_mesh
expect_bad_scene missing_mesh "missing_mesh.json: objects[0].file: cannot read mesh \"$WORK/meshes/missing.obj\""

echo "{$HEAD, \"objects\": [{\"type\": \"box\", \"min\": [0,0,0], \"max\": [1,1,1], \"material\": \"gold\"}]}" | scene unknown_material
expect_bad_scene unknown_material "unknown_material.json: objects[0].material: "

echo "{$HEAD, \"materials\": {\"m\": {\"reflect\": 1.5}}, \"objects\": []}" | scene weight
expect_bad_scene weight "weight.json: materials.m.reflect: must be in [0, 1], got 1.5"

echo "{$HEAD, \"materials\": {\"m\": {\"ior\": 0.5}}, \"objects\": []}" | scene ior
expect_bad_scene ior "ior.json: materials.m.ior: must be >= 1, got 0.5"

echo "{$HEAD, \"objects\": [{\"type\": \"sphere\", \"center\": [0,0,0], \"radius\": \"1\"}]}" | scene wrong_type
expect_bad_scene wrong_type "wrong_type.json: objects[0].radius: must be a number"

echo "{$HEAD, \"objects\": [{\"type\": \"box\", \"min\": [0,0,0], \"max\": [1,0,1]}]}" | scene flat_box
expect_bad_scene flat_box "flat_box.json: objects[0].max[1]: must be > min[1]"

echo "{$HEAD, \"objects\": [{\"type\": \"quad\", \"vertices\": [[0,0,0],[1,0,0],[1,1,0],[0,1,0.5]]}]}" | scene bent_quad
expect_bad_scene bent_quad "bent_quad.json: objects[0].vertices: the 4 vertices must be coplanar"

echo '{"version": 2, "camera": {"position": [0, 1, 5], "look_at": [0, 0, 0]}, "objects": []}' | scene version
expect_bad_scene version "version.json: version: must be 1"

# 100,000 nested arrays (200 KB, made here): once a stack overflow (SIGSEGV), now refused
# where the nesting passes 64 levels.
{ head -c 100000 /dev/zero | tr '\0' '['; head -c 100000 /dev/zero | tr '\0' ']'; } | scene deep
expect_bad_scene deep "deep.json:1:65: arrays and objects nested deeper than 64 levels"

# Input files that are no regular files, or far larger than their kind's cap, are refused
# before anything is read (the big ones are sparse: no disk is used).
expect_rejected dev_zero "/dev/zero: cannot read scene: not a regular file (a character device)" \
  render /dev/zero --method gpu --gl none
truncate -s 65M "$WORK/huge.json"
expect_bad_scene huge "huge.json: cannot read scene: is 65 MiB, over the cap of 64 MiB"
echo "{$HEAD, \"objects\": [{\"type\": \"mesh\", \"file\": \"/dev/zero\"}]}" | scene zero_mesh
expect_bad_scene zero_mesh "zero_mesh.json: objects[0].file: cannot read mesh \"/dev/zero\": not a regular file"
truncate -s 9G "$WORK/huge.obj"
echo "{$HEAD, \"objects\": [{\"type\": \"mesh\", \"file\": \"huge.obj\"}]}" | scene huge_mesh
expect_bad_scene huge_mesh "huge_mesh.json: objects[0].file: cannot read mesh \"$WORK/huge.obj\": is 9 GiB, over the cap of 8 GiB"
rm -f "$WORK/huge.obj" "$WORK/huge.json"
ln -s /dev/zero "$WORK/zero.mtl"
printf 'mtllib zero.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' > "$WORK/zero_mtl.obj"
echo "{$HEAD, \"objects\": [{\"type\": \"mesh\", \"file\": \"zero_mtl.obj\"}]}" | scene zero_mtl
expect_bad_scene zero_mtl "zero_mtl.json: objects[0].file: mtllib \"zero.mtl\" of mesh \"$WORK/zero_mtl.obj\": not a regular file"

# A 5 MB unknown key.
{ printf '{"'; head -c 5000000 /dev/zero | tr '\0' 'k'; echo "\": 1, $HEAD, \"objects\": []}"; } | scene long_key
expect_bad_scene long_key 'long_key.json: ["kkkkkkkk'

# More memory than any machine here has: 32768^2 pixels and six 16384^2 faces (~176 GiB).
available_kib=$(awk '/^MemAvailable:/ {print $2}' /proc/meminfo 2>/dev/null)
if [ -n "$available_kib" ] && [ "$available_kib" -lt $((160 * 1024 * 1024)) ]; then
  echo '{"version": 1, "camera": {"position": [0, 1, 5], "look_at": [0, 0, 0], "width": 32768, "height": 32768}, "objects": [], "render": {"cube_resolution": 16384}}' | scene too_big
  expect_bad_scene too_big "too_big.json: render: estimated "
fi

expect_rejected missing_scene "$WORK/nonexistent.json" render "$WORK/nonexistent.json" --method gpu --gl none

# ---- Loads, with a warning ---------------------------------------------------------------

# An empty OBJ is no error: the render succeeds (exit 0, image written) and stderr holds one
# warning line naming the object's file field.
: > "$WORK/empty.obj"
echo "{$HEAD, \"objects\": [{\"type\": \"box\", \"min\": [0,0,0], \"max\": [1,1,1]}, {\"type\": \"mesh\", \"file\": \"empty.obj\"}]}" | scene empty_mesh
"$ABCUBE" render "$WORK/empty_mesh.json" -o "$WORK/empty_mesh.png" --method raytrace > "$WORK/stdout" 2> "$WORK/stderr"
status=$?
expected="abcube: $WORK/empty_mesh.json: objects[1].file: warning: mesh \"empty.obj\" has no triangles"
if [ "$status" -eq 0 ] && [ -s "$WORK/empty_mesh.png" ] && [ "$(cat "$WORK/stderr")" = "$expected" ] && [ ! -s "$WORK/stdout" ]; then
  passed=$((passed + 1))
  echo "ok   empty_mesh: $(cat "$WORK/stderr")"
else
  failed=$((failed + 1))
  echo "FAIL empty_mesh: exit $status, stderr was: $(head -c 300 "$WORK/stderr" | tr '\n' '|')"
fi

# A missing material (forgiving OBJ): exit 0, one warning line; hostile names from an OBJ
# are shown escaped, a 200,000-character name cut.
expect_warning() {
  local name=$1 expected=$2
  "$ABCUBE" render "$WORK/$name.json" -o "$WORK/$name.png" --method raytrace > "$WORK/stdout" 2> "$WORK/stderr"
  local status=$?
  if [ "$status" -eq 0 ] && [ -s "$WORK/$name.png" ] && [ "$(wc -l < "$WORK/stderr")" -eq 1 ] &&
     grep -qF -- "$expected" "$WORK/stderr" && [ "$(wc -c < "$WORK/stderr")" -le 600 ] &&
     [ -z "$(tr -d '\n' < "$WORK/stderr" | LC_ALL=C tr -d '[:print:]')" ]; then
    passed=$((passed + 1))
    echo "ok   $name: $(head -c 200 "$WORK/stderr")"
  else
    failed=$((failed + 1))
    echo "FAIL $name: exit $status, stderr was: $(head -c 300 "$WORK/stderr" | tr '\n' '|')"
  fi
}
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl \033]0;pwned\007\033[31mred\nf 1 2 3\n' > "$WORK/escape.obj"
echo "{$HEAD, \"objects\": [{\"type\": \"mesh\", \"file\": \"escape.obj\"}]}" | scene usemtl_escape
expect_warning usemtl_escape 'objects[0].file: warning: mesh "escape.obj": usemtl: material "\e]0;pwned\x07\e[31mred" not found; the default material is used'
{ printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl '; head -c 200000 /dev/zero | tr '\0' 'm'; printf '\nf 1 2 3\n'; } > "$WORK/long.obj"
echo "{$HEAD, \"objects\": [{\"type\": \"mesh\", \"file\": \"long.obj\"}]}" | scene usemtl_long
expect_warning usemtl_long 'mmmmmmmm"... (200000 bytes) not found'

# ---- Bad command lines ------------------------------------------------------------------

expect_rejected unknown_option "--frobnicate" render "$GOOD" --method gpu --gl none --frobnicate
expect_rejected bad_method "--method: must be one of abuffer, zbuffer, envmap, raytrace, gpu, hybrid, gpu_abuffer, got \"photon\"" render "$GOOD" --method photon --gl none
expect_rejected bad_cube_res "--cube-res" render "$GOOD" --method gpu --gl none --cube-res 0
expect_rejected unknown_command "frobnicate" frobnicate "$GOOD"

echo "cli scene_errors: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
