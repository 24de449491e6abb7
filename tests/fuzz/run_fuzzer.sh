#!/usr/bin/env bash
# run_fuzzer.sh FUZZER KEPT_INPUTS SECONDS [SEED_DIR ...]: runs every kept input (seeds and past
# findings, tests/fuzz/corpus/NAME) and the seed folders that exist, then mutates them for SECONDS.
# Inputs the fuzzer finds go to a scratch folder, never into the source tree. Prints the
# executions and the findings; fails on a finding, naming the input that reproduces it.
set -uo pipefail
fuzzer=$1 kept=$2 seconds=$3
shift 3
name=$(basename "$fuzzer")
work=$(mktemp -d "/tmp/cairn_${name}_XXXXXX")
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/corpus" "$work/findings"
seeds=()
[ -d "$kept" ] && seeds+=("$kept")
for s in "$@"; do
  if [ -d "$s" ]; then seeds+=("$s"); else echo "$name: seed folder $s is missing; fuzzing without it"; fi
done
# Leaks are findings too; the sanitizer's own exit codes mark them.
"$fuzzer" -max_total_time="$seconds" -timeout=20 -rss_limit_mb=4096 -max_len=2000000 -print_final_stats=1 \
  -artifact_prefix="$work/findings/" "$work/corpus" "${seeds[@]}" >"$work/log" 2>&1
status=$?
execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$work/log" | grep -o '[0-9]*$')
findings=$(find "$work/findings" -type f | wc -l)
echo "$name: ${execs:-0} executions in ${seconds} s, ${findings} findings"
if [ "$status" -ne 0 ] || [ "$findings" -ne 0 ]; then
  tail -n 60 "$work/log"
  keep=${CAIRN_FUZZ_FINDINGS:-/tmp/cairn_fuzz_findings}/$name
  mkdir -p "$keep" && cp "$work"/findings/* "$keep"/ 2>/dev/null
  echo "$name: reproduce with: $fuzzer $keep/<input>; once fixed, add the input to $kept"
  exit 1
fi
