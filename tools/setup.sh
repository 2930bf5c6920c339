#!/usr/bin/env bash
# Installs the Debian packages abcube needs, by need (idempotent; skips what is present):
#   bash tools/setup.sh           building and rendering: compiler, CMake, GL run-times, the libraries
#   bash tools/setup.sh --python  and the Python module: its headers, pybind11, numpy, pip, venv
#   bash tools/setup.sh --test    and everything the tests and tools use: GoogleTest, pytest, Dask,
#                                 clang-14 with libFuzzer and its sanitizers, clang-format, POV-Ray, OpenImageIO's
#                                 tools, the assimp test models, headless Chromium (the report's page),
#                                 GNU time (a process's peak memory)
# GL headers come from glad (generated at configure time); libEGL and libOSMesa are opened at
# run time, so only their run-time packages are needed. Run as root, or with sudo available.
set -euo pipefail

BASE=(
  build-essential cmake ninja-build git python3
  libegl1 libegl-mesa0 libgl1-mesa-dri libosmesa6
  libglm-dev python3-glad
  libopenimageio-dev libpng-dev libopenexr-dev
  nlohmann-json3-dev libtinyobjloader-dev libtinygltf-dev libembree-dev libcli11-dev
)
PYTHON=(python3-dev pybind11-dev python3-numpy python3-pip python3-venv python3-setuptools python3-wheel)
TEST=(
  libgtest-dev libgmock-dev python3-pytest python3-distributed openimageio-tools
  clang-14 clang-format-14 libclang-rt-14-dev libfuzzer-14-dev llvm-14 assimp-testmodels povray chromium time
)

usage() { echo "usage: bash tools/setup.sh [--python | --test]" >&2; exit 2; }
PACKAGES=("${BASE[@]}")
case "${1:-}" in
  "") ;;
  --python) PACKAGES+=("${PYTHON[@]}") ;;
  --test) PACKAGES+=("${PYTHON[@]}" "${TEST[@]}") ;;
  *) usage ;;
esac
[ $# -le 1 ] || usage

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
