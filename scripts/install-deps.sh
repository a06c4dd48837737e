#!/usr/bin/env bash
# Installs exactly the Debian 12 packages hemibake builds and tests with. Idempotent.
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config git
  libopenmesh-dev libosmesa6-dev libglm-dev libopenimageio-dev openimageio-tools libtinygltf-dev
  libembree-dev libtbb-dev libcli11-dev nlohmann-json3-dev libstb-dev libeigen3-dev
  libgtest-dev libbenchmark-dev
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
