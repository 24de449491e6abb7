#!/usr/bin/env bash
# Cross-builds the target-portable core of cairn (common, hal, the stereo error model, the filter,
# evaluation, the pose graph, mapping) for an Arm board with Debian's cross compiler.
# Usage: scripts/cross-build.sh [aarch64|armhf] [--install]
#   --install  first installs the cross compiler (needs root or sudo)
# Exits 77 (skip) when the cross compiler is not installed and --install was not given.
set -euo pipefail
cd "$(dirname "$0")/.."
arch=${1:-aarch64}
case "$arch" in
  aarch64) triple=aarch64-linux-gnu ;;
  armhf) triple=arm-linux-gnueabihf ;;
  *) echo "cross-build: unknown architecture '$arch' (aarch64 or armhf)" >&2; exit 2 ;;
esac
if [[ "${2:-}" == "--install" ]]; then CAIRN_CROSS=1 ./scripts/install-deps.sh; fi
if ! command -v "$triple-g++" >/dev/null; then
  echo "cross-build: $triple-g++ is not installed (run with --install, or: apt-get install g++-$triple)"
  exit 77
fi
build="${CAIRN_CROSS_BUILD_DIR:-build/cross-$arch}"
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_TOOLCHAIN_FILE="toolchains/$triple.cmake" -DCAIRN_PORTABLE_CORE_ONLY=ON >/dev/null
libs=(common/libcommon.a hal/libhal.a stereo/libstereo_core.a estimation/math/libestimation_math.a
      estimation/filter/libfilter.a estimation/eval/libestimation_eval.a estimation/graph/libpose_graph.a
      mapping/libmapping.a)
cmake --build "$build" --target common hal stereo_core estimation_math filter estimation_eval pose_graph mapping
for lib in "${libs[@]}"; do
  obj=$(cd "$build" && ar t "$lib" | head -n 1)
  (cd "$build" && ar p "$lib" "$obj" > /tmp/cairn-cross-$$.o)
  echo "$lib: $(file -b /tmp/cairn-cross-$$.o | cut -d, -f1-2)"
  rm -f /tmp/cairn-cross-$$.o
done
