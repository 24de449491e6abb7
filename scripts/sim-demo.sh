#!/usr/bin/env bash
# Simulated multi-robot mission on the default world, then the rover's recording replayed through
# cairnd (whatever stages exist). No hardware and no shared data needed.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target cairnd cairn
duration="${SIM_DURATION:-10}"
./build/release/tools/cairn sim --world configs/worlds/default.yaml --robots rover,hexacopter \
  --duration "$duration" --seed 1 --out out/sim
./build/release/daemon/cairnd --config configs/rover.yaml --set can.enabled=false \
  --replay out/sim/rover --out out/sim-cairnd
echo "sim-demo: mission in out/sim (EuRoC/ASL per robot, can0.log), cairnd results in out/sim-cairnd"
