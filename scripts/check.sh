#!/usr/bin/env bash
# README command 2 (and what .ci/run runs): install, build with warnings as errors, run the unit
# tests under AddressSanitizer + UBSan, then the whole suite with CTest (format check included).
set -euo pipefail
cd "$(dirname "$0")/.."

./scripts/install-deps.sh
jobs=$(nproc)

echo "== AddressSanitizer + UBSan build of the core unit tests"
cmake -S . -B build/asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSEEP_SANITIZE=ON \
  -DSEEP_BUILD_SERVICE=OFF -DSEEP_BUILD_BENCH=OFF >/dev/null
cmake --build build/asan -j"$jobs"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build/asan -L unit --output-on-failure -j"$jobs"

echo "== Release build and the whole test suite"
cmake -S . -B build/check -G Ninja -DCMAKE_BUILD_TYPE=Release -DSEEP_WERROR=ON >/dev/null
cmake --build build/check -j"$jobs"
ctest --test-dir build/check --output-on-failure -j"$jobs"
