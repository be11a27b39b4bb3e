#!/bin/sh
# The handout shows what the viewer shows: the viewer plays lesson 01 under Xvfb and saves its view
# at every step (viewer_match.txt, save-view: the image with its overlay, as "Save view PNG"), and
# each handout picture must match it (voxlab compare on the 8-bit PNGs).
# Tolerance, MAE 0.002 (per channel, 8-bit values as 0..1): measured 0 on 8 of the 14 steps (before the bounce step, 15 now); up to
# 8e-6 (a few pixels one or two 8-bit steps apart) where vct-grid's inject averages fragments with
# atomics in a varying order; on step 1, the point view of the fragment list, whose records are
# appended in a varying order so splats at equal depth change places, 1.0e-4, 2.5e-4 and 4.0e-4 in
# three runs (LP_NUM_THREADS 1 and 2): the limit is five times the worst. Another step's picture
# (step 13 against step 14: MAE 0.10) must fail it (the last check).
# Exit 77 (skip) only when xvfb-run is missing.
set -e
exe="$1"; root="$2"; out="$3"
command -v xvfb-run >/dev/null 2>&1 || { echo "xvfb-run not found: skipping"; exit 77; }
rm -rf "$out"; mkdir -p "$out/viewer"
"$exe" handout "$root/lessons/01-voxel-cone-tracing.md" --out "$out/handout" > "$out/handout.log"
export VOXLAB_VIEWER_OUT="$out/viewer"
xvfb-run -a -s "-screen 0 1600x900x24" "$exe" view --script "$root/tests/cli/handout/viewer_match.txt" >"$out/viewer.log" 2>&1 ||
  { cat "$out/viewer.log"; exit 1; }
steps=$(ls "$out/handout/01-voxel-cone-tracing"/step-*.png | wc -l)
[ "$steps" -eq "$(ls "$out/viewer"/step-*.png | wc -l)" ] || { echo "the viewer saved a different number of steps"; exit 1; }
for h in "$out/handout/01-voxel-cone-tracing"/step-*.png; do
  v="$out/viewer/$(basename "$h")"
  echo "$(basename "$h"): $("$exe" compare "$h" "$v" 2>&1 | grep -E '^(rmse|mae|max_abs) ' | tr -s ' \n' '  ')"
  "$exe" compare "$h" "$v" --fail-above mae=0.002 >/dev/null 2>&1 || { echo "FAIL: $h differs from the viewer's $v"; exit 1; }
done
if "$exe" compare "$out/handout/01-voxel-cone-tracing/step-13.png" "$out/viewer/step-14.png" --fail-above mae=0.002 >/dev/null 2>&1; then
  echo "FAIL: the check does not tell step 13 from step 14"; exit 1
fi
echo "every handout picture of lesson 01 is the viewer's view"
