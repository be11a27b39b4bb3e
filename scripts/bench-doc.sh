#!/usr/bin/env bash
# Regenerates the timing table of docs/performance.md: `voxlab bench` runs every registered
# technique (`voxlab list --json`) at its defaults on one scene, and the bench.json files it writes
# become the text between the markers <!-- bench-table:begin --> and <!-- bench-table:end -->:
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
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
voxlab="$(realpath "${1:-$root/build/voxlab}")"
scene="${SCENE:-cornell-box}"
runs="${RUNS:-3}"
process_runs="${PROCESS_RUNS:-3}"
size="${SIZE:-512x512}"
doc="${DOC:-$root/docs/performance.md}"
work="${WORK:-$root/build/bench-doc/$scene}"
mkdir -p "$work"

if [[ "${TABLE_ONLY:-0}" != 1 ]]; then
  load_before="$(cut -d' ' -f1-3 /proc/loadavg)"
  started="$(date -u '+%Y-%m-%d %H:%M UTC')"
  t0="$(date +%s.%N)"
  techniques="$("$voxlab" list --json | python3 -c 'import json,sys; print(" ".join(t["id"] for t in json.load(sys.stdin)["techniques"]))')"
  for t in $techniques; do
    "$voxlab" bench --technique "$t" --scene "$scene" --size "$size" --runs "$runs" \
      --process-runs "$process_runs" --out "$work/$t" >/dev/null
    rm -rf "$work/$t/run"
    w0="$(date +%s.%N)"
    "$voxlab" run --technique "$t" --scene "$scene" --size "$size" --out "$work/$t/run" >/dev/null
    w1="$(date +%s.%N)"
    python3 -c "import json; print(json.dumps({'whole_run_s': $w1 - $w0, 'files': $(find "$work/$t/run" -type f | wc -l)}))" \
      >"$work/$t/whole-run.json"
    echo "bench-doc: $t done" >&2
  done
  t1="$(date +%s.%N)"
  load_after="$(cut -d' ' -f1-3 /proc/loadavg)"
  commit="$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)"
  git -C "$root" diff --quiet HEAD -- src shaders 2>/dev/null || commit="$commit with local changes"
  # What the table's header says about this measurement; TABLE_ONLY=1 re-renders from it.
  WALL_S="$(python3 -c "print(f'{$t1 - $t0:.0f}')")" STARTED="$started" COMMIT="$commit" \
  LOAD_BEFORE="$load_before" LOAD_AFTER="$load_after" CORES="$(nproc)" TECHNIQUES="$techniques" \
  THREADS="${LP_NUM_THREADS:-unset (llvmpipe: one per core)}" \
  SETTINGS="--scene $scene --size $size --runs $runs --process-runs $process_runs" \
  python3 -c 'import json, os; keys = ["WALL_S", "STARTED", "COMMIT", "LOAD_BEFORE", "LOAD_AFTER", "CORES",
    "TECHNIQUES", "THREADS", "SETTINGS"]; print(json.dumps({k: os.environ[k] for k in keys}))' >"$work/run.json"
fi

python3 - "$doc" "$work" <<'PY'
import json, os, sys
doc, work = sys.argv[1], sys.argv[2]
e = json.load(open(os.path.join(work, "run.json")))
benches = []
for t in e["TECHNIQUES"].split():
    b = json.load(open(os.path.join(work, t, "bench.json")))
    b["whole"] = json.load(open(os.path.join(work, t, "whole-run.json")))
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
    "| technique | all stages, median ms (min-max) | `run --final-only` process, median ms (min-max) "
    "| whole `run`, every output written: s (files) | GPU memory MiB |",
    "|---|---:|---:|---:|---:|",
]
for b in benches:
    total = b["total_cpu_ms_median"]
    stage_totals = [sum(s["cpu_ms"][i] for s in b["stages"]) for i in range(b["runs"])]
    process = "not timed"
    if "process_wall_ms_median" in b:
        process = (f"{b['process_wall_ms_median']:.0f} ({b['process_wall_ms_min']:.0f}-"
                   f"{b['process_wall_ms_max']:.0f})")
    lines.append(f"| {b['technique']} | {ms(total)} ({ms(min(stage_totals))}-{ms(max(stage_totals))}) | "
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

begin, end = "<!-- bench-table:begin -->", "<!-- bench-table:end -->"
text = open(doc).read() if os.path.exists(doc) else ""
if begin in text and end in text:
    head, rest = text.split(begin, 1)
    _, tail = rest.split(end, 1)
    open(doc, "w").write(head + begin + "\n" + table + end + tail)
    print(f"bench-doc: updated {doc}", file=sys.stderr)
else:
    print(table)
    print(f"bench-doc: {doc} has no {begin} ... {end}; printed the table instead", file=sys.stderr)
PY
