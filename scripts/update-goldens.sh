#!/usr/bin/env bash
# Rewrites the snapshot goldens under tests/golden/ from the current build. Review the change by
# looking at the images (voxlab run writes PNGs of the same outputs) before committing it.
# An optional argument narrows it to a gtest filter, e.g. 'Snapshot.lpv_*', so that goldens of
# outputs a change should not affect stay as they are.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/build.sh"
cd "$root/build"
LP_NUM_THREADS=1 VOXLAB_UPDATE_GOLDENS=1 VOXLAB_ROOT="$root" ./voxlab_tests --gtest_filter="${1:-Snapshot.*}"
git -C "$root" status --short tests/golden
