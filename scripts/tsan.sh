#!/usr/bin/env bash
# Builds only the concurrency suite under ThreadSanitizer and runs it: many threads querying
# the same built indexes (and the same memory-mapped sidecar), every answer against brute force.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-tsan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLOCI_SANITIZE_THREAD=ON \
  -DLOCI_BUILD_BENCH=OFF >/dev/null
cmake --build build-tsan -j"$(nproc)" --target test_concurrent_queries
TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1:suppressions=scripts/tsan.supp \
  ./build-tsan/tests/concurrency/test_concurrent_queries
