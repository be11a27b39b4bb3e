#!/usr/bin/env bash
# Regenerates the checked-in reference images tests/golden/reference/<scene>/<mode>.exr with the
# CPU reference path tracer (`voxlab reference`). Deterministic: the same spp and seed give the
# same pixels on any thread count.
#
#   scripts/make-references.sh [VOXLAB_BINARY]      (default: build/voxlab)
#
# Threads: $VOXLAB_THREADS (default: all cores). About 16 minutes on one core.
# The per-pixel standard-error images (<mode>.stderr.exr) stay in build/references/: they are
# not checked in; their mean and RMS are stored in the references' voxlab:mean_stderr and
# voxlab:rms_stderr attributes.
#
# spp per mode (Cornell box, 512x512, camera 0, pixel centres, seed 0), chosen so that the RMS
# standard error is about 0.01 (a tenth of the smallest technique RMSE compared with it) while a
# render takes minutes. Measured (mean / RMS standard error over pixels and channels, seconds on
# one core of the 2-core dev machine):
#   full        512 spp   0.00879 / 0.0115     410 s
#   direct       32 spp   0.00011 / 0.00020     15 s
#   indirect    512 spp   0.00879 / 0.0115     296 s
#   indirect-1  512 spp   0.00623 / 0.0090     246 s
# direct converges fastest: the spot light is evaluated exactly and the light panel is sampled
# by MIS. The EXRs store half floats (zip): rounding error RMSE 6e-5, far below the noise.
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
