#!/usr/bin/env bash
# The main job on the built-in default, no hardware needed: installs what is missing, builds the
# release preset, and runs a simulated mission of a team on the default world: one cairnd per robot
# (two rovers and a hexacopter, as on the robots), deployed from the lander (each starts in front
# of one of its tags), talking over loopback through the team exchange with CURVE keys made for
# the demo, each writing ./out/<robot> ($CAIRN_DEMO_OUT/<robot>). Then replays the bundled real EuRoC
# excerpt into ./out/euroc when the shared data sets are present.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target cairnd cairn
duration="${CAIRN_DEMO_DURATION:-60}"
world="${CAIRN_DEMO_WORLD:-}"  # a world file; "" = the profiles' default world
seed="${CAIRN_DEMO_SEED:-1}"
port="${CAIRN_DEMO_PORT:-47701}"
out="${CAIRN_DEMO_OUT:-out}"
read -r -a extra <<<"${CAIRN_DEMO_SET:-}"  # more KEY=VALUE settings for every robot, space separated
cairnd=./build/release/daemon/cairnd
cairn=./build/release/tools/cairn
robots=(rover hexacopter rover2)
letters=(a b c)
profiles=(rover hexacopter rover)
team=$out/team
rm -rf "$team"
mkdir -p "$team/keys"
echo "members:" >"$team/team.yaml"
for i in "${!robots[@]}"; do
  r=${robots[$i]}
  "$cairn" keys generate --name "$r" --dir "$team/keys" >/dev/null
  key=$(awk '$1 == "public-key" {print $2}' "$team/keys/$r.pub")
  echo "  - {name: $r, letter: ${letters[$i]}, address: \"tcp://127.0.0.1:$((port + i))\", public_key: \"$key\"}" \
    >>"$team/team.yaml"
done
common=(--sim --set "sim.duration=$duration" --set "sim.seed=$seed" ${world:+--set "sim.world=$world"} --set "sim.robots=$(IFS=,; echo "${robots[*]}")"
        --set sim.deploy_from_lander=true --set replay.pacing=fast --set replay.deterministic=true --set live.enabled=false
        --set recording.enabled=false --set team.enabled=true --set "team.members_file=$team/team.yaml"
        --set team.linger=600 --log-level warn)
for kv in "${extra[@]}"; do common+=(--set "$kv"); done
echo "demo: simulating a ${duration} s mission of ${robots[*]} on ${world:-the default world} (seed $seed), exchanging over loopback"
pids=()
for i in "${!robots[@]}"; do
  r=${robots[$i]}
  rm -rf "${out:?}/$r"  # a new mission: no items or outputs of an earlier one
  "$cairnd" --config "configs/${profiles[$i]}.yaml" "${common[@]}" --set "robot.name=$r" \
    --set "graph.optimizer.own_robot=${letters[$i]}" --set "team.secret_key_file=$team/keys/$r.key" \
    --out "$out/$r" &
  pids+=($!)
done
# The first robot to fail stops the others: they would wait out team.linger for it.
status=0
running=("${pids[@]}")
while ((${#running[@]} > 0)); do
  finished=""
  if ! wait -n -p finished "${running[@]}"; then
    status=1
    kill -TERM "${running[@]}" 2>/dev/null || true
    sleep 5
    kill -KILL "${running[@]}" 2>/dev/null || true
    wait || true
    break
  fi
  left=()
  for pid in "${running[@]}"; do [[ $pid == "$finished" ]] || left+=("$pid"); done
  running=("${left[@]}")
done
if ((status != 0)); then
  echo "demo: a simulated robot's cairnd failed (see above)" >&2
  exit 1
fi
data="${CAIRN_DATA_DIR:-../shared/data}/euroc-v1_01-micro"
if [[ -d "$data" ]]; then
  # Dense stereo and mapping on the real pairs too (off in the EuRoC profile, which tests replay).
  rm -rf "${out:?}/euroc"
  "$cairnd" --config configs/euroc.yaml --replay "$data" --out "$out/euroc" --log-level warn \
    --set stereo.enabled=true --set mapping.enabled=true
else
  echo "demo: skipping the EuRoC replay: missing $data (the shared data sets next to this checkout)"
fi
"$cairn" summary "${robots[@]/#/$out/}" $([[ -d $out/euroc ]] && echo "$out/euroc")
