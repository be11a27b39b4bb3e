#!/usr/bin/env bash
# Regenerates the checked-in reference images tests/golden/reference/<scene>/<mode>.exr with the
# CPU reference path tracer (`voxlab reference`). Deterministic: the same spp and seed give the
# same pixels on any thread count.
#
#   scripts/make-references.sh [VOXLAB_BINARY]      (default: build/voxlab)
#   SCENES="sponza" scripts/make-references.sh      (only some scenes; default: cornell-box sponza)
#
# Threads: $VOXLAB_THREADS (default: all cores).
# The per-pixel standard-error images (<mode>.stderr.exr) stay in build/references/: they are
# not checked in; their mean and RMS are stored in the references' voxlab:mean_stderr and
# voxlab:rms_stderr attributes. The EXRs store half floats (zip): rounding error RMSE 6e-5, far
# below the noise.
#
# Cornell box (512x512, camera 0, pixel centres, seed 0): spp chosen so that the RMS standard
# error is about 0.01 (a tenth of the smallest technique RMSE compared with it) while a render
# takes minutes. Measured (mean / RMS standard error over pixels and channels, seconds on one
# core of the 2-core dev machine):
#   full        512 spp   0.00879 / 0.0115     410 s
#   direct       32 spp   0.00011 / 0.00020     15 s
#   indirect    512 spp   0.00879 / 0.0115     296 s
#   indirect-1  512 spp   0.00623 / 0.0090     246 s
#   indirect-2  512 spp   0.00751 / 0.0101     821 s on 2 threads, load about 10 (2026-12-02)
#   indirect-4  512 spp   0.00840 / 0.0111     436 s on 2 threads, load 5 to 8 (2026-12-02)
# direct converges fastest: the spot light is evaluated exactly and the light panel is sampled
# by MIS.
#
# Sponza (512x512, camera 0 'nave', pixel centres, seed 0): the sun is the only light and is
# evaluated exactly, so direct has no noise at all (every spp gives the same pixel); the others
# were sized from a 128x128, 4 spp trial (full: RMS standard error 0.0145, 0.25 s per spp on 2
# threads) so that the whole set takes about 12 minutes on 2 free cores and the RMS standard error
# stays near 0.004, small against an RMSE of 0.02. Measured at 512x512 in docs/fidelity.md.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
voxlab="${1:-$root/build/voxlab}"
scenes="${SCENES:-cornell-box sponza}"

render() {  # scene size mode spp [scene file, when the scene is not in scenes/]
  local golden="$root/tests/golden/reference/$1" work="$root/build/references/$1"
  mkdir -p "$golden" "$work"
  nice -n 10 "$voxlab" reference --scene "${5:-$1}" --size "$2" --mode "$3" --spp "$4" --half --quiet \
    --out "$work/$3.exr"
  cp "$work/$3.exr" "$golden/$3.exr"
}

for scene in $scenes; do
  case "$scene" in
    cornell-box)
      render cornell-box 512x512 direct 32
      render cornell-box 512x512 indirect-1 512
      render cornell-box 512x512 full 512
      render cornell-box 512x512 indirect 512
      # voxel-path-tracing's default paths.bounces=2 declares indirect-{paths.bounces}: r in {2, 3};
      # RMS standard error 0.0101
      render cornell-box 512x512 indirect-2 512
      # and paths.bounces=4 (voxlab fidelity --set paths.bounces=4): r in {2, ..., 5}; RMS standard error 0.0111
      render cornell-box 512x512 indirect-4 512
      # vct-grid's bounces test (tests/unit/test_vct_bounces.cpp) runs at 128x128: direct light
      # and two indirect bounces (r <= 3), RMS standard error about 0.005
      render cornell-box 128x128 two-bounce 1024
      ;;
    sponza)
      render sponza 512x512 direct 16
      render sponza 512x512 indirect-1 128
      render sponza 512x512 full 64
      render sponza 512x512 indirect 64
      # voxel-path-tracing's default paths.bounces=2 (indirect-{paths.bounces}); RMS standard error 0.0035
      render sponza 512x512 indirect-2 64
      ;;
    cornell-box-panel-only)  # the emissive panel as the only light (vct-grid's emissive-only row)
      f="$root/tests/data/scenes/cornell-box-panel-only.gltf"
      render cornell-box-panel-only 128x128 direct 32 "$f"
      render cornell-box-panel-only 128x128 indirect-1 512 "$f"
      render cornell-box-panel-only 128x128 full 512 "$f"
      ;;
    skylight-room|two-rooms|corridor|spheres-room|spheres-room-cm|open-courtyard)
      # The suite's own scenes (scripts/make_suite_scenes.py): 256x256, the size `voxlab fidelity`
      # runs at. Their lights are punctual (no emissive surfaces), so direct has no noise at all;
      # the other modes' spp and their measured noise are in docs/fidelity.md.
      render "$scene" 256x256 direct 4
      render "$scene" 256x256 indirect-1 "${SUITE_SPP:-256}"
      render "$scene" 256x256 indirect-2 "${SUITE_SPP:-256}"
      render "$scene" 256x256 full "${SUITE_SPP:-256}"
      ;;
    *) echo "make-references.sh: no reference settings for scene '$scene' (known: cornell-box sponza cornell-box-panel-only skylight-room two-rooms corridor spheres-room spheres-room-cm open-courtyard)" >&2; exit 2 ;;
  esac
  ls -l "$root/tests/golden/reference/$scene"
done
