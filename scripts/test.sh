#!/usr/bin/env bash
# The quick start's second command: builds and runs the whole test suite twice, once optimised
# and once under AddressSanitizer + UndefinedBehaviorSanitizer, then the concurrency suite
# under ThreadSanitizer. The tests labelled "large" run
# on the fetched Natural Earth layers and take minutes: they are opt-in, with
# LOCI_TEST_LARGE=1 after `bash datasets/fetch.sh` (they skip themselves without the cache).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
jobs=$(nproc)

# CI fails on a compiler warning (LOCI_WARNINGS_AS_ERRORS=ON); elsewhere they are shown.
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DLOCI_WARNINGS_AS_ERRORS="${LOCI_WARNINGS_AS_ERRORS:-OFF}" >/dev/null
cmake --build build -j"$jobs"
large=(-LE large)
[ "${LOCI_TEST_LARGE:-0}" = 1 ] && large=()
ctest --test-dir build -j"$jobs" --output-on-failure "${large[@]}"

cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Release -DLOCI_SANITIZE=ON \
  -DLOCI_BUILD_BENCH=OFF >/dev/null
cmake --build build-asan -j"$jobs"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build-asan -j"$jobs" --output-on-failure -LE large

bash scripts/tsan.sh
