#!/usr/bin/env bash
# The quick start's second command: builds and runs the whole test suite twice, once optimised
# and once under AddressSanitizer + UndefinedBehaviorSanitizer. Tests labelled "large" need
# datasets/fetch.sh to have run and skip themselves otherwise.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
jobs=$(nproc)

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$jobs"
ctest --test-dir build -j"$jobs" --output-on-failure

cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Release -DLOCI_SANITIZE=ON \
  -DLOCI_BUILD_BENCH=OFF >/dev/null
cmake --build build-asan -j"$jobs"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build-asan -j"$jobs" --output-on-failure -LE large
