#!/usr/bin/env bash
# Regenerates the checked-in reference images tests/golden/reference/<scene>/<mode>.exr with the
# CPU reference path tracer (`voxlab reference`). Deterministic: the same spp and seed give the
# same pixels on any thread count.
#
#   scripts/make-references.sh [VOXLAB_BINARY]      (default: build/voxlab)
#
# Threads: $VOXLAB_THREADS (default: all cores). About 17 minutes on one free core.
# The per-pixel standard-error images (<mode>.stderr.exr) stay in build/references/: they are
# not checked in; their mean and RMS are stored in the references' voxlab:mean_stderr and
# voxlab:rms_stderr attributes.
#
# spp per mode (Cornell box, 512x512, camera 0, pixel centres, seed 0), chosen so that the RMS
# standard error is below 0.01 (the mean below 0.008) while a render takes minutes:
#   full 512, direct 32, indirect 512, indirect-1 512
# direct converges fastest: the spot light is evaluated exactly and the light panel is sampled
# by MIS, so 64 spp leave a standard error near 1e-4.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
voxlab="${1:-$root/build/voxlab}"
scene=cornell-box
size=512x512
golden="$root/tests/golden/reference/$scene"
work="$root/build/references/$scene"
mkdir -p "$golden" "$work"

render() {  # mode spp
  nice -n 10 "$voxlab" reference --scene "$scene" --size "$size" --mode "$1" --spp "$2" --half --quiet \
    --out "$work/$1.exr"
  cp "$work/$1.exr" "$golden/$1.exr"
}

render direct 32
render indirect-1 512
render full 512
render indirect 512
ls -l "$golden"
