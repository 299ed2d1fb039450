#!/usr/bin/env bash
# Instruction counts of each benchmark phase under callgrind: stable on a busy machine where
# wall time is not. Usage: tests/bench/callgrind.sh [BUILD_DIR] [bench_rtree options...]
# Prints, per phase function, the inclusive instruction count per query or per box.
set -euo pipefail
build=${1:-build}
shift || true
out=$(mktemp)
trap 'rm -f "$out"' EXIT
valgrind --tool=callgrind --callgrind-out-file="$out" "$build/tests/bench/bench_rtree" --reps 1 "$@" >/dev/null 2>&1
callgrind_annotate --inclusive=yes "$out" 2>/dev/null |
  grep -E '(loci|boost|geos|sidx)_(windows|nearest|pack|insert_all|build)' |
  sed -E 's/^ *([0-9,]+) .*\?\?\?:(.*)$/\1 \2/' | cut -c1-160
