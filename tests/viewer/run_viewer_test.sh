#!/bin/sh
# Runs one viewer script under Xvfb: run_viewer_test.sh VOXLAB_EXE SCRIPT OUT_DIR
# Exit 77 (ctest SKIP_RETURN_CODE) only when xvfb-run is missing; everything else is a real result.
set -e
exe="$1"; script="$2"; out="$3"
command -v xvfb-run >/dev/null 2>&1 || { echo "xvfb-run not found: skipping"; exit 77; }
rm -rf "$out"
mkdir -p "$out"
view() { xvfb-run -a -s "-screen 0 1600x900x24" "$exe" view --script "$script"; }
case "${script##*/}" in  # the file name: a checkout path may contain any of these words
  *walk_stages*)
    # Every technique `voxlab list` names: `voxlab run` writes every output, the viewer walks it.
    for t in $("$exe" list --json | python3 -c 'import json,sys; print(" ".join(t["id"] for t in json.load(sys.stdin)["techniques"]))'); do
      echo "== walking $t"
      export VOXLAB_WALK_TECHNIQUE="$t" VOXLAB_VIEWER_OUT="$out/$t" VOXLAB_VIEWER_RUN="$out/$t/run"
      mkdir -p "$VOXLAB_VIEWER_OUT"
      "$exe" run --technique "$t" --scene cornell-box --out "$VOXLAB_VIEWER_RUN" >/dev/null
      view
    done ;;
  *every_lesson*)
    # Every lesson in lessons/ played from its first step to its last (tests/viewer/every_lesson.txt).
    for f in "$VOXLAB_ROOT"/lessons/[0-9]*.md; do
      name=$(basename "$f" .md)
      echo "== playing $name"
      export VOXLAB_LESSON="$f" VOXLAB_VIEWER_OUT="$out/$name"
      mkdir -p "$VOXLAB_VIEWER_OUT"
      view >"$VOXLAB_VIEWER_OUT/log.txt" 2>&1 || { cat "$VOXLAB_VIEWER_OUT/log.txt"; exit 1; }
      grep "^lesson step" "$VOXLAB_VIEWER_OUT/log.txt" | tail -n 1
    done ;;
  *lesson_sweep*)
    # The step's sweep runs into a cache under TMPDIR: a fresh one, so the child really runs.
    export VOXLAB_VIEWER_OUT="$out" TMPDIR="$out/tmp"
    mkdir -p "$TMPDIR"
    view >"$out/log.txt" 2>&1 || { cat "$out/log.txt"; exit 1; }
    cat "$out/log.txt"
    [ -f "$(ls -d "$TMPDIR"/voxlab-sweeps/*/ | head -n 1)sweep.json" ] || { echo "no sweep.json in the cache"; exit 1; }
    # The viewer's figure and voxlab figure's of the same state say the same (title, notes,
    # captions) and hold pictures of the same sizes.
    "$exe" figure --technique vct-grid --output cone-trace/indirect-diffuse --size 512x512 \
      --out "$out/cli-figure.svg" >/dev/null
    python3 - "$out/figure.svg" "$out/cli-figure.svg" <<'PY'
import base64, struct, sys
import xml.etree.ElementTree as ET
def summary(path):
    root = ET.parse(path).getroot()
    texts = [(e.get("class"), e.text) for e in root.iter("{http://www.w3.org/2000/svg}text")]
    sizes = [struct.unpack(">II", base64.b64decode(e.get("href").split(",", 1)[1])[16:24])
             for e in root.iter("{http://www.w3.org/2000/svg}image")]
    return texts, sizes
viewer, cli = summary(sys.argv[1]), summary(sys.argv[2])
print("viewer figure:", viewer)
if viewer != cli or len(viewer[1]) != 2:
    sys.exit(f"the viewer's figure {viewer} differs from voxlab figure's {cli}")
PY
    ;;
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
  *compare*)
    export VOXLAB_VIEWER_OUT="$out"
    view >"$out/log.txt" 2>&1 || { cat "$out/log.txt"; exit 1; }
    cat "$out/log.txt"
    # The RMSE the compare view printed for final vs the reference must be `voxlab compare`'s on
    # the same files (both compute it with reference::computeMetrics on the same floats; the
    # viewer prints 9 significant digits, so allow a relative 1e-8 for the printing).
    ref="$VOXLAB_ROOT/tests/golden/reference/cornell-box/full.exr"
    shown=$(sed -n 's/^compare final vs .*full\.exr: rmse \([^ ]*\) .*/\1/p' "$out/log.txt" | head -n 1)
    [ -n "$shown" ] || { echo "the viewer printed no compare metrics for final vs full.exr"; exit 1; }
    "$exe" compare "$out/view/composite.final.exr" "$ref" --json >"$out/compare.json"
    python3 - "$shown" "$out/compare.json" <<'PY'
import json, sys
viewer = float(sys.argv[1])
cli = json.load(open(sys.argv[2]))["rmse"]
print(f"rmse: viewer {viewer!r}, voxlab compare {cli!r}")
if abs(viewer - cli) > 1e-8 * max(abs(cli), 1e-30):
    sys.exit(f"the compare view's rmse {viewer} differs from voxlab compare's {cli}")
PY
    ;;
  *presenter*)
    # Presenter mode is for a projector: a 1920x1080 screen and window.
    export VOXLAB_VIEWER_OUT="$out"
    xvfb-run -a -s "-screen 0 1920x1080x24" "$exe" view --present --window 1920x1080 --script "$script" ;;
  *plugins*)
    export VOXLAB_VIEWER_OUT="$out"
    view
    # The test-only visualiser's writer ran for the test-only semantic (one line per cell of the
    # 8^3 level 0), next to the files every volume gets (one EXR per level).
    cells="$out/saved/cells.cells.index.txt"
    [ -f "$cells" ] || { echo "missing $cells: the test visualiser's writer did not run"; exit 1; }
    [ "$(wc -l <"$cells")" -eq 512 ] || { echo "$cells has $(wc -l <"$cells") lines, expected 512"; exit 1; }
    grep -qx "3 3 4 283" "$cells" || { echo "$cells lacks cell (3, 3, 4) with index 283"; exit 1; }
    [ -f "$out/saved/cells.cells@1.exr" ] && [ -f "$out/saved/record.probed-cell.bin" ] ||
      { echo "save-output did not write the usual files"; ls "$out/saved"; exit 1; }
    # The click re-ran the probing stage: its record is the clicked cell (the stage's first run
    # recorded the parameters' default, cell (0, 0, 0)).
    python3 - "$out/saved/record.probed-cell.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))["first_records"]
got = [(int(x["x"]), int(x["y"]), int(x["z"]), x["value"]) for x in r]
print("probe record:", got)
if got != [(3, 3, 4, 283.0)]:
    sys.exit(f"probe record {got}, expected [(3, 3, 4, 283.0)]")
PY
    ;;
  *soak*)
    # CI: exactly VOXLAB_SOAK_ACTIONS (default 400, about two minutes here) random actions from a
    # fixed seed, so that the run is the same on every machine and at any speed. A longer or
    # another soak: VOXLAB_SOAK_SECONDS=600 (time instead of a count) and/or VOXLAB_SOAK_SEED=N, or
    # VOXLAB_SOAK_SEED=random (from the clock). The seed is printed, and the viewer prints the
    # exact `soak` line that replays a run.
    export VOXLAB_VIEWER_OUT="$out"
    if [ -n "${VOXLAB_SOAK_SECONDS:-}" ]; then
      export VOXLAB_SOAK_ACTIONS="${VOXLAB_SOAK_ACTIONS:-0}"
    else
      export VOXLAB_SOAK_SECONDS=0 VOXLAB_SOAK_ACTIONS="${VOXLAB_SOAK_ACTIONS:-400}"
    fi
    VOXLAB_SOAK_SEED="${VOXLAB_SOAK_SEED:-1796177202}"
    [ "$VOXLAB_SOAK_SEED" = random ] && VOXLAB_SOAK_SEED=$(date +%s)
    export VOXLAB_SOAK_SEED
    echo "soak seed $VOXLAB_SOAK_SEED ($VOXLAB_SOAK_ACTIONS actions, or $VOXLAB_SOAK_SECONDS s when no count); replay: VOXLAB_SOAK_SEED=$VOXLAB_SOAK_SEED VOXLAB_SOAK_ACTIONS=N ctest -R viewer.soak"
    view ;;
  failing)
    # A folder of scripts that must fail: each names its expected message on its first line
    # ("# expect: TEXT"), so a check is shown to catch the deliberately wrong input it is given.
    export VOXLAB_VIEWER_OUT="$out"
    python3 - "$out" <<'PY'
import struct, sys, zlib
def png(path, rgb_rows):
    raw = b"".join(b"\0" + bytes(row) for row in rgb_rows)
    chunk = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
    h, w = len(rgb_rows), len(rgb_rows[0]) // 3
    open(path, "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) +
                           chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
rows = [[90] * (64 * 3) for _ in range(64)]
png(sys.argv[1] + "/grey.png", rows)
rows[10][30] = 91  # one channel of one pixel
png(sys.argv[1] + "/grey-one-pixel.png", rows)
PY
    n=0
    for s in "$script"/*.txt; do
      want=$(sed -n 's/^# expect: //p' "$s" | head -n 1)
      [ -n "$want" ] || { echo "$s has no '# expect: TEXT' line"; exit 1; }
      if xvfb-run -a -s "-screen 0 1600x900x24" "$exe" view --script "$s" >"$out/log.txt" 2>&1; then
        cat "$out/log.txt"; echo "$s passed, but its check must fail"; exit 1
      fi
      grep -qF -- "$want" "$out/log.txt" || { cat "$out/log.txt"; echo "$s failed without '$want'"; exit 1; }
      echo "ok ${s##*/}: failed with '$want'"
      n=$((n + 1))
    done
    [ "$n" -ge 2 ] || { echo "only $n failing scripts in $script"; exit 1; } ;;
  *)
    export VOXLAB_VIEWER_OUT="$out"
    view ;;
esac
