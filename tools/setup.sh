#!/usr/bin/env bash
# Installs the Debian packages abcube needs (idempotent; skips what is present).
# Run as root, or with sudo available. Safe to run many times.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config python3
  libegl-dev libegl1-mesa-dev libgl-dev libosmesa6-dev libgles-dev mesa-utils
  libegl-mesa0 libgl1-mesa-dri
  libglm-dev python3-glad
  libopenimageio-dev openimageio-tools
  nlohmann-json3-dev libtinyobjloader-dev
  libgtest-dev libgmock-dev libbenchmark-dev
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
