#!/usr/bin/env bash
# The main job on the built-in default, no hardware needed: installs what is missing, builds the
# release preset, and runs a simulated two-robot mission on the default world: one cairnd per
# robot (rover and hexacopter, as on the robots), each writing ./out/<robot>. Then replays the
# bundled real EuRoC excerpt into ./out/euroc when the shared data sets are present.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target cairnd cairn
duration="${CAIRN_DEMO_DURATION:-20}"
cairnd=./build/release/daemon/cairnd
common=(--sim --set "sim.duration=$duration" --set replay.pacing=fast --set replay.deterministic=true
        --set live.enabled=false --set recording.enabled=false --log-level warn)
echo "demo: simulating a ${duration} s mission of a rover and a hexacopter on the default world"
pids=()
for robot in rover hexacopter; do
  "$cairnd" --config "configs/$robot.yaml" "${common[@]}" --out "out/$robot" &
  pids+=($!)
done
status=0
for pid in "${pids[@]}"; do wait "$pid" || status=1; done
if ((status != 0)); then
  echo "demo: a simulated robot's cairnd failed (see above)" >&2
  exit 1
fi
data="${CAIRN_DATA_DIR:-../shared/data}/euroc-v1_01-micro"
if [[ -d "$data" ]]; then
  # Dense stereo and mapping on the real pairs too (off in the EuRoC profile, which tests replay).
  "$cairnd" --config configs/euroc.yaml --replay "$data" --out out/euroc --log-level warn \
    --set stereo.enabled=true --set mapping.enabled=true
else
  echo "demo: skipping the EuRoC replay: missing $data (the shared data sets next to this checkout)"
fi
./build/release/tools/cairn summary out/*/
