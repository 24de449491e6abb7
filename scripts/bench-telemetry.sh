#!/usr/bin/env bash
# Measures what recording and live streaming cost: replays the EuRoC excerpt at real time with
# recording (zstd) and the Foxglove stream on, one Foxglove client subscribed to every channel, and
# reports the telemetry executor's and the WebSocket thread's CPU time as a share of one core.
# Usage: scripts/bench-telemetry.sh [SECONDS]   (after a release build; needs node + npm)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-20}
build=build/release
data="${CAIRN_DATA_DIR:-../shared/data}/euroc-v1_01-micro"
out=$(mktemp -d)
js="$build/js-clients"
if [[ ! -d "$js/node_modules/@foxglove/ws-protocol" ]]; then
  mkdir -p "$js" && cp tests/js/package.json "$js/" && npm install --prefix "$js" --silent --no-audit --no-fund
fi
cp tests/js/*.mjs "$js/"
"$build/daemon/cairnd" --config configs/euroc.yaml --replay "$data" --out "$out" \
  --set live.enabled=true --set live.port=0 --set recording.enabled=true \
  --set replay.pacing=realtime --set replay.deterministic=false >"$out/log" 2>&1 &
pid=$!
for _ in $(seq 100); do grep -q "ws://" "$out/log" && break; sleep 0.1; done
url=$(grep -o "ws://[0-9.:]*" "$out/log")
node "$js/ws_check.mjs" "$url" "$seconds" 0 >"$out/client.json"
kill -TERM "$pid"; wait "$pid"
python3 - "$out" <<'PY'
import json, sys
d = json.load(open(sys.argv[1] + "/diagnostics.json"))
wall = d["wall_time_s"]
tele = next(e["cpu_seconds"] for e in d["executors"] if e["name"] == "telemetry")
ws = d["live_stream"]["server_cpu_seconds"]
print(json.dumps({"wall_s": round(wall, 2), "telemetry_cpu_share": round(tele / wall, 4),
                  "websocket_cpu_share": round(ws / wall, 4),
                  "recording_and_streaming_share_of_one_core": round((tele + ws) / wall, 4),
                  "live_messages_published": d["live_stream"]["published"],
                  "dropped_for_slow_clients": d["live_stream"]["dropped_for_slow_clients"]}))
PY
rm -rf "$out"
