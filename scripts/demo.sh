#!/usr/bin/env bash
# The main job on the built-in default, no hardware needed: installs what is missing, builds the
# release preset, replays the bundled EuRoC excerpt through cairnd and writes ./out.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target cairnd cairn
data="${CAIRN_DATA_DIR:-../shared/data}/euroc-v1_01-micro"
if [[ ! -d "$data" ]]; then
  echo "demo: missing $data (the shared data sets next to this checkout)" >&2
  exit 1
fi
./build/release/daemon/cairnd --config configs/euroc.yaml --replay "$data" --out out
echo "demo: results in ./out (summary.json, diagnostics.json, config.yaml)"
