#!/usr/bin/env bash
# The quick start's first command: installs what loci needs, builds it, and runs the main job
# on the bundled sample layer (Natural Earth coastlines around Denmark): index the layer, ask
# window and nearest-n questions of it, and show each R-tree built over its segments; then find
# the vessel pairs of the synthetic AIS sample that come within half a nautical mile in 20 minutes.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"

layer=datasets/samples/coastline-denmark.geojson
run() {
  echo "\$ loci $*"
  ./build/cli/loci "$@"
  echo
}
run info "$layer"
run index "$layer" --per segment -q
run query "$layer" --bbox 10.5,55.2,11.2,55.8 -f csv
run query "$layer" --nearest 11.0,57.5 -k 3 -f csv
run query "$layer" --bbox 10.5,55.2,11.2,55.8 --candidates -f ids
./build/cli/loci-quickstart "$layer"
echo
run fleet conflicts datasets/samples/ais-denmark-synthetic.csv --within 926 --horizon 1200
