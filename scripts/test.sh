#!/usr/bin/env bash
# The whole test suite: builds everything in Release and runs CTest (all GoogleTest suites), then rebuilds the
# loader and CLI suites with AddressSanitizer + UndefinedBehaviorSanitizer and runs them (bad input must never
# crash). Exit code 0 only when every test passed.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="${HEMIBAKE_JOBS:-$(nproc)}"

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$jobs"

echo "== sanitizer build (ASan + UBSan): loader and CLI suites"
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHEMIBAKE_SANITIZE=ON -DHEMIBAKE_BUILD_BENCH=OFF >/dev/null
cmake --build build-asan -j"$jobs" --target test_mesh test_cli
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:halt_on_error=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0"
./build-asan/tests/test_mesh --gtest_brief=1
# The two Cornell accuracy checks run the same code paths as the other CLI tests, only for minutes longer: they
# run in the release suites below.
./build-asan/tests/test_cli --gtest_brief=1 --gtest_filter='-CliCornellMedium.*:CliRender.CornellMatchesThePathTracedCameraImage'

echo "== fuzzing the glTF loader (libFuzzer + ASan/UBSan, clang, ${HEMIBAKE_FUZZ_SECONDS:-90} s)"
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHEMIBAKE_FUZZ=ON \
  -DHEMIBAKE_BUILD_TESTS=OFF -DHEMIBAKE_BUILD_BENCH=OFF >/dev/null
cmake --build build-fuzz -j"$jobs" --target fuzz_gltf_loader
# New inputs go to a scratch corpus; the seed corpus in the repo (tests/fuzz/corpus) is only read.
fuzz_corpus="$(mktemp -d)"
trap 'rm -rf "$fuzz_corpus"' EXIT
if ! ./build-fuzz/tests/fuzz/fuzz_gltf_loader "$fuzz_corpus" tests/fuzz/corpus -max_total_time="${HEMIBAKE_FUZZ_SECONDS:-90}" \
     -max_len=65536 -print_final_stats=1 -artifact_prefix=build-fuzz/ >build-fuzz/fuzz.log 2>&1; then
  tail -n 60 build-fuzz/fuzz.log
  echo "fuzz_gltf_loader found a crash; the input is saved as build-fuzz/crash-* (log: build-fuzz/fuzz.log)" >&2
  exit 1
fi
grep -E "^(Done|stat::average_exec_per_sec)" build-fuzz/fuzz.log

echo "== release suites (CTest)"
ctest --test-dir build --output-on-failure -j"$jobs"
