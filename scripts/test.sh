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
./build-asan/tests/test_cli --gtest_brief=1

echo "== release suites (CTest)"
ctest --test-dir build --output-on-failure -j"$jobs"
