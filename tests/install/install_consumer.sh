#!/usr/bin/env bash
# The installed package as another project uses it: `cmake --install` of the build into a
# temporary prefix, examples/two_views.cpp configured and built OUTSIDE the tree with
# find_package(abcube) and CMAKE_PREFIX_PATH=prefix, run, its two PNGs checked.
# Usage: install_consumer.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
BUILD=$(cd "$1" && pwd)
SRC=$(cd "$2" && pwd)
WORK=$(mktemp -d /tmp/abcube_install.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# Install the build into the prefix.
cmake --install "$BUILD" --prefix "$WORK/prefix" > "$WORK/install.log" || { cat "$WORK/install.log"; fail "cmake --install"; }
for f in include/abcube/renderer.hpp include/abcube/scene.hpp include/abcube/image.hpp include/abcube/error.hpp; do
  [[ -f "$WORK/prefix/$f" ]] || fail "not installed: $f"
done
[[ -n $(find "$WORK/prefix" -name abcubeConfig.cmake) ]] || fail "no abcubeConfig.cmake installed"

# An outside project: one source file, found through the package config only.
mkdir -p "$WORK/consumer"
cp "$SRC/examples/two_views.cpp" "$WORK/consumer/"
cat > "$WORK/consumer/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.21)
project(abcube_consumer LANGUAGES CXX)
set(CMAKE_CXX_STANDARD 17)
find_package(abcube 0.5 REQUIRED)
add_executable(two_views two_views.cpp)
target_link_libraries(two_views PRIVATE abcube::abcube)
CMAKE
generator=()
command -v ninja > /dev/null && generator=(-G Ninja)
cmake -S "$WORK/consumer" -B "$WORK/consumer/build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DCMAKE_EXPORT_COMPILE_COMMANDS=ON \
  -DCMAKE_PREFIX_PATH="$WORK/prefix" > "$WORK/configure.log" 2>&1 || { cat "$WORK/configure.log"; fail "configure"; }
cmake --build "$WORK/consumer/build" > "$WORK/build.log" 2>&1 || { cat "$WORK/build.log"; fail "build"; }

# Run it (no source tree on its include path: the build used the prefix's headers).
grep -q "$SRC/include" "$WORK/consumer/build/compile_commands.json" 2> /dev/null && fail "consumer compiled against the source tree"
mkdir -p "$WORK/out"
"$WORK/consumer/build/two_views" "$WORK/out" "$SRC/scenes/cornell.json" || fail "two_views exited $?"
for v in 0 1; do
  [[ -s "$WORK/out/view$v.png" ]] || fail "view$v.png missing or empty"
done
cmp -s "$WORK/out/view0.png" "$WORK/out/view1.png" && fail "the two views are the same image"
echo "install consumer: ok"
