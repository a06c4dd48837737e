#!/usr/bin/env bash
# One command from a fresh Debian 12 machine: install dependencies, build, and bake the example scene into
# out/cornell_box/ (lightmapped glb, EXR lightmaps, bake.json).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)" --target hemibake
./build/hemibake info examples/cornell_box.gltf
./build/hemibake bake examples/cornell_box.gltf -o out/cornell_box --progress
