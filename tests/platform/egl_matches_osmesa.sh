#!/bin/sh
# The EGL platform (VOXLAB_GL=egl) renders what OSMesa renders: both run vct-grid at 32^3 / 64x64;
# the G-buffer normals must be identical and the final image may differ only where inject's
# atomic averaging order varies (one RGBA8 step, 1/255 = 0.0039, as between two OSMesa runs;
# measured max_abs 0.0039, RMSE 1.5e-5 at defaults). A bad VOXLAB_GL value is one line, exit 2.
# Exit 77 (skip) only when EGL itself is unavailable on the machine.
set -e
exe="$1"; out="$2"
rm -rf "$out"; mkdir -p "$out"
args="--technique vct-grid --set voxel.resolution=32 --size 64x64 --only vct-grid/gbuffer/normal --only vct-grid/composite/final"
if ! VOXLAB_GL=egl "$exe" run $args --out "$out/egl" >"$out/egl.log" 2>&1; then
  cat "$out/egl.log"
  grep -q "VOXLAB_GL=egl:" "$out/egl.log" && { echo "EGL unavailable: skipping"; exit 77; }
  exit 1
fi
VOXLAB_GL=osmesa "$exe" run $args --out "$out/osmesa" >/dev/null
grep -q '"context": "egl"' "$out/egl/manifest.json" || { echo "manifest does not name the egl context"; exit 1; }
grep -q '"context": "osmesa"' "$out/osmesa/manifest.json" || { echo "manifest does not name the osmesa context"; exit 1; }
"$exe" compare "$out/egl/gbuffer.normal.exr" "$out/osmesa/gbuffer.normal.exr" --fail-above max_abs=0
"$exe" compare "$out/egl/composite.final.exr" "$out/osmesa/composite.final.exr" --fail-above max_abs=0.0045
if VOXLAB_GL=vulkan "$exe" run $args --out "$out/bad" 2>"$out/bad.log"; then echo "VOXLAB_GL=vulkan was accepted"; exit 1; fi
grep -q "VOXLAB_GL='vulkan' is not a GL platform; valid: osmesa (default), egl" "$out/bad.log" || { cat "$out/bad.log"; exit 1; }
echo "egl and osmesa agree"
