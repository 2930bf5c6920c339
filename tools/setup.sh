#!/usr/bin/env bash
# Installs the Debian packages abcube needs (idempotent; skips what is present).
# GL headers come from glad (generated at configure time); libEGL and libOSMesa are
# opened at run time, so only their run-time packages are needed.
# clang-14, its sanitizer run-times, libFuzzer and llvm-symbolizer (llvm-14) build and run
# the fuzz harnesses (tools/fuzz.sh); assimp-testmodels' OBJ and MTL files seed them.
# Run as root, or with sudo available. Safe to run many times.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build python3
  libegl1 libegl-mesa0 libgl1-mesa-dri libosmesa6
  libglm-dev python3-glad
  libopenimageio-dev openimageio-tools
  nlohmann-json3-dev libtinyobjloader-dev libtinygltf-dev libembree-dev
  libgtest-dev libgmock-dev libbenchmark-dev libcli11-dev
  python3-dev pybind11-dev python3-numpy python3-pytest python3-distributed
  clang-14 libclang-rt-14-dev libfuzzer-14-dev llvm-14 assimp-testmodels
  povray
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "setup: done"
