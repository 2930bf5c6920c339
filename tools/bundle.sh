#!/usr/bin/env bash
# Makes one folder that runs abcube on a bare x86-64 Linux: no Debian packages, no package
# registry, an NVIDIA driver or none.
#   tools/bundle.sh OUT [--archive]
# OUT/abcube/ holds:
#   bin/abcube, bin/test_gl   launchers: the bundled dynamic loader runs the program with
#                             only the bundle's libraries (and the system's for what the
#                             bundle lacks: a GPU driver)
#   lib/                      the program, the GL tests, and every shared object a render
#                             of each method opens here (LD_DEBUG=files), glibc included:
#                             Debian 12's libstdc++ and LLVM need GLIBC_2.36, newer than a
#                             glibc 2.35 system has; the bundled loader brings its own
#   lib/dri/                  Mesa's llvmpipe (EGL surfaceless), for the CPU side by side
#   share/glvnd/egl_vendor.d  Mesa's EGL vendor file; the system's (NVIDIA's) are read first
#   scenes/                   the repository's scenes
# Never bundled: a GPU driver's own libraries (libnvidia*, libEGL_nvidia, libcuda), and the
# image module (OpenImageIO and its 280 libraries): the bundle writes PNG and EXR, and
# textured scenes need the module.
# --archive: also OUT/abcube.tar.xz, the folder compressed (what travels), and its size.
# Needs build/abcube and build/tests/test_gl (cmake --build build).
set -euo pipefail
cd "$(dirname "$0")/.."
[[ $# -ge 1 ]] || { echo "usage: tools/bundle.sh OUT [--archive]" >&2; exit 2; }
OUT=$1
ARCHIVE=${2:-}
BUILD=${ABCUBE_BUILD:-build}
for f in "$BUILD/abcube" "$BUILD/tests/test_gl"; do
  [[ -x $f ]] || { echo "bundle: $f is missing: build it first (cmake --build $BUILD)" >&2; exit 2; }
done
B=$OUT/abcube
rm -rf "$B"
mkdir -p "$B/bin" "$B/lib/dri" "$B/share/glvnd/egl_vendor.d" "$B/scenes"
cp "$BUILD/abcube" "$B/lib/abcube.bin"
cp "$BUILD/tests/test_gl" "$B/lib/test_gl.bin"
cp -r scenes/. "$B/scenes/"

# What each method opens here, through each GL path (the loader's own log).
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
opened() { LD_DEBUG=files "$@" 2>&1 >/dev/null | sed -n 's/.*file=\([^ ]*\).*/\1/p'; }
{
  for method in raytrace abuffer zbuffer envmap gpu hybrid; do
    n=(--cube-res 16)
    [[ $method == raytrace ]] && n=()
    for gl in egl osmesa; do
      opened "$BUILD/abcube" render scenes/cornell.json -o "$work/x.png" --width 16 --height 12 "${n[@]}" \
        --method "$method" --gl "$gl"
    done
  done
  opened "$BUILD/abcube" info
  ldd "$BUILD/abcube" "$BUILD/tests/test_gl" | awk '/=>/ {print $3} /ld-linux/ && !/=>/ {print $1}'
} | sort -u > "$work/names"

# Each name to its file (ldconfig's cache for bare names), driver libraries left out.
cache=$(ldconfig -p)
while IFS= read -r name; do
  [[ -n $name ]] || continue
  case $name in *nvidia* | *libcuda* | */abcube | */test_gl | *libabcube_oiio*) continue ;; esac
  if [[ $name == /* ]]; then
    path=$name
  else
    path=$(awk -v n="$name" '$1 == n {print $NF; exit}' <<< "$cache")
  fi
  [[ -n $path && -e $path ]] || continue
  if [[ $path == */dri/* ]]; then
    cp -L "$path" "$B/lib/dri/$(basename "$path")"
  else
    cp -L "$path" "$B/lib/$(basename "$name")"
  fi
done < "$work/names"
# The loader under the name the launchers call.
cp -L /lib64/ld-linux-x86-64.so.2 "$B/lib/ld-linux-x86-64.so.2"
cat > "$B/share/glvnd/egl_vendor.d/50_mesa.json" <<'JSON'
{"file_format_version": "1.0.0", "ICD": {"library_path": "libEGL_mesa.so.0"}}
JSON

for program in abcube test_gl; do
  cat > "$B/bin/$program" <<EOF
#!/bin/sh
# The bundled $program through the bundled loader (tools/bundle.sh).
here=\$(cd "\$(dirname "\$0")/.." && pwd)
export __EGL_VENDOR_LIBRARY_DIRS="\${__EGL_VENDOR_LIBRARY_DIRS:-/etc/glvnd/egl_vendor.d:/usr/share/glvnd/egl_vendor.d}:\$here/share/glvnd/egl_vendor.d"
export LIBGL_DRIVERS_PATH="\${LIBGL_DRIVERS_PATH:-\$here/lib/dri}"
exec "\$here/lib/ld-linux-x86-64.so.2" --library-path "\$here/lib" "\$here/lib/$program.bin" "\$@"
EOF
  chmod +x "$B/bin/$program"
done
echo "bundle: $B: $(find "$B/lib" -name '*.so*' | wc -l) shared objects, $(du -sm "$B" | cut -f1) MiB"
if [[ $ARCHIVE == --archive ]]; then
  tar -C "$OUT" -cf - abcube | xz -T0 -9e > "$OUT/abcube.tar.xz"  # the smallest xz makes: the bundle is near its budget
  echo "bundle: $OUT/abcube.tar.xz: $(awk -v b="$(stat -c %s "$OUT/abcube.tar.xz")" 'BEGIN {printf "%.1f", b / 1048576}') MiB"
fi
