#!/usr/bin/env bash
# The whole test suite: builds everything in Release and runs CTest (all GoogleTest suites), then rebuilds the
# loader and CLI suites and the small raster and baker cases with AddressSanitizer + UndefinedBehaviorSanitizer and
# runs them (bad input must never crash), and fuzzes the loader and the mesh stages after it (libFuzzer). Exit code
# 0 only when every test passed.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="${HEMIBAKE_JOBS:-$(nproc)}"

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$jobs"

echo "== sanitizer build (ASan + UBSan): loader, CLI, raster and baker suites"
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHEMIBAKE_SANITIZE=ON -DHEMIBAKE_BUILD_BENCH=OFF >/dev/null
cmake --build build-asan -j"$jobs" --target test_mesh test_cli test_raster test_baker
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:halt_on_error=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0"
./build-asan/tests/test_mesh --gtest_brief=1
# The two Cornell accuracy checks run the same code paths as the other CLI tests, only for minutes longer: they
# run in the release suites below.
./build-asan/tests/test_cli --gtest_brief=1 --gtest_filter='-CliCornellMedium.*:CliRender.CornellMatchesThePathTracedCameraImage'
# Raster and baker: every test but those that take more than ~0.15 s in Release (seconds to minutes under the
# sanitizers); they exercise the same code on bigger scenes, and run in the release suites below.
./build-asan/tests/test_raster --gtest_brief=1 --gtest_filter='-Hemicube.ErrorShrinksWithResolution:GroundTruth1ab/*:GroundTruth1cd/*:Resolutions/*/3:HemicubeWeights.CentrePixelMatchesTheMidpointDeltaFormFactor:Hemicube.ItemIdsNameTheElementEachPixelSees'
./build-asan/tests/test_baker --gtest_brief=1 --gtest_filter='-ThinWall.*:WallOnSlabs.*:SunkBox.*:HangingPanel.*:EveryPreset/SealedRoom.StaysExactlyDark/2:EveryPreset/SealedRoom.StaysExactlyDark/3:BakeExtremes.*:WrittenLightmapSeams.*:LightmapBaker.NoTexelIsInterpolatedAcrossAWallStandingOnItsSurface:ExposedArea.PartlyCoveredElementsReceiveTheIrradianceOfTheirExposedPart:ExposedArea.PatchesSumTheirElementsExposedAreas:LightmapBaker.SeamsOnSmoothSurfacesAreStitched:LightmapBaker.EmitterOverSquare*:ReferenceTexels.*:PathTracer.ResultsDoNotDependOnThreadCountAndThroughputIsReported:PathTracer.EmissiveRectangleMatchesCornerFormFactors:PathTracer.FurnaceIncidentRadianceIsEmissionOverOneMinusReflectance:OneEmittingFace.*:CornellExtremes.*:CornellDirect.*:EnergyBalance.*:GltfWriter.CornellBoxAt128TexelsPerMetrePassesTheValidator:EmissiveAreaLights.OpenScenePowerBalances:EmissiveAreaLights.FurnaceSolvedWithRayTracedEmitters:LightProbe.FurnaceSeesLeOverOneMinusRhoInEveryDirection'

# Fuzzers: new inputs go to scratch corpora; the seed corpus in the repo (tests/fuzz/corpus) is only read. A
# finding fails the run with the input saved as build-fuzz/crash-* (or timeout-*, oom-*).
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHEMIBAKE_FUZZ=ON \
  -DHEMIBAKE_BUILD_TESTS=OFF -DHEMIBAKE_BUILD_BENCH=OFF >/dev/null
cmake --build build-fuzz -j"$jobs" --target fuzz_gltf_loader fuzz_mesh_unwrap
fuzz_scratch="$(mktemp -d)"
trap 'rm -rf "$fuzz_scratch"' EXIT
fuzz() {  # name seconds [libFuzzer arguments...]
  local name="$1" seconds="$2"
  shift 2
  echo "== fuzzing $name (libFuzzer + ASan/UBSan, clang, $seconds s)"
  mkdir -p "$fuzz_scratch/$name"
  if ! "./build-fuzz/tests/fuzz/$name" "$fuzz_scratch/$name" "$@" -max_total_time="$seconds" -timeout=30 \
       -print_final_stats=1 -artifact_prefix=build-fuzz/ >"build-fuzz/$name.log" 2>&1; then
    tail -n 60 "build-fuzz/$name.log"
    echo "$name found a crash, hang or broken promise; the input is in build-fuzz/ (log: build-fuzz/$name.log)" >&2
    exit 1
  fi
  grep -E "^(Done|stat::average_exec_per_sec)" "build-fuzz/$name.log"
}
# Any bytes as a glTF file.
fuzz fuzz_gltf_loader "${HEMIBAKE_FUZZ_SECONDS:-60}" tests/fuzz/corpus -max_len=65536
# Small random meshes through subdivision, unwrapping and texels; inputs of any length from the start (a mesh
# needs a few hundred bytes), not grown slowly from a few; tests/fuzz/corpus_unwrap keeps past findings.
fuzz fuzz_mesh_unwrap "${HEMIBAKE_FUZZ_UNWRAP_SECONDS:-30}" tests/fuzz/corpus_unwrap -max_len=1024 -len_control=0

echo "== release suites (CTest)"
ctest --test-dir build --output-on-failure -j"$jobs"
