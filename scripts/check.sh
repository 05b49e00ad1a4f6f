#!/usr/bin/env bash
# README command 2 (and what .ci/run runs): install; the sanitizer builds (AddressSanitizer, with
# UBSan on the core: the core, service and client tests; ThreadSanitizer: the `concurrency`
# tests), each -O1 and building only the targets its tests need; then the Release build with
# warnings as errors and the whole suite with CTest (format check included). Each stage prints
# its time.
set -euo pipefail
cd "$(dirname "$0")/.."

./scripts/install-deps.sh
jobs=$(nproc)
stage_start=$SECONDS
stage_done() { echo "== $1: $((SECONDS - stage_start)) s"; stage_start=$SECONDS; }

# The sanitizer builds: -O1 (what the sanitizers' manuals recommend for speed with useful stacks),
# -g1 (line tables: all a sanitizer's stack trace prints, at a third of -g's object size), no
# benchmarks, warnings not errors (the Release build below is the warnings gate; GCC 12 at -O1
# under ASan reports std::regex's std::function members as maybe-uninitialized). The system gRPC
# and protobuf are not instrumented: ASan still checks our code around them, and the TSan tests
# use no gRPC at all.
# Unity batches (CMake's CMAKE_UNITY_BUILD, 8 files a batch) in every build here: a test file and
# a core or service file spend most of their compile time in the same headers (GoogleTest, gRPC,
# protobuf, Eigen), which a batch parses once: a Release build takes about two-thirds of the time
# it takes one file a unit (docs/development.md). A batch
# keeps every file's own names apart: a name two files both define at file scope stops the build.
# The benches (bench/CMakeLists.txt) and the generated protobuf code stay one file a unit.
unity=(-G Ninja -DCMAKE_UNITY_BUILD=ON)
sanitizer_flags=("${unity[@]}" -DCMAKE_BUILD_TYPE=None -DSEEP_BUILD_BENCH=OFF -DSEEP_WERROR=OFF)

echo "== AddressSanitizer (+ UBSan on the core) build of the core, service and client tests"
cmake -S . -B build/asan "${sanitizer_flags[@]}" -DSEEP_SANITIZE=ON \
  -DCMAKE_CXX_FLAGS="-O1 -g1" >/dev/null
# The test folders' own targets (Ninja's <folder>/all), with what they need (seepd, seep).
cmake --build build/asan -j"$jobs" --target tests/core/all tests/service/all tests/client/all
stage_done "ASan build"
# detect_leaks: a leak fails the test. The chaos test (label `chaos`, 12 restarts of seepd) runs
# in the Release suite only: under ASan it would add minutes and find nothing the crash tests do
# not exercise.
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
ctest --test-dir build/asan -L 'unit|service|client' -LE chaos --output-on-failure -j"$jobs"
unset ASAN_OPTIONS UBSAN_OPTIONS
stage_done "ASan tests"

echo "== ThreadSanitizer build of the concurrency tests"
cmake -S . -B build/tsan "${sanitizer_flags[@]}" \
  -DCMAKE_CXX_FLAGS="-O1 -g1 -fsanitize=thread" -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=thread \
  >/dev/null
cmake --build build/tsan -j"$jobs" --target seep_concurrency_tests seep_core_team_tests
TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 \
  ctest --test-dir build/tsan -L concurrency --output-on-failure -j"$jobs"
stage_done "TSan build and tests"

echo "== Release build and the whole test suite"
cmake -S . -B build/check "${unity[@]}" -DCMAKE_BUILD_TYPE=Release -DSEEP_WERROR=ON >/dev/null
cmake --build build/check -j"$jobs"
ctest --test-dir build/check --output-on-failure -j"$jobs"
stage_done "Release build and suite"
