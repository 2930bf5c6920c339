#!/usr/bin/env bash
# abcube installed as a user installs it, then used from a folder far from the tree:
#   1. `cmake --install BUILD --prefix P`: P/bin/abcube renders every method with no
#      variable set, and the Python module under P's site folder imports and renders;
#   2. `pip install --no-build-isolation .` into a venv made with --system-site-packages
#      (the tree's build folder reused by default, and it says so): `import abcube` from
#      /tmp with no PYTHONPATH, and a render whose image is not black;
#   3. `cmake --install` of a build without the Python module (the README's first command
#      builds the program alone): exit 0, a line saying the module was skipped and how to
#      build it, and the installed program runs.
# Usage: install_package.sh BUILD_DIR SOURCE_DIR PYTHON
set -euo pipefail
BUILD=$(cd "$1" && pwd)
SRC=$(cd "$2" && pwd)
PYTHON=$3
WORK=$(mktemp -d /tmp/abcube_package.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# 1. The prefix.
cmake --install "$BUILD" --prefix "$WORK/prefix" > "$WORK/install.log" || { cat "$WORK/install.log"; fail "cmake --install"; }
[[ -x "$WORK/prefix/bin/abcube" ]] || fail "no bin/abcube installed"
cd "$WORK"
env -i PATH="$WORK/prefix/bin:/usr/bin:/bin" abcube --version | grep -q '^abcube ' || fail "installed abcube --version"
for method in raytrace abuffer zbuffer envmap gpu hybrid; do
  options=(--width 64 --height 48)
  [[ $method == raytrace ]] || options+=(--cube-res 32)
  env -i PATH="$WORK/prefix/bin:/usr/bin:/bin" abcube render "$SRC/scenes/cornell.json" -o "$WORK/p_$method.png" \
    --method "$method" "${options[@]}" 2> "$WORK/err" || { cat "$WORK/err"; fail "installed abcube render --method $method"; }
done
# The image module comes from the prefix: a texture and a TIFF need it.
env -i PATH="$WORK/prefix/bin:/usr/bin:/bin" LD_DEBUG=files abcube render "$SRC/scenes/textured.json" \
  -o "$WORK/p_textured.tif" --width 64 --height 48 --cube-res 32 2> "$WORK/err" ||
  { tail -n 5 "$WORK/err"; fail "installed abcube, a texture to TIFF"; }
grep -q "file=$WORK/prefix/[^ ]*/libabcube_oiio.so" "$WORK/err" || fail "the installed program did not load the prefix's image module"
module=$(find "$WORK/prefix" -name 'abcube*.so' -path '*-packages/*' | head -n 1)
[[ -n $module ]] || fail "no Python module under the prefix's site folder"
site=$(dirname "$module")
PYTHONPATH="$site" "$PYTHON" -c "
import abcube, sys
assert abcube.__file__.startswith('$site'), abcube.__file__
img = abcube.Renderer(gl='none').render(abcube.load_scene('$SRC/scenes/cornell.json'), method='raytrace', width=64, height=48)
assert img.mean() > 0.05, img.mean()
" || fail "the prefix's Python module"

# 2. pip into a venv.
"$PYTHON" -m venv --system-site-packages "$WORK/venv" || fail "python3 -m venv (Debian: python3-venv)"
reuse=()
[[ $BUILD == "$SRC/build" ]] || reuse=(env ABCUBE_CMAKE_BUILD_DIR="$BUILD")  # the default reuses SRC/build
(cd "$SRC" && "${reuse[@]}" "$WORK/venv/bin/python" -m pip install --no-build-isolation --no-index \
   --no-deps -v "$SRC") > "$WORK/pip.log" 2>&1 || { tail -n 30 "$WORK/pip.log"; fail "pip install"; }
[[ -n ${reuse[*]} ]] || grep -q "setup.py: reusing the build in $SRC/build" "$WORK/pip.log" ||
  { tail -n 30 "$WORK/pip.log"; fail "pip did not reuse the tree's build"; }
cd /tmp
env -u PYTHONPATH "$WORK/venv/bin/python" -c "
import abcube
assert abcube.__file__.startswith('$WORK/venv'), abcube.__file__
scene = abcube.load_scene('$SRC/scenes/cornell.json')
img = abcube.Renderer(gl='none').render(scene, method='raytrace', width=64, height=48)
assert img.shape == (48, 64, 3) and img.mean() > 0.05, (img.shape, img.mean())
# A texture needs the image module: the one pip put beside the extension.
abcube.Renderer(gl='none').render(abcube.load_scene('$SRC/scenes/textured.json'), method='raytrace', width=32, height=24)
modules = [l.split()[-1] for l in open('/proc/self/maps') if l.rstrip().endswith('libabcube_oiio.so')]
assert modules and all(m.startswith('$WORK/venv/') for m in modules), modules
print('pip: abcube', abcube.__version__, 'from', abcube.__file__)
" || fail "import abcube from the venv"

# 3. A build without the Python module (hidden for the install, put back on exit).
module=$(ls "$BUILD"/python/abcube*.so | head -n 1)
mv "$module" "$WORK/module.so"
trap 'mv "$WORK/module.so" "$module"; rm -rf "$WORK"' EXIT
cmake --install "$BUILD" --prefix "$WORK/prefix2" > "$WORK/install2.log" 2>&1 ||
  { tail -n 20 "$WORK/install2.log"; fail "cmake --install without the Python module"; }
grep -q "abcube: the Python module was not built, so it is not installed (cmake --build $BUILD --target abcube_python" \
  "$WORK/install2.log" || fail "the skipped module is not named"
env -i PATH="$WORK/prefix2/bin:/usr/bin:/bin" abcube --version | grep -q '^abcube ' || fail "abcube --version from prefix2"
echo "1 passed, 0 failed"
