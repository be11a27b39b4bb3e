#!/usr/bin/env bash
# Installs what is missing, builds, and runs the whole test suite (CTest: unit, snapshot, physics,
# command-line and viewer tests), once with llvmpipe on one thread and once on two, because
# atomics and work distribution differ between them (testing.md).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup.sh"
"$root/scripts/build.sh"
cd "$root/build"
for threads in 1 2; do
  echo "== ctest with LP_NUM_THREADS=$threads"
  LP_NUM_THREADS=$threads ctest --output-on-failure -j1 --timeout 600
done
