#!/usr/bin/env bash
# Configures and builds the sanitized tree build-asan/: every target with AddressSanitizer and
# UndefinedBehaviorSanitizer (VOXLAB_SANITIZE), plus the libFuzzer scene-loader target
# (VOXLAB_FUZZ), with Clang from Debian. Used by scripts/test.sh and scripts/fuzz.sh.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
# Paths relative to the checkout for ccache, also in the debug information (which ccache would
# otherwise key on the folder), so that clones share the cache (scripts/build.sh).
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$root}"
cmake -S "$root" -B "$root/build-asan" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DVOXLAB_SANITIZE=ON -DVOXLAB_FUZZ=ON \
  -DCMAKE_C_FLAGS="-fdebug-prefix-map=$root=." -DCMAKE_CXX_FLAGS="-fdebug-prefix-map=$root=." >/dev/null
cmake --build "$root/build-asan" -j"$(nproc)"
