#!/usr/bin/env bash
# Installs what is missing, builds and runs every test: the concurrency tests under
# ThreadSanitizer, then the whole suite under AddressSanitizer + UndefinedBehaviorSanitizer.
# Ends with ctest's summary of the full suite.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
cmake --preset tsan >/dev/null
cmake --build --preset tsan
ctest --preset tsan
cmake --preset asan-ubsan >/dev/null
cmake --build --preset asan-ubsan
ctest --preset asan-ubsan
