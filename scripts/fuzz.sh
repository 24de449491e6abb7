#!/usr/bin/env bash
# scripts/fuzz.sh SECONDS [NAME ...]: fuzzes every decoder of outside bytes (or the named ones) for
# SECONDS each, with coverage feedback on the whole tree (its own build, build/fuzz), and prints the
# executions and findings per target. A finding's input is kept in /tmp/cairn_fuzz_findings/NAME;
# once fixed, add it to tests/fuzz/corpus/NAME, where every test run replays it.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:?usage: scripts/fuzz.sh SECONDS [NAME ...]}
shift
cmake --preset asan-ubsan -B build/fuzz -DCAIRN_FUZZ_COVERAGE=ON -DCAIRN_FUZZ_SECONDS="$seconds" >/dev/null
cmake --build build/fuzz --target fuzzers
names=("$@")
if [ ${#names[@]} -eq 0 ]; then names=(all); fi
regex=$(IFS='|'; echo "${names[*]}")
[ "$regex" = all ] && regex=.
ctest --test-dir build/fuzz -L fuzz -R "$regex" -j 2 --output-on-failure -V 2>&1 | grep -E "executions in|reproduce with|tests passed|failed out of"
