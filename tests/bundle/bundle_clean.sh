#!/usr/bin/env bash
# tools/bundle.sh end to end (docs/install.md "A bundle for a bare machine"): the bundled
# program renders every method through each GL path with an empty environment (env -i), the
# bundled GL tests run, and, where a mount namespace can be made (root), the program runs
# with the system's library folder holding glibc alone and reports what it finds.
# Usage (ctest runs it so): bash bundle_clean.sh /path/to/repo BUILD_DIR
set -u
REPO=$1
BUILD=$2
CLI_TEST=bundle
. "$REPO/tests/cli/lib/check.sh"

ABCUBE_BUILD=$BUILD bash "$REPO/tools/bundle.sh" "$WORK" > "$WORK/bundle.log" 2>&1
status=$?
check "tools/bundle.sh exits 0 ($(tail -n 3 "$WORK/bundle.log"))" [ $status -eq 0 ]
B=$WORK/abcube
check "the bundle holds no driver library" bash -c "! ls '$B/lib' | grep -q -e nvidia -e libcuda"
check "the bundle holds no OpenImageIO" bash -c "! ls '$B/lib' | grep -q -i openimageio"
for method in raytrace abuffer zbuffer envmap gpu hybrid; do
  for gl in egl-surfaceless osmesa; do
    n=(--cube-res 16)
    [[ $method == raytrace ]] && n=()
    env -i "$B/bin/abcube" render "$B/scenes/cornell.json" -o "$WORK/$method-$gl.png" --width 32 --height 24 \
      "${n[@]}" --method "$method" --gl "$gl" > /dev/null 2> "$WORK/err"
    status=$?
    check "env -i: $method --gl $gl renders ($(head -c 300 "$WORK/err"))" [ $status -eq 0 ]
    check "env -i: $method --gl $gl wrote its image" [ -s "$WORK/$method-$gl.png" ]
  done
done
# The GL tests through each API, but the two that draw textured scenes: textures need the
# image module, which the bundle leaves out.
untextured='-ZbufferGl.TexturedFloorMatchesCpuShading:ZbufferGl.PinnedSoupDrawsAsCopiedSoup'
for api in egl osmesa; do
  env -i ABCUBE_TEST_GL=$api "$B/bin/test_gl" --gtest_filter="$untextured" > "$WORK/gl.log" 2>&1
  status=$?
  check "env -i: the bundled GL tests pass on $api ($(tail -n 3 "$WORK/gl.log"))" [ $status -eq 0 ]
done

# The system's library folder with glibc alone in it (a bind mount in a private namespace).
if unshare -m true 2> /dev/null; then
  mkdir -p "$WORK/glibc"
  for f in libc.so.6 libm.so.6 ld-linux-x86-64.so.2 libpthread.so.0 libdl.so.2 librt.so.1 libresolv.so.2; do
    cp -L "/usr/lib/x86_64-linux-gnu/$f" "$WORK/glibc/" 2> /dev/null
  done
  unshare -m /bin/sh -c "mount --bind '$WORK/glibc' /usr/lib/x86_64-linux-gnu &&
    env -i '$B/bin/abcube' info > '$WORK/info.txt' 2>&1 &&
    env -i '$B/bin/abcube' render '$B/scenes/cornell.json' -o '$WORK/hidden.png' --width 32 --height 24 \
      --cube-res 16 --method hybrid" > "$WORK/ns.log" 2>&1
  status=$?
  check "system libraries hidden: info and a hybrid render ($(tail -n 3 "$WORK/ns.log"))" [ $status -eq 0 ]
  check "system libraries hidden: info finds a GL path" grep -q "GL_RENDERER:" "$WORK/info.txt"
else
  echo "bundle: no mount namespace here (not root): the hidden-libraries run is skipped"
fi
echo "bundle: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
