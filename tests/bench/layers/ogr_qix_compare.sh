#!/usr/bin/env bash
# loci against GDAL's own spatial indexes on the Natural Earth layers: the shapefile's .qix and
# the GeoPackage's R-tree (an SQLite R-tree, GDAL's modern default format):
#   1. index time: `loci index` (as chosen, and --per feature) vs `ogrinfo -sql "CREATE
#      SPATIAL INDEX ON ..."` (.qix) or `SELECT CreateSpatialIndex(...)` (GeoPackage); loci's
#      builds and the .qix are medians of 5 runs, the GeoPackage's R-tree build one run
#   2. a batch of N windows (default 1000): one `loci query --bbox-file` vs N `ogrinfo -spat`
#      runs on the indexed file, both giving the features whose exact geometry meets
#      the window; the FID sets must be identical.
# Usage: ogr_qix_compare.sh [LOCI_EXE] [N]; LOCI_BENCH_LAYERS picks layers, LOCI_BENCH_DIR the
# working directory (shapefiles made there by ogr2ogr on first use). Needs datasets/fetch.sh to have filled the cache.
# Windows come from a fixed seed, so every run times the same batch.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../../.." && pwd)
loci=${1:-$root/build/cli/loci}
n=${2:-1000}
work=${LOCI_BENCH_DIR:-$root/build/bench-layers}
mkdir -p "$work"
export OGR_GEOJSON_MAX_OBJ_SIZE=0

now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", b - a }'; }

# N windows inside lon [-170, 170], lat [-60, 75], 0.2 to 12 degrees wide.
awk -v n="$n" 'BEGIN { srand(2024); for (i = 0; i < n; i++) {
  x = -170 + 340 * rand(); y = -60 + 135 * rand(); w = 0.2 + 11.8 * rand(); h = w / 2;
  printf "%.6f,%.6f,%.6f,%.6f\n", x, y, x + w, y + h } }' > "$work/windows.txt"

# compare FILE NAME FORMAT: loci's index and window batch against OGR's on the same file, where
# OGR's index is the shapefile's .qix or the GeoPackage's R-tree.
compare() {
  local file=$1 name=$2 format=$3
  rm -f "$file.loci" "${file%.shp}.qix"
  # OGR's index first: building it rewrites a GeoPackage, which would make loci's stale.
  t0=$(now)
  if [ "$format" = shapefile ]; then
    ogrinfo -q "$file" -sql "CREATE SPATIAL INDEX ON \"$name\"" >/dev/null
  else
    ogrinfo -q "$file" -sql "SELECT CreateSpatialIndex('$name', 'geom')" >/dev/null
  fi
  t1=$(now); "$loci" index -q "$file"  # the sidecar the window batch reads
  index_ogr=$(elapsed "$t0" "$t1")
  # Builds vary run to run: medians of 5, alternated.
  local chosen=() feature=() qix=()
  for _ in 1 2 3 4 5; do
    rm -f "$work/$name.$format.chosen.loci" "$work/$name.$format.feature.loci"
    t0=$(now); "$loci" index -q "$file" -o "$work/$name.$format.chosen.loci"; t1=$(now)
    chosen+=("$(elapsed "$t0" "$t1")")
    t0=$(now); "$loci" index -q --per feature "$file" -o "$work/$name.$format.feature.loci"; t1=$(now)
    feature+=("$(elapsed "$t0" "$t1")")
    if [ "$format" = shapefile ]; then
      rm -f "${file%.shp}.qix"
      t0=$(now); ogrinfo -q "$file" -sql "CREATE SPATIAL INDEX ON \"$name\"" >/dev/null; t1=$(now)
      qix+=("$(elapsed "$t0" "$t1")")
    fi
  done
  index_loci=$(printf '%s\n' "${chosen[@]}" | sort -g | sed -n 3p)
  index_feature=$(printf '%s\n' "${feature[@]}" | sort -g | sed -n 3p)
  [ "$format" = shapefile ] && index_ogr=$(printf '%s\n' "${qix[@]}" | sort -g | sed -n 3p)
  per=$("$loci" info "$file" | sed -n 's/.*packed-[a-z]* per \(feature\|segment\).*/\1/p')

  t0=$(now); "$loci" query -q "$file" --bbox-file "$work/windows.txt" > "$work/$name.$format.loci.txt"; t1=$(now)
  : > "$work/$name.$format.ogr.txt"
  i=0
  while IFS=, read -r x0 y0 x1 y1; do
    i=$((i + 1))
    ogrinfo -ro -q -al -geom=NO -spat "$x0" "$y0" "$x1" "$y1" "$file" |
      sed -n 's/^OGRFeature([^)]*):\([0-9]*\)$/\1/p' | awk -v q="$i" '{ print q, $1 }' >> "$work/$name.$format.ogr.txt"
  done < "$work/windows.txt"
  t2=$(now)
  query_loci=$(elapsed "$t0" "$t1"); query_ogr=$(elapsed "$t1" "$t2")

  if cmp -s <(sort "$work/$name.$format.loci.txt") <(sort "$work/$name.$format.ogr.txt"); then same=identical; else same=DIFFERENT; fi
  hits=$(wc -l < "$work/$name.$format.loci.txt")
  echo "$name ($format): index loci ${index_loci}s (per $per, as chosen; --per feature ${index_feature}s)" \
    "vs OGR ${index_ogr}s;" \
    "$n windows ($hits answers, $same): loci ${query_loci}s vs ogrinfo -spat ${query_ogr}s," \
    "$(awk -v a="$query_ogr" -v b="$query_loci" 'BEGIN { printf "%.1f", a / b }')x"
  [ "$same" = identical ] || exit 1
}

for name in ${LOCI_BENCH_LAYERS:-countries-land-10m countries-coastline-1m}; do
  src="$root/datasets/cache/$name/map.geo.json"
  [ -s "$src" ] || { echo "skip $name: run datasets/fetch.sh"; continue; }
  # GeoPackage: converted without an index, so that building its R-tree is timed alone.
  gpkg="$work/$name.gpkg"
  [ -s "$gpkg" ] || ogr2ogr -f GPKG -nln "$name" -lco SPATIAL_INDEX=NO "$gpkg" "$src"
  ogrinfo -q "$gpkg" -sql "SELECT DisableSpatialIndex('$name', 'geom')" >/dev/null 2>&1 || true
  compare "$gpkg" "$name" geopackage
  # Shapefile: GDAL 3.6 takes very long to write the 10 m land polygons; set
  # LOCI_BENCH_SHAPEFILES to the layers to convert (default: the coastline only).
  case " ${LOCI_BENCH_SHAPEFILES:-countries-coastline-1m} " in
    *" $name "*)
      shp="$work/$name.shp"
      [ -s "$shp" ] || ogr2ogr -f "ESRI Shapefile" -nln "$name" "$shp" "$src"
      compare "$shp" "$name" shapefile ;;
  esac
done
