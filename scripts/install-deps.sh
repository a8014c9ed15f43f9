#!/usr/bin/env bash
# Installs every build, test and run dependency of QuadSketch from Debian 12 packages.
# Usage: scripts/install-deps.sh        (uses sudo when not root)
set -euo pipefail
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
PACKAGES=(
  build-essential cmake ninja-build pkg-config git time python3
  libopenmesh-dev libeigen3-dev libsuitesparse-dev libopenblas-dev
  libglfw3-dev libglm-dev libimgui-dev libstb-dev
  nlohmann-json3-dev libcli11-dev libgtest-dev libbenchmark-dev
  coinor-libipopt-dev
  libgl-dev libegl-dev libopengl-dev libgl1-mesa-dri libegl-mesa0 mesa-utils
  fonts-dejavu-core
  xvfb xauth
  assimp-utils
  clang libclang-rt-14-dev
)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages already installed"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -qq
$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}"
