#!/usr/bin/env bash
# Regenerates the fidelity tables in docs/fidelity.md: every registered technique (`voxlab list
# --json`) is run with its default parameters (plus the variants listed below) on each scene,
# camera 0, 512x512, and the "reference_error" entries `voxlab run` writes into its manifest (one
# per output tagged with a reference mode) become the table's rows (between the markers
# <!-- fidelity-table:begin/end --> for the Cornell box, <!-- fidelity-table:<scene>:begin/end -->
# for the other scenes).
#
#   scripts/fidelity.sh [VOXLAB_BINARY]      (default: build/voxlab)
#   SCENES=sponza scripts/fidelity.sh        (only some scenes; default: cornell-box sponza)
#   TECHNIQUES=vct-grid scripts/fidelity.sh  (only some techniques: their rows are replaced, the
#                                             other techniques' rows are kept as they are)
#
# Needs the references in tests/golden/reference/<scene>/ (scripts/make-references.sh).
# Outputs (and the error images) go to build/fidelity/<scene>/<technique>[+variant]/.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
voxlab="$(realpath "${1:-$root/build/voxlab}")"
size=512x512
doc="$root/docs/fidelity.md"
for scene in ${SCENES:-cornell-box sponza}; do
work="$root/build/fidelity/$scene"
mkdir -p "$work"
marker=fidelity-table
[[ "$scene" == cornell-box ]] || marker="fidelity-table:$scene"

# Extra rows: "technique name=value[,name=value...]".
variants=(
  "vct-grid cone.resolution=full"
  "vct-grid mipmap.mode=isotropic"
  "vct-grid mipmap.mode=max-opacity"
  "vct-grid cone.aperture=60"
  "vct-grid cone.max-distance=1"
  "vct-grid inject.shadow-offset=0"
  "vct-grid inject.average=compare-and-swap"
  "vct-grid bounces=2"
  "vct-grid bounces=3"
  "vct-grid voxel.format=rgba16f"
  "vct-grid voxel.format=rgba16f,bounces=3"
  "vct-grid mipmap.mode=isotropic,cone.aperture=60,cone.max-distance=1,inject.shadow-offset=0,inject.average=compare-and-swap"
  "lpv gi.lookup-sign=plus-n"
  "lpv lpv.scheme=thesis,lpv.weighting=thesis"
  "near-field rays.radius=2"
  "near-field rays.count=32"
  "voxel-path-tracing paths.bounces=1"
  "voxel-path-tracing paths.bounces=4"
  "voxel-path-tracing paths.count=16"
  "svo svo.dilate=true"
  "lpv inject.vpl-shift=0.5"
  "lpv inject.lighting=per-cell"
  "svo svo.layout=tile"
  "svo cone.aperture=60,cone.max-distance=1"
  "lrsm lrsm.estimator=paper"
)

runs=()
run() {  # technique [name=value,...]
  local label="$1" sets=()
  if [[ -n "${2:-}" ]]; then
    label="$1+${2//,/+}"
    IFS=',' read -ra assignments <<<"$2"
    for a in "${assignments[@]}"; do sets+=(--set "$a"); done
  fi
  nice -n 10 "$voxlab" run --technique "$1" --scene "$scene" --size "$size" --camera 0 "${sets[@]}" \
    --out "$work/$label" >/dev/null
  runs+=("$work/$label/manifest.json")
  echo "fidelity: ran $label" >&2
}

for t in ${TECHNIQUES:-$("$voxlab" list --json | python3 -c 'import json,sys; print(" ".join(t["id"] for t in json.load(sys.stdin)["techniques"]))')}; do
  run "$t"
  for v in "${variants[@]}"; do
    if [[ "${v%% *}" == "$t" ]]; then run "$t" "${v#* }"; fi
  done
done

TECHNIQUES="${TECHNIQUES:-}" python3 - "$doc" "$marker" "${runs[@]}" <<'PY'
import json, os, sys
doc, marker, manifests = sys.argv[1], sys.argv[2], sys.argv[3:]
only = os.environ["TECHNIQUES"].split()
rows = ["| technique | parameters (non-default) | output | reference | RMSE | PSNR (dB) | MAE | MRE | SSIM | mean ratio |",
        "|---|---|---|---|---:|---:|---:|---:|---:|---:|"]
notes = {}
for path in manifests:
    m = json.load(open(path))
    label = path.split("/")[-2]
    params = ", ".join(label.split("+")[1:]) or "defaults"
    for s in m["stages"]:
        for o in s["outputs"]:
            r = o.get("reference_error")
            if not r:
                continue
            if "skipped" in r:
                rows.append(f"| {m['technique']} | {params} | {s['id']}/{o['name']} | {r['mode']} | skipped: {r['skipped']} ||||||")
                continue
            psnr = "inf" if r["psnr"] is None else f"{r['psnr']:.2f}"
            out = f"{s['id']}/{o['name']}"
            k = r.get("reference_downsampled")
            if k:
                out += f" (1/{k} res., vs reference box-filtered {k}x{k})"
            rows.append(f"| {m['technique']} | {params} | {out} | {r['mode']} | "
                        f"{r['rmse']:.4f} | {psnr} | {r['mae']:.4f} | {r['mre']:.3f} | {r['ssim']:.3f} | {r['mean_ratio']:.3f} |")
            notes[r["mode"]] = (r.get("spp"), r.get("rms_stderr"))
table = "\n".join(rows) + "\n\nReferences used (spp, RMS standard error): " + ", ".join(
    f"{k} {v[0]} spp / {v[1]:.4g}" for k, v in sorted(notes.items()) if v[1] is not None) + ".\n"
begin, end = f"<!-- {marker}:begin -->", f"<!-- {marker}:end -->"
try:
    text = open(doc).read()
except FileNotFoundError:
    text = ""
if begin in text and end in text:
    head, rest = text.split(begin, 1)
    old, tail = rest.split(end, 1)
    if only:
        # Keep the other techniques' rows (and the old references line); the new rows take the
        # place of the first old row of these techniques.
        kept, placed = [], False
        for line in old.strip("\n").split("\n"):
            cells = [c.strip() for c in line.split("|")]
            if len(cells) > 2 and cells[1] in only:
                if not placed:
                    kept += rows[2:]
                    placed = True
                continue
            kept.append(line)
        if not placed:
            kept = kept[:2] + rows[2:] + kept[2:]
        # The references line lists every mode the table uses: the kept rows' and the new ones'.
        used, refs = {}, ""
        for line in kept:
            cells = [c.strip() for c in line.split("|")]
            if len(cells) > 4 and cells[1] not in ("technique", "---"):
                used[cells[4]] = True
            if line.startswith("References used"):
                for entry in line.split(": ", 1)[1].rstrip(".").split(", "):
                    mode, rest = entry.split(" ", 1)
                    spp, err = rest.split(" spp / ")
                    notes.setdefault(mode, (int(spp), float(err)))
        kept = [line for line in kept if line.strip() and not line.startswith("References used")]
        table = "\n".join(kept) + "\n\nReferences used (spp, RMS standard error): " + ", ".join(
            f"{k} {v[0]} spp / {v[1]:.4g}" for k, v in sorted(notes.items()) if v[1] is not None and k in used) + ".\n"
    open(doc, "w").write(head + begin + "\n" + table + end + tail)
    print(f"fidelity: updated {doc}", file=sys.stderr)
else:
    print(table)
PY
done
