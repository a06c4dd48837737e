#!/usr/bin/env bash
# Installs exactly the Debian 12 packages hemibake builds and tests with. Idempotent.
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config git
  libopenmesh-dev libosmesa6-dev libglm-dev libopenimageio-dev openimageio-tools libtinygltf-dev
  libembree-dev libtbb-dev libcli11-dev nlohmann-json3-dev libstb-dev libeigen3-dev
  libgtest-dev libbenchmark-dev
  clang libclang-rt-14-dev python3
  nodejs npm
)
# A package counts as present when dpkg has it installed. Node.js and npm also count when their commands exist:
# NodeSource's (or nvm's) node is not Debian's package, and NodeSource's nodejs bundles npm and conflicts with
# Debian's npm package, so asking apt for npm there would fail.
present() {
  case "$1" in
    nodejs) command -v node >/dev/null 2>&1 && return 0 ;;
    npm) command -v npm >/dev/null 2>&1 && return 0 ;;
  esac
  dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"
}
missing=()
for p in "${packages[@]}"; do
  present "$p" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The Khronos glTF validator (npm package), which tests run on every glb hemibake writes
# (scripts/validate-gltf.mjs). Installed into tools/node_modules (git-ignored) with the machine's Node.js.
GLTF_VALIDATOR_VERSION="2.0.0-dev.3.10"
cd "$(dirname "$0")/.."
# The tests that validate glbs fail (never skip) without it, so a missing node/npm is an error here too.
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  echo "install-deps: node/npm still missing after installing nodejs and npm; cannot install the glTF validator" >&2
  exit 1
fi
installed="$(node -p "require('./tools/node_modules/gltf-validator/package.json').version" 2>/dev/null || true)"
if [ "$installed" != "$GLTF_VALIDATOR_VERSION" ]; then
  mkdir -p tools
  npm install --prefix tools --no-save --no-audit --no-fund --loglevel=error "gltf-validator@$GLTF_VALIDATOR_VERSION"
fi
installed="$(node -p "require('./tools/node_modules/gltf-validator/package.json').version" 2>/dev/null || true)"
if [ "$installed" != "$GLTF_VALIDATOR_VERSION" ]; then
  echo "install-deps: the glTF validator $GLTF_VALIDATOR_VERSION did not install into tools/node_modules" >&2
  exit 1
fi
