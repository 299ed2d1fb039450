#!/usr/bin/env bash
# The `loci query` path on a big sidecar against a small one, and nearest-n in batch:
#   1. opening: one window query on the fetched coastline's per-segment sidecar (4.8 M
#      segments, about 260 MB) against the same query on the bundled sample's (19 k segments,
#      1 MB): median wall time of 7 runs, resident memory, and instructions (valgrind) when
#      valgrind is installed. Opening must not grow with the file.
#   2. a --nearest-file batch of N nearest-10 queries (default 10000, fixed seed) on one core
#      (-j 1) on the coastline sidecar, median of 5 runs: queries per second, start-up and
#      opening included;
#      beside it the library's own nearest-10 on the same segment boxes (`loci bench`: a
#      packed R-tree in memory, random points in the layer's extent) and the ratio.
#   3. per feature: one window over Funen on the coastline as a shapefile indexed per feature
#      (converted once with ogr2ogr), which `loci` answers reading the candidates' records
#      itself, against the same query run by loci-full: median wall time of 7 runs each, and
#      the ratio.
# Usage: layer_queries.sh [LOCI_EXE] [N]; LOCI_BENCH_DIR is the working directory. Needs
# datasets/fetch.sh to have filled the cache.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../../.." && pwd)
loci=${1:-$root/build/cli/loci}
n=${2:-10000}
work=${LOCI_BENCH_DIR:-$root/build/bench-layers}
mkdir -p "$work"
export OGR_GEOJSON_MAX_OBJ_SIZE=0
src="$root/datasets/cache/countries-coastline-1m/map.geo.json"
[ -s "$src" ] || { echo "skip: run datasets/fetch.sh"; exit 0; }
ln -sf "$src" "$work/coast.geojson"
cp "$root/datasets/samples/coastline-denmark.geojson" "$work/sample.geojson"
# Indexed afresh, so that the file is what this loci writes (a sidecar of an earlier release
# may still be read, with other chunk sizes).
"$loci" index -q --per segment "$work/coast.geojson"
"$loci" index -q --per segment "$work/sample.geojson"

median() { sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
seconds() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.4f", (b - a) / 1e9 }'; }
one_query() {  # LAYER WINDOW [EXE]: median seconds and resident KB of 7 runs
  local t=() m=() t0 t1 exe=${3:-$loci}
  for _ in 1 2 3 4 5 6 7; do
    t0=$(date +%s%N)
    /usr/bin/time -f "%M" -o "$work/time.txt" "$exe" query "$1" --bbox "$2" -f ids > /dev/null
    t1=$(date +%s%N)
    read -r k < "$work/time.txt"; t+=("$(seconds "$t0" "$t1")"); m+=("$k")
  done
  echo "$(printf '%s\n' "${t[@]}" | median) $(printf '%s\n' "${m[@]}" | median)"
}
instructions() {
  command -v valgrind > /dev/null || { echo "n/a"; return; }
  valgrind --tool=callgrind --callgrind-out-file=/dev/null "$loci" query "$1" --bbox "$2" -f ids \
    2>&1 >/dev/null | sed -n 's/.*Collected : \([0-9]*\).*/\1/p'
}
window=10.2,55.3,10.3,55.4  # in both layers' extents (Funen)
read -r big_s big_kb <<< "$(one_query "$work/coast.geojson" "$window")"
read -r small_s small_kb <<< "$(one_query "$work/sample.geojson" "$window")"
big_i=$(instructions "$work/coast.geojson" "$window")
small_i=$(instructions "$work/sample.geojson" "$window")
echo "one window: coastline sidecar $(stat -c %s "$work/coast.geojson.loci") B: ${big_s}s ${big_kb}KB" \
  "${big_i} instructions; sample sidecar $(stat -c %s "$work/sample.geojson.loci") B: ${small_s}s" \
  "${small_kb}KB ${small_i} instructions; ratio $(awk -v a="$big_s" -v b="$small_s" 'BEGIN { printf "%.2f", a / b }')x time," \
  "$(awk -v a="$big_i" -v b="$small_i" 'BEGIN { if (b > 0) printf "%.3f", a / b; else print "n/a" }')x instructions"

awk -v n="$n" 'BEGIN { srand(7); for (i = 0; i < n; i++)
  printf "%.6f,%.6f\n", -180 + 360 * rand(), -80 + 160 * rand() }' > "$work/nearest.txt"
batch=()  # seconds of 5 runs, the median taken
for _ in 1 2 3 4 5; do
  t0=$(date +%s%N)
  "$loci" query "$work/coast.geojson" --nearest-file "$work/nearest.txt" -k 10 -f ids -j 1 \
    > "$work/nearest.out"
  t1=$(date +%s%N)
  batch+=("$(seconds "$t0" "$t1")")
done
batch_s=$(printf '%s\n' "${batch[@]}" | median)
echo "$n nearest-10 on one core: $(awk -v s="$batch_s" -v n="$n" 'BEGIN { printf "%.3f s, %.0f queries/s", s, n / s }')" \
  "(median of 5: ${batch[*]}; $(wc -l < "$work/nearest.out") rows)"
# The library's own nearest-10 on the same boxes, in one process (the layer read through GDAL
# first, not timed).
lib_ms=$("$loci" bench "$work/coast.geojson" --per segment --queries "$n" -k 10 2>/dev/null |
  awk '/^nearest-n queries/ { print $3 }')
echo "library nearest-10 on the same boxes: $(awk -v ms="$lib_ms" -v n="$n" 'BEGIN { printf "%.0f queries/s", n / (ms / 1000) }');" \
  "the command's batch takes $(awk -v ms="$lib_ms" -v s="$batch_s" 'BEGIN { printf "%.1f", s / (ms / 1000) }')x its time (aim: within 5x)"

# Per feature, on a shapefile: the front against loci-full (beside it, or where it installs it).
full=$(dirname "$loci")/loci-full
[ -x "$full" ] || full=$(dirname "$loci")/../libexec/loci/loci-full
if [ -x "$full" ]; then
  [ "$work/coast.shp" -nt "$src" ] ||
    ogr2ogr -f "ESRI Shapefile" "$work/coast.shp" "$src" > /dev/null
  "$loci" index -q --per feature "$work/coast.shp"
  read -r front_s _ <<< "$(one_query "$work/coast.shp" "$window")"
  read -r full_s _ <<< "$(one_query "$work/coast.shp" "$window" "$full")"
  echo "one window per feature on the coastline shapefile: loci ${front_s}s, loci-full ${full_s}s" \
    "($(awk -v a="$full_s" -v b="$front_s" 'BEGIN { printf "%.1f", a / b }')x)"
fi
