#!/usr/bin/env bash
# A lean start (docs/install.md): the program needs no OpenImageIO to start, to render, or
# to read and write PNG and EXR; the image module (libabcube_oiio.so) is loaded only for
# another format or a texture, and its absence fails only those, with one line.
# Usage (ctest runs it so): bash lean_start.sh /path/to/abcube /path/to/repo
set -u
ABCUBE=$1
REPO=$2
CLI_TEST=lean_start
. "$(dirname "$0")/lib/check.sh"

# The shared objects a run opens, from the dynamic loader's own log.
opened() { LD_DEBUG=files "$@" 2>&1 >/dev/null | grep -o 'file=[^ ]*' | sort -u; }

check "the program does not link OpenImageIO" bash -c "! readelf -d '$ABCUBE' | grep -q OpenImageIO"
check "--version opens no OpenImageIO" bash -c "! (LD_DEBUG=files '$ABCUBE' --version 2>&1 | grep -q libOpenImageIO)"
for ext in png exr; do
  opened "$ABCUBE" render "$REPO/scenes/cornell.json" -o "$WORK/c.$ext" --width 40 --height 30 --cube-res 32 > "$WORK/libs"
  check "render to .$ext writes it" [ -s "$WORK/c.$ext" ]
  check "render to .$ext opens no OpenImageIO" bash -c "! grep -q -e libOpenImageIO -e libabcube_oiio '$WORK/libs'"
done
check "compare of PNG and EXR opens no OpenImageIO" \
  bash -c "! (LD_DEBUG=files '$ABCUBE' compare '$WORK/c.png' '$WORK/c.exr' 2>&1 | grep -q libOpenImageIO)"
opened "$ABCUBE" render "$REPO/scenes/cornell.json" -o "$WORK/c.tif" --width 40 --height 30 --cube-res 32 > "$WORK/libs"
check "render to .tif writes it" [ -s "$WORK/c.tif" ]
check "render to .tif loads the image module" grep -q libabcube_oiio "$WORK/libs"
"$ABCUBE" render "$REPO/scenes/textured.json" -o "$WORK/t.png" --width 40 --height 30 --cube-res 32 2> "$WORK/err"
status=$?
check "a textured scene renders ($(cat "$WORK/err"))" [ $status -eq 0 ]

# Without the module: PNG and EXR still work; another format fails with one line, exit 1,
# naming the module and where it was looked for, and writes nothing.
export ABCUBE_IMAGE_MODULE=$WORK/absent/libabcube_oiio.so
"$ABCUBE" render "$REPO/scenes/cornell.json" -o "$WORK/n.png" --width 40 --height 30 --cube-res 32 2> "$WORK/err"
status=$?
check "without the module, PNG renders ($(cat "$WORK/err"))" [ $status -eq 0 ]
"$ABCUBE" render "$REPO/scenes/cornell.json" -o "$WORK/n.tif" --width 40 --height 30 --cube-res 32 2> "$WORK/err"
status=$?
check "without the module, .tif exits 1 (got $status)" [ $status -eq 1 ]
check "without the module: one line" [ "$(wc -l < "$WORK/err")" -eq 1 ]
check "without the module: names it and the place ($(cat "$WORK/err"))" \
  grep -q "needs OpenImageIO, through abcube's image module libabcube_oiio.so.*$WORK/absent" "$WORK/err"
check "without the module: nothing written" [ ! -e "$WORK/n.tif" ]
unset ABCUBE_IMAGE_MODULE
echo "cli lean_start: $passed passed, $failed failed"
[ $failed -eq 0 ]
