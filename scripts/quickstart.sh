#!/usr/bin/env bash
# The quick start's first command: installs what loci needs, builds it, and runs the main job
# on the bundled sample layer (Natural Earth coastlines around Denmark).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
./build/cli/loci-quickstart datasets/samples/coastline-denmark.geojson
