#!/usr/bin/env bash
# One command from a fresh Debian 12 machine: install dependencies, build, and run hemibake on the example scene.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)" --target hemibake
./build/hemibake info examples/cornell_box.gltf
