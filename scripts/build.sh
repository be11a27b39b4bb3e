#!/usr/bin/env bash
# Configures and builds voxlab into build/ (Release). Used by the README commands and CI.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
# ccache (used when installed, CMakeLists.txt) sees paths relative to the checkout, so every clone
# of the project shares its cache entries wherever it lies.
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$root}"
cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$root/build" -j"$(nproc)"
