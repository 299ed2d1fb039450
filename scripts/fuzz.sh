#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, ASan + UBSan) and runs each for a bounded time,
# LOCI_FUZZ_SECONDS (default 30), starting from its committed seed corpus. A crash, a leak, a
# sanitizer report, a timeout or an exception other than loci::Error fails the run; the input
# is left in build-fuzz/findings/ and becomes a regression test.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${LOCI_FUZZ_SECONDS:-30}
CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLOCI_FUZZ=ON \
  -DLOCI_BUILD_BENCH=OFF >/dev/null
targets=(sidecar query_text geojson_index shapefile fleet_csv ais_csv sql)
cmake --build build-fuzz -j"$(nproc)" --target "${targets[@]/#/fuzz_}"
mkdir -p build-fuzz/findings
for t in "${targets[@]}"; do
  work=$(mktemp -d)
  cp -r "tests/fuzz/corpus/$t/." "$work/"
  log=build-fuzz/fuzz_$t.log
  if ! ASAN_OPTIONS=detect_leaks=1 ./build-fuzz/tests/fuzz/fuzz_"$t" -max_total_time="$seconds" \
      -timeout=20 -rss_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix=build-fuzz/findings/"$t"- "$work" >"$log" 2>&1; then
    tail -40 "$log"
    echo "fuzz: $t found a failing input (build-fuzz/findings/)" >&2
    rm -rf "$work"
    exit 1
  fi
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo '?')
  echo "fuzz: $t: $runs executions in ${seconds} s, no finding"
  rm -rf "$work"
done
