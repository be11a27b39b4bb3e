#!/usr/bin/env bash
# Regenerates the table of Step 3 of lessons/09-motion.md, what every technique re-runs for a light
# move: each registered technique (`voxlab list --json`) plays 16 frames at 128x128, final output
# only, on the Cornell box (the spot tilts from elevation 90 to 55 degrees) and on Sponza (the sun
# turns from azimuth 20 to 60 degrees). From each run's manifest: the stages every frame after the
# first re-ran, the CPU ms of the first frame and of the fastest later one (the one other jobs on
# the machine disturbed least), and the mean flicker over the 15 frame-to-frame changes. A
# technique without a light (voxelization) is left out, and so is one whose light move re-runs
# nothing. The table replaces the one under the lesson's header row
# "| technique | stages a light move re-runs"; the lines above it say how it was measured.
#
#   scripts/lesson-motion.sh [VOXLAB_BINARY]     (default: build/voxlab)
#   FRAMES=16 SIZE=128x128 LESSON=lessons/09-motion.md scripts/lesson-motion.sh
#
# The runs go to WORK=build/lesson-motion/<scene>/<technique>/ (40 s on 2 cores with Mesa's shader
# cache warm, a few minutes when it is cold).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
voxlab="$(realpath "${1:-$root/build/voxlab}")"
frames="${FRAMES:-16}"
size="${SIZE:-128x128}"
lesson="$(realpath "${LESSON:-$root/lessons/09-motion.md}")"
work="${WORK:-$root/build/lesson-motion}"
[ -x "$voxlab" ] || { echo "lesson-motion: no voxlab binary at $voxlab (build first: scripts/build.sh)" >&2; exit 2; }
[ -f "$lesson" ] || { echo "lesson-motion: no lesson at $lesson" >&2; exit 2; }
case "$frames" in '' | *[!0-9]* | 0 | 1) echo "lesson-motion: FRAMES=$frames is not a count of 2 or more" >&2; exit 2 ;; esac

# The techniques that have a light to move (voxelization has none).
techniques="$("$voxlab" list --json | python3 -c '
import json, sys
lit = lambda t: any(p["name"] == "light.0.elevation" for s in t["stages"] for p in s.get("parameters", []))
print(" ".join(t["id"] for t in json.load(sys.stdin)["techniques"] if lit(t)))')"
declare -A animate=([cornell-box]="light.0.elevation=90:55" [sponza]="light.0.azimuth=20:60")
load_before="$(cut -d' ' -f1-3 /proc/loadavg)"
started=$(date +%s)
for scene in cornell-box sponza; do
  for t in $techniques; do
    out="$work/$scene/$t"
    rm -rf "$out"
    mkdir -p "$out"
    (cd "$root" && "$voxlab" run --technique "$t" --scene "$scene" --size "$size" --final-only --frames "$frames" \
      --animate "${animate[$scene]}" --out "$out" >/dev/null)
    echo "lesson-motion: $scene $t done" >&2
  done
done
load_after="$(cut -d' ' -f1-3 /proc/loadavg)"

WORK="$work" LESSON="$lesson" TECHNIQUES="$techniques" FRAMES="$frames" SIZE="$size" \
LOAD_BEFORE="$load_before" LOAD_AFTER="$load_after" SECONDS_TAKEN=$(( $(date +%s) - started )) \
python3 - <<'PY'
import json, os, sys
work, lesson = os.environ["WORK"], os.environ["LESSON"]

def summary(scene, technique):
    m = json.load(open(os.path.join(work, scene, technique, "manifest.json")))
    frames = m["frames"]
    later = frames[1:]
    rerun = [s["stage"] for s in later[0]["stages_run"]] if later else []
    for f in later:  # the stages every later frame re-ran, in the order of the first
        names = {s["stage"] for s in f["stages_run"]}
        rerun = [s for s in rerun if s in names]
    return {
        "stages": rerun,
        "first": frames[0]["cpu_ms"],
        "later": min(f["cpu_ms"] for f in later),
        "flicker": m["temporal"]["mean_flicker"],
    }

rows = []
for t in os.environ["TECHNIQUES"].split():
    box, sponza = summary("cornell-box", t), summary("sponza", t)
    if not box["stages"] and not sponza["stages"]:
        continue
    rows.append(f"| {t} | {', '.join(box['stages']) or 'none'} | {box['first']:.0f} / {box['later']:.0f} "
                f"| {sponza['first']:.0f} / {sponza['later']:.0f} | {box['flicker']:.4f} | {sponza['flicker']:.4f} |")
header = "| technique | stages a light move re-runs"
table = [header + " | Cornell ms, first / later | Sponza ms, first / later | Cornell flicker | Sponza flicker |",
         "|---|---|---|---|---|---|"] + rows
lines = open(lesson).read().split("\n")
start = next((i for i, l in enumerate(lines) if l.startswith(header)), None)
if start is None:
    print("\n".join(table))
    sys.exit(f"lesson-motion: {lesson} has no table whose header starts with '{header}'; printed it instead")
end = start
while end < len(lines) and lines[end].startswith("|"):
    end += 1
lines[start:end] = table
open(lesson, "w").write("\n".join(lines))
print(f"lesson-motion: updated {lesson}: {len(rows)} techniques, {os.environ['FRAMES']} frames at "
      f"{os.environ['SIZE']}, load average {os.environ['LOAD_BEFORE']} before and {os.environ['LOAD_AFTER']} after, "
      f"{os.environ['SECONDS_TAKEN']} s", file=sys.stderr)
PY
