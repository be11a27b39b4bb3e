#!/usr/bin/env bash
# Regenerates the timing table of docs/performance.md: `voxlab bench` runs every registered
# technique (`voxlab list --json`) at its defaults on one scene, and the bench.json files it writes
# become the text between the markers <!-- bench-table:begin --> and <!-- bench-table:end -->:
# per technique a frame (the stages the final image needs, `bench --final-only`: median and spread),
# per technique and stage the median and the spread (fastest and slowest timed run) of the stage's
# CPU wall time, the median GPU time, the GPU memory the run allocated, the wall time of whole
# `voxlab run --final-only` processes and of one whole `voxlab run` writing every output (what a
# user waits for at the defaults). Above the table: when, on what, the load average before
# and after (the machine may be shared: a later quiet run replaces a loaded one) and how long the
# whole measurement took.
#
#   scripts/bench-doc.sh [VOXLAB_BINARY]        (default: build/voxlab)
#   SCENE=sponza RUNS=5 PROCESS_RUNS=5 SIZE=512x512 DOC=docs/performance.md scripts/bench-doc.sh
#   TABLE_ONLY=1 scripts/bench-doc.sh           (re-render the table from the last measurement's files)
#
# Defaults: SCENE=cornell-box, RUNS=3 timed runs of all stages per technique, PROCESS_RUNS=3 whole
# processes, SIZE=512x512. The bench files go to WORK=build/bench-doc/<scene>/<technique>/.
#
# Then the per-frame table between <!-- frame-table:begin --> and <!-- frame-table:end -->: per
# technique `voxlab bench --frames FRAMES` on FRAME_SCENE (default cornell-box-moving, which has a
# moving object) at FRAME_SIZE (default 128x128, FRAMES 4: a few minutes for all techniques), the
# median per-frame CPU ms of a light move, a camera move and a moving object with the stages each
# re-ran, beside the per-frame GPU figures the technique's sources publish. Files go to
# FRAME_WORK=build/bench-doc/frames-<scene>/<technique>/.
#   PART=frames scripts/bench-doc.sh            (the per-frame table only; PART=bench: the timing table only)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
voxlab="$(realpath "${1:-$root/build/voxlab}")"
scene="${SCENE:-cornell-box}"
runs="${RUNS:-3}"
process_runs="${PROCESS_RUNS:-3}"
size="${SIZE:-512x512}"
doc="${DOC:-$root/docs/performance.md}"
work="${WORK:-$root/build/bench-doc/$scene}"
part="${PART:-all}"
frame_scene="${FRAME_SCENE:-cornell-box-moving}"
frame_size="${FRAME_SIZE:-128x128}"
frames="${FRAMES:-4}"
frame_work="${FRAME_WORK:-$root/build/bench-doc/frames-$frame_scene}"
case "$part" in all|bench|frames) ;; *) echo "bench-doc: PART must be all, bench or frames, not '$part'" >&2; exit 2;; esac
mkdir -p "$work" "$frame_work"

# Before a measurement: the load, the time, the source the binary was built from (read before
# measuring: edits made meanwhile do not count) and the techniques `voxlab list` names.
start_measurement() {
  load_before="$(cut -d' ' -f1-3 /proc/loadavg)"
  started="$(date -u '+%Y-%m-%d %H:%M UTC')"
  commit="$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)"
  git -C "$root" diff --quiet HEAD -- src shaders 2>/dev/null || commit="$commit with local changes"
  t0="$(date +%s.%N)"
  techniques="$("$voxlab" list --json | python3 -c 'import json,sys; print(" ".join(t["id"] for t in json.load(sys.stdin)["techniques"]))')"
}

# After it: what the table's header says about the measurement, written to FILE (TABLE_ONLY=1
# re-renders the tables from these files).   record_measurement FILE SETTINGS
record_measurement() {
  local t1 load_after
  t1="$(date +%s.%N)"
  load_after="$(cut -d' ' -f1-3 /proc/loadavg)"
  WALL_S="$(python3 -c "print(f'{$t1 - $t0:.0f}')")" STARTED="$started" COMMIT="$commit" \
  LOAD_BEFORE="$load_before" LOAD_AFTER="$load_after" CORES="$(nproc)" TECHNIQUES="$techniques" \
  THREADS="${LP_NUM_THREADS:-unset (llvmpipe: one per core)}" SETTINGS="$2" \
  python3 -c 'import json, os; keys = ["WALL_S", "STARTED", "COMMIT", "LOAD_BEFORE", "LOAD_AFTER", "CORES",
    "TECHNIQUES", "THREADS", "SETTINGS"]; print(json.dumps({k: os.environ[k] for k in keys}))' >"$1"
}

if [[ "$part" != frames && "${TABLE_ONLY:-0}" != 1 ]]; then
  start_measurement
  for t in $techniques; do
    "$voxlab" bench --technique "$t" --scene "$scene" --size "$size" --runs "$runs" \
      --process-runs "$process_runs" --out "$work/$t" >/dev/null
    "$voxlab" bench --technique "$t" --scene "$scene" --size "$size" --runs "$runs" --process-runs 0 \
      --final-only --out "$work/$t/final-only" >/dev/null
    rm -rf "$work/$t/run"
    w0="$(date +%s.%N)"
    "$voxlab" run --technique "$t" --scene "$scene" --size "$size" --out "$work/$t/run" >/dev/null
    w1="$(date +%s.%N)"
    python3 -c "import json; print(json.dumps({'whole_run_s': $w1 - $w0, 'files': $(find "$work/$t/run" -type f | wc -l)}))" \
      >"$work/$t/whole-run.json"
    echo "bench-doc: $t done" >&2
  done
  record_measurement "$work/run.json" "--scene $scene --size $size --runs $runs --process-runs $process_runs"
fi

if [[ "$part" != frames ]]; then
PYTHONPATH="$root/scripts" python3 - "$doc" "$work" <<'PY'
import json, os, sys
from doc_markers import update_doc
doc, work = sys.argv[1], sys.argv[2]
e = json.load(open(os.path.join(work, "run.json")))
benches = []
for t in e["TECHNIQUES"].split():
    b = json.load(open(os.path.join(work, t, "bench.json")))
    b["whole"] = json.load(open(os.path.join(work, t, "whole-run.json")))
    final_only = os.path.join(work, t, "final-only", "bench.json")
    b["final_only"] = json.load(open(final_only)) if os.path.exists(final_only) else None
    benches.append(b)
first = benches[0]

def ms(v):
    return f"{v:.1f}" if v < 100 else f"{v:.0f}"

# One runnable job per core is this measurement itself; more means other work shared the cores.
loads = [float(x) for x in e["LOAD_BEFORE"].split()[:1] + e["LOAD_AFTER"].split()[:1]]
if max(loads) > 1.5:
    load_note = (f"**The machine was shared** (other work ran beside the measurement): every time is an "
                 f"upper bound, at a load average of {max(loads):.0f} several times what a quiet machine "
                 "gives; a run at a load average below about 1.5 replaces this table.")
else:
    load_note = "The machine was quiet."
lines = [
    f"Measured {e['STARTED']} at {e['COMMIT']}: `voxlab bench {e['SETTINGS']}` for every technique "
    f"of `voxlab list`, {e['WALL_S']} s in all. {first['gl_renderer']}, {first['gl_version']}; "
    f"{e['CORES']} cores, LP_NUM_THREADS {e['THREADS']}. Load average (1, 5, 15 min) "
    f"{e['LOAD_BEFORE']} before and {e['LOAD_AFTER']} after. " + load_note,
    "",
    "| technique | a frame: the final image's stages (`bench --final-only`), median ms (min-max) "
    "| all stages, every output, median ms (min-max) | `run --final-only` process, median ms (min-max) "
    "| whole `run`, every output written: s (files) | GPU memory MiB |",
    "|---|---:|---:|---:|---:|---:|",
]

def totals(b):
    return b["total_cpu_ms_median"], [sum(s["cpu_ms"][i] for s in b["stages"]) for i in range(b["runs"])]
for b in benches:
    total, stage_totals = totals(b)
    frame = "not timed"
    if b["final_only"]:
        f_total, f_totals = totals(b["final_only"])
        frame = f"{ms(f_total)} ({ms(min(f_totals))}-{ms(max(f_totals))})"
    process = "not timed"
    if "process_wall_ms_median" in b:
        process = (f"{b['process_wall_ms_median']:.0f} ({b['process_wall_ms_min']:.0f}-"
                   f"{b['process_wall_ms_max']:.0f})")
    lines.append(f"| {b['technique']} | {frame} | {ms(total)} ({ms(min(stage_totals))}-{ms(max(stage_totals))}) | "
                 f"{process} | {b['whole']['whole_run_s']:.2f} ({b['whole']['files']}) | {b['memory_total_mib']:.1f} |")
lines += [
    "",
    "Per stage: CPU wall time (the stage's commands finished), median and the fastest and slowest "
    "timed run; GPU time from timer queries, median; the first run's CPU time (shader compilation "
    "included).",
    "",
    "| technique | stage | median ms | min-max ms | median GPU ms | first run ms |",
    "|---|---|---:|---:|---:|---:|",
]
for b in benches:
    for s in b["stages"]:
        lines.append(f"| {b['technique']} | {s['id']} | {ms(s['cpu_ms_median'])} | "
                     f"{ms(min(s['cpu_ms']))}-{ms(max(s['cpu_ms']))} | {ms(s['gpu_ms_median'])} | "
                     f"{ms(s['cpu_ms_first'])} |")
table = "\n".join(lines) + "\n"

if update_doc(doc, "bench-table", table, "bench-doc"):
    print(f"bench-doc: updated {doc}", file=sys.stderr)
PY
fi

[[ "$part" == bench ]] && exit 0

if [[ "${TABLE_ONLY:-0}" != 1 ]]; then
  start_measurement
  for t in $techniques; do
    "$voxlab" bench --technique "$t" --scene "$frame_scene" --size "$frame_size" --runs 1 --process-runs 0 \
      --frames "$frames" --out "$frame_work/$t" >/dev/null
    echo "bench-doc: $t frames done" >&2
  done
  record_measurement "$frame_work/run.json" \
    "--scene $frame_scene --size $frame_size --runs 1 --process-runs 0 --frames $frames"
fi

PYTHONPATH="$root/scripts" python3 - "$doc" "$frame_work" <<'PY'
import json, os, sys
from doc_markers import update_doc
doc, work = sys.argv[1], sys.argv[2]
e = json.load(open(os.path.join(work, "run.json")))
# What the sources publish per frame or per pass on their GPUs (the "Published GPU figures" table
# below the markers): quoted, and where a source gives passes only, their sum says so.
published = {
    "vct-grid": "Gomes 4.6 (GTX 750 Ti, Sponza, 256^3): passes 10.60 in all (voxelize 2.05, inject 1.76, "
                "occlusion fix 1.88, mipmap 0.71, cone trace 4.20); a light move re-runs inject to cone trace, 8.55",
    "svo": "Gomes 4.6 (same): SVO creation 64.72, mipmap 3.86, cone trace 51.74 (120.32 in all)",
    "lpv": "Gomes Table 4 (GTX 750 Ti, Sponza): 28.91 per frame (voxelization 12.28 of it; injection 0.11, "
           "propagation 1.79)",
    "lrsm": "SRS14 Tables 2-3 (GTX 770, Sponza): 58.5 per frame (voxelization 5.3, LRSM construction 3.1)",
    "near-field": "Gomes Table 5 (GTX 750 Ti, Sibenik): 7 fps, about 143 per frame (indirect lighting 40.46)",
    "clipmap": "compix VoxelConeTracingGI (GTX 1080, 1100x600): 8.3 per frame, one level updated per frame",
    "volumetric": "Gomes Table 2 (GTX 750 Ti, 1024x768): density 0.21, march 0.49 (half) / 1.80 (full), "
                  "blur + upsample 1.09 / 1.14",
}
def ms(v):
    return f"{v:.1f}" if v < 100 else f"{v:.0f}"
loads = [float(x) for x in e["LOAD_BEFORE"].split()[:1] + e["LOAD_AFTER"].split()[:1]]
if max(loads) > 1.5:
    load_note = (f"**The machine was shared** (other work ran beside the measurement): every time is an upper "
                 f"bound, at a load average up to {max(loads):.1f}; a run at a load average below about 1.5 replaces "
                 "this table.")
else:
    load_note = "The machine was quiet."
first = None
rows = []
for t in e["TECHNIQUES"].split():
    b = json.load(open(os.path.join(work, t, "bench.json")))
    first = first or b
    changes = {c["change"]: c for c in b["frame_changes"]}
    def cell(name):
        c = changes.get(name)
        return ms(c["frame_cpu_ms_median"]) if c else "-"
    def stages(name):
        c = changes.get(name)
        return ", ".join(c["stages"]) if c and c["stages"] else "none"
    rows.append(f"| {t} | {ms(b['total_cpu_ms_median'])} | {cell('light move')} | {cell('camera move')} | "
                f"{cell('moving object')} | {stages('light move')} | {stages('camera move')} | "
                f"{stages('moving object')} | {published.get(t, '-')} |")
lines = [
    f"Measured {e['STARTED']} at {e['COMMIT']}: `voxlab bench {e['SETTINGS']}` for every technique of "
    f"`voxlab list`, {e['WALL_S']} s in all. {first['gl_renderer']}; {e['CORES']} cores, LP_NUM_THREADS "
    f"{e['THREADS']}. Load average (1, 5, 15 min) {e['LOAD_BEFORE']} before and {e['LOAD_AFTER']} after. "
    + load_note,
    "",
    "Per-frame CPU ms on this machine, the median over the frames of the re-run stages' summed times "
    "(the full run, every stage once, beside them); the published figures are GPU ms on the sources' "
    "hardware and scenes, for scale only.",
    "",
    "| technique | full run ms | light move ms | camera move ms | moving object ms | light move re-runs "
    "| camera move re-runs | moving object re-runs | published GPU ms (source) |",
    "|---|---:|---:|---:|---:|---|---|---|---|",
] + rows
table = "\n".join(lines) + "\n"
if update_doc(doc, "frame-table", table, "bench-doc"):
    print(f"bench-doc: updated {doc} (frame table)", file=sys.stderr)
PY
