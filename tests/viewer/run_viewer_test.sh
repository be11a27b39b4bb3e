#!/bin/sh
# Runs one viewer script under Xvfb: run_viewer_test.sh VOXLAB_EXE SCRIPT OUT_DIR
# Exit 77 (ctest SKIP_RETURN_CODE) only when xvfb-run is missing; everything else is a real result.
set -e
exe="$1"; script="$2"; out="$3"
command -v xvfb-run >/dev/null 2>&1 || { echo "xvfb-run not found: skipping"; exit 77; }
rm -rf "$out"
mkdir -p "$out"
view() { xvfb-run -a -s "-screen 0 1600x900x24" "$exe" view --script "$script"; }
case "$script" in
  *walk_stages*)
    # Every technique `voxlab list` names: `voxlab run` writes every output, the viewer walks it.
    for t in $("$exe" list --json | python3 -c 'import json,sys; print(" ".join(t["id"] for t in json.load(sys.stdin)["techniques"]))'); do
      echo "== walking $t"
      export VOXLAB_WALK_TECHNIQUE="$t" VOXLAB_VIEWER_OUT="$out/$t" VOXLAB_VIEWER_RUN="$out/$t/run"
      mkdir -p "$VOXLAB_VIEWER_OUT"
      "$exe" run --technique "$t" --scene cornell-box --out "$VOXLAB_VIEWER_RUN" >/dev/null
      view
    done ;;
  *camera_overlay*)
    export VOXLAB_VIEWER_OUT="$out"
    view >"$out/log.txt" 2>&1 || { cat "$out/log.txt"; exit 1; }
    cat "$out/log.txt"
    # Run the copied command (free camera after fly/look) and compare its final image with the
    # viewer's: the camera goes through text with 7 significant digits, so allow what that moves
    # (measured RMSE 1.3e-5 and 4.7e-5 on the tonemapped RGBA8 image: a handful of pixels one 8-bit
    # step apart; 2e-4 is four times the worst; the scene camera instead of the flown one gives 0.13).
    cmd=$(sed -n 's/^command: voxlab run \(.*\) --out out$/\1/p' "$out/log.txt" | head -n 1)
    [ -n "$cmd" ] || { echo "no copied command in the viewer's output"; exit 1; }
    case "$cmd" in *--look-from*) ;; *) echo "copied command has no free camera: $cmd"; exit 1 ;; esac
    eval "\"$exe\" run $cmd --only vct-grid/composite/final --out \"$out/reproduced\"" >/dev/null
    "$exe" compare "$out/view/composite.final.exr" "$out/reproduced/composite.final.exr" --fail-above rmse=0.0002 ;;
  *)
    export VOXLAB_VIEWER_OUT="$out"
    view ;;
esac
