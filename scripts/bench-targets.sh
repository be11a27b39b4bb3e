#!/usr/bin/env bash
# Measures the speed targets of docs/performance.md ("Against the targets") back to back against a
# baseline build, and writes the result between <!-- targets-table:begin --> and
# <!-- targets-table:end -->.
#
#   scripts/bench-targets.sh [BASELINE_COMMIT]    (default: ab9f77c, main before outputs on demand)
#   ROUNDS=3 RUNS=3 PROCESS_RUNS=3 SIZE=512x512 SCENE=cornell-box scripts/bench-targets.sh
#   TABLE_ONLY=1 scripts/bench-targets.sh         (re-render from the last measurement's files)
#
# The baseline is checked out in a worktree under build/targets-baseline/ and its voxlab built
# there (its own shaders: VOXLAB_ROOT points at the worktree). Then, per technique of `voxlab
# list`, ROUNDS rounds alternate the two builds, each round timing with either:
#   - `voxlab bench`: a frame (the baseline computed every stage for any image; this build's
#     `bench --final-only` computes the final image's stages only), whole `run --final-only`
#     processes (start-up included) and the GPU memory the run allocated;
#   - one whole `voxlab run` writing every output (what "a whole run" meant when the targets were set).
# vct-grid is also timed with every cone at full resolution (`cone.resolution=full`), and its voxel
# stages (voxelize to mipmap) are summed. Files go to WORK=build/bench-targets/.
#
# The targets: vct-grid frame <= 350 ms; full resolution <= 950 ms (the peer renderer's frame on
# this machine); voxelize + inject + occlusion fix + mips <= 30 ms; every technique's final-only
# process <= half of the baseline's whole run. Each target is judged on the median over the rounds
# (of the baseline's whole runs for the limit): on a shared machine one round can be slowed by
# other work, which the range beside it shows. The GPU memory column is for reading: that a
# final-only run allocates only what its final image needs is a test (EveryTechnique/OnDemand).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
baseline="${1:-ab9f77c}"
rounds="${ROUNDS:-3}"
runs="${RUNS:-3}"
process_runs="${PROCESS_RUNS:-3}"
size="${SIZE:-512x512}"
scene="${SCENE:-cornell-box}"
doc="${DOC:-$root/docs/performance.md}"
work="${WORK:-$root/build/bench-targets}"
voxlab="$root/build/voxlab"
base_src="$root/build/targets-baseline/src"

if [[ "${TABLE_ONLY:-0}" != 1 ]]; then
  base_commit="$(git -C "$root" rev-parse --verify --quiet "$baseline^{commit}")" ||
    { echo "bench-targets: '$baseline' is not a commit of this repository (give a commit id or tag)" >&2; exit 2; }
  [[ -x "$voxlab" ]] || { echo "bench-targets: $voxlab is missing: run scripts/build.sh first" >&2; exit 2; }
  if [[ "$(git -C "$base_src" rev-parse HEAD 2>/dev/null || true)" != "$base_commit" ]]; then
    rm -rf "$base_src"
    git -C "$root" worktree prune
    mkdir -p "$(dirname "$base_src")"
    git -C "$root" worktree add --detach --force "$base_src" "$base_commit" >/dev/null
  fi
  echo "bench-targets: building the baseline $baseline in $base_src (the voxlab target only)" >&2
  cmake -S "$base_src" -B "$base_src/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$base_src/build" -j"$(nproc)" --target voxlab >/dev/null
  base_voxlab="$base_src/build/voxlab"

  rm -rf "$work"
  mkdir -p "$work"
  load_before="$(cut -d' ' -f1-3 /proc/loadavg)"
  started="$(date -u '+%Y-%m-%d %H:%M UTC')"
  commit="$(git -C "$root" rev-parse --short HEAD)"
  git -C "$root" diff --quiet HEAD -- src shaders || commit="$commit with local changes"
  t0="$(date +%s)"
  techniques="$("$voxlab" list --json | python3 -c 'import json,sys; print(" ".join(t["id"] for t in json.load(sys.stdin)["techniques"]))')"

  # measure SIDE ROUND TECHNIQUE [SET...]: one bench and (without SETs) one timed whole run.
  measure() {
    local side="$1" round="$2" t="$3"; shift 3
    local sets=() name="$t" out bin final=()
    for s in "$@"; do sets+=(--set "$s"); name="$name+$s"; done
    out="$work/$side/$name/r$round"
    mkdir -p "$out"
    if [[ "$side" == base ]]; then
      bin=(env VOXLAB_ROOT="$base_src" "$base_voxlab")
    else
      bin=("$voxlab"); final=(--final-only)
    fi
    (cd "$work" && "${bin[@]}" bench --technique "$t" --scene "$scene" --size "$size" --runs "$runs" \
      --process-runs "$process_runs" "${final[@]}" "${sets[@]}" --out "$out/bench" >/dev/null)
    [[ $# -gt 0 ]] && return 0
    local w0 w1
    w0="$(date +%s.%N)"
    (cd "$work" && "${bin[@]}" run --technique "$t" --scene "$scene" --size "$size" --out "$out/run" >/dev/null)
    w1="$(date +%s.%N)"
    python3 -c "print($w1 - $w0)" >"$out/whole-run-s"
    rm -rf "$out/run"
  }
  for t in $techniques; do
    for r in $(seq "$rounds"); do
      measure base "$r" "$t"
      measure new "$r" "$t"
      if [[ "$t" == vct-grid ]]; then
        measure base "$r" "$t" cone.resolution=full
        measure new "$r" "$t" cone.resolution=full
      fi
    done
    echo "bench-targets: $t done" >&2
  done
  python3 -c 'import json, sys; print(json.dumps(dict(zip(["baseline", "commit", "started", "load_before",
    "load_after", "wall_s", "settings", "techniques"], sys.argv[1:]))))' \
    "$baseline" "$commit" "$started" "$load_before" "$(cut -d' ' -f1-3 /proc/loadavg)" "$(( $(date +%s) - t0 ))" \
    "--scene $scene --size $size --runs $runs --process-runs $process_runs, $rounds rounds" "$techniques" \
    >"$work/measurement.json"
fi

PYTHONPATH="$root/scripts" python3 - "$doc" "$work" <<'PY'
import glob, json, os, statistics, sys
from doc_markers import update_doc
doc, work = sys.argv[1], sys.argv[2]
m = json.load(open(os.path.join(work, "measurement.json")))

def rounds(side, name):
    """Per round: the bench (and the whole run's seconds where timed)."""
    out = []
    for d in sorted(glob.glob(os.path.join(work, side, name, "r*"))):
        b = json.load(open(os.path.join(d, "bench", "bench.json")))
        whole = os.path.join(d, "whole-run-s")
        b["whole_s"] = float(open(whole).read()) if os.path.exists(whole) else None
        out.append(b)
    return out

def span(values, scale=1.0, digits=0):
    lo, hi = min(values) * scale, max(values) * scale
    f = lambda v: f"{v:.{digits}f}"
    return f(lo) if f(lo) == f(hi) else f"{f(lo)}-{f(hi)}"

VOXEL_STAGES = ("voxelize-static", "voxelize", "inject", "occlusion-fix", "mipmap")
def voxel_stages(b):
    return sum(s["cpu_ms_median"] for s in b["stages"] if s["id"] in VOXEL_STAGES)

loads = [float(x) for x in (m["load_before"].split()[:1] + m["load_after"].split()[:1])]
quiet = "The machine was quiet." if max(loads) <= 1.5 else (
    f"**The machine was shared** (load average up to {max(loads):.1f}): both builds ran under the same load, "
    "so the ratios hold; the absolute times are upper bounds.")
lines = [
    f"Measured {m['started']} at {m['commit']} against the baseline {m['baseline']}, alternated round by round "
    f"(`scripts/bench-targets.sh`, {m['settings']}, {m['wall_s']} s in all). Load average (1, 5, 15 min) "
    f"{m['load_before']} before and {m['load_after']} after. {quiet} Each cell is the range of the rounds' "
    "medians, baseline -> now; a target is met when the median over the rounds is within it.",
    "",
    "| technique | a frame, ms | `run --final-only` process, ms | whole `run`, every output, s | final-only limit: half the baseline's median whole run, ms | met | GPU memory of a final-only run, MiB |",
    "|---|---:|---:|---:|---:|---|---:|",
]
met_count, techniques = 0, m["techniques"].split()
for t in techniques:
    base, new = rounds("base", t), rounds("new", t)
    limit = 0.5 * 1000.0 * statistics.median(b["whole_s"] for b in base)
    met = statistics.median(b["process_wall_ms_median"] for b in new) <= limit
    met_count += met
    lines.append(
        f"| {t} | {span([b['total_cpu_ms_median'] for b in base])} -> {span([b['total_cpu_ms_median'] for b in new])} "
        f"| {span([b['process_wall_ms_median'] for b in base])} -> {span([b['process_wall_ms_median'] for b in new])} "
        f"| {span([b['whole_s'] for b in base], digits=2)} -> {span([b['whole_s'] for b in new], digits=2)} "
        f"| {limit:.0f} | {'yes' if met else '**no**'} "
        f"| {span([b['memory_total_mib'] for b in base], digits=1)} -> {span([b['memory_total_mib'] for b in new], digits=1)} |")

vb, vn = rounds("base", "vct-grid"), rounds("new", "vct-grid")
fb, fn = rounds("base", "vct-grid+cone.resolution=full"), rounds("new", "vct-grid+cone.resolution=full")
frame = statistics.median(b["total_cpu_ms_median"] for b in vn)
full = statistics.median(b["total_cpu_ms_median"] for b in fn)
voxels = statistics.median(voxel_stages(b) for b in vn)
yes = lambda ok: "yes" if ok else "**no**"
lines += [
    "",
    "| target | baseline | now | met |",
    "|---|---:|---:|---|",
    f"| vct-grid frame at the defaults at most 350 ms | {span([b['total_cpu_ms_median'] for b in vb])} | "
    f"{span([b['total_cpu_ms_median'] for b in vn])} | {yes(frame <= 350.0)} |",
    f"| vct-grid with every cone at full resolution at most 950 ms (the peer's frame here) | "
    f"{span([b['total_cpu_ms_median'] for b in fb])} | {span([b['total_cpu_ms_median'] for b in fn])} | {yes(full <= 950.0)} |",
    f"| voxelize, inject, occlusion fix and mips at most 30 ms (vct-grid, 128^3) | "
    f"{span([voxel_stages(b) for b in vb], digits=1)} | {span([voxel_stages(b) for b in vn], digits=1)} | {yes(voxels <= 30.0)} |",
    f"| every technique's final-only process at most half the baseline's whole run | | {met_count} of {len(techniques)} | "
    f"{yes(met_count == len(techniques))} |",
]
if update_doc(doc, "targets-table", "\n".join(lines) + "\n", "bench-targets"):
    print(f"bench-targets: updated {doc}", file=sys.stderr)
PY
