#!/usr/bin/env bash
# Regenerates the fidelity table in docs/fidelity.md: every registered technique (`voxlab list
# --json`) is run with its default parameters (plus the variants listed below) on the Cornell box,
# camera 0, 512x512, and the "reference_error" entries `voxlab run` writes into its manifest (one
# per output tagged with a reference mode) become the table's rows.
#
#   scripts/fidelity.sh [VOXLAB_BINARY]      (default: build/voxlab)
#
# Needs the references in tests/golden/reference/cornell-box/ (scripts/make-references.sh).
# Outputs (and the error images) go to build/fidelity/<technique>[+variant]/.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
voxlab="$(realpath "${1:-$root/build/voxlab}")"
scene=cornell-box
size=512x512
work="$root/build/fidelity"
doc="$root/docs/fidelity.md"
mkdir -p "$work"

# Extra rows: "technique name=value[,name=value...]".
variants=(
  "vct-grid cone.resolution=full"
  "vct-grid mipmap.mode=anisotropic"
  "lpv gi.lookup-sign=plus-n"
  "lpv lpv.scheme=thesis,lpv.weighting=thesis"
  "lpv inject.vpl-shift=0.5"
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

for t in $("$voxlab" list --json | python3 -c 'import json,sys; print(" ".join(t["id"] for t in json.load(sys.stdin)["techniques"]))'); do
  run "$t"
  for v in "${variants[@]}"; do
    if [[ "${v%% *}" == "$t" ]]; then run "$t" "${v#* }"; fi
  done
done

python3 - "$doc" "${runs[@]}" <<'PY'
import json, sys
doc, manifests = sys.argv[1], sys.argv[2:]
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
begin, end = "<!-- fidelity-table:begin -->", "<!-- fidelity-table:end -->"
try:
    text = open(doc).read()
except FileNotFoundError:
    text = ""
if begin in text and end in text:
    head, rest = text.split(begin, 1)
    _, tail = rest.split(end, 1)
    open(doc, "w").write(head + begin + "\n" + table + end + tail)
    print(f"fidelity: updated {doc}", file=sys.stderr)
else:
    print(table)
PY
