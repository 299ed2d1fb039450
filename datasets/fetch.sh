#!/usr/bin/env bash
# Fetches the large real layers into datasets/cache (git-ignored) from the npm registry:
#   countries-coastline-1m/map.geo.json   Natural Earth coastlines, 1 m resolution
#   countries-land-10m/map.geo.json       Natural Earth land polygons, 10 m resolution
# Idempotent: a layer already in the cache is not fetched again. Needs npm.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
cache="$here/cache"
mkdir -p "$cache"

fetch() {
  local name=$1
  local dest="$cache/$name"
  if [ -s "$dest/map.geo.json" ]; then
    echo "datasets: $name already cached"
    return
  fi
  echo "datasets: fetching @geo-maps/$name"
  local tmp
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' RETURN
  (cd "$tmp" && npm pack --silent "@geo-maps/$name" >/dev/null)
  mkdir -p "$tmp/x"
  tar xzf "$tmp"/*.tgz -C "$tmp/x"
  [ -s "$tmp/x/package/map.geo.json" ] || { echo "datasets: $name has no map.geo.json" >&2; exit 1; }
  rm -rf "$dest.partial"
  mkdir -p "$dest.partial"
  mv "$tmp/x/package/map.geo.json" "$tmp/x/package/LICENSE" "$dest.partial/" 2>/dev/null || \
    mv "$tmp/x/package/map.geo.json" "$dest.partial/"
  rm -rf "$dest"
  mv "$dest.partial" "$dest"
  echo "datasets: $name ready in $dest"
}

layers=("$@")
[ ${#layers[@]} -gt 0 ] || layers=(countries-coastline-1m countries-land-10m)
for l in "${layers[@]}"; do fetch "$l"; done
