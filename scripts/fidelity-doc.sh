#!/usr/bin/env bash
# Regenerates the tables of docs/fidelity.md: `voxlab fidelity` over every technique and every
# scene of scenes/suite.json at its default size, and its fidelity.md tables pasted between
# <!-- fidelity-table:begin --> and <!-- fidelity-table:end -->; then `voxlab fidelity --frames 16`
# over the suite's animated scenes, its tables (flicker and energy per frame against the path
# tracer's frames) pasted between <!-- fidelity-frames:begin --> and <!-- fidelity-frames:end -->.
# The page with the pictures is build/fidelity/fidelity.html. Nothing here names a technique or a
# scene.
#
#   scripts/fidelity-doc.sh [VOXLAB_BINARY]     (default: build/voxlab; about 3 minutes here)
#   FIDELITY_ARGS="--set cone.aperture=60" scripts/fidelity-doc.sh   (extra arguments)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
voxlab="$(realpath "${1:-$root/build/voxlab}")"
out="$root/build/fidelity"
# shellcheck disable=SC2086
"$voxlab" fidelity --out "$out" ${FIDELITY_ARGS:-}
# shellcheck disable=SC2086
"$voxlab" fidelity --frames 16 --out "$out/frames" ${FIDELITY_ARGS:-}
PYTHONPATH="$root/scripts" python3 - "$root/docs/fidelity.md" "$out/fidelity.md" "$out/fidelity.json" "$out/frames/fidelity.md" <<'PY'
import json, sys
from doc_markers import paste_between_markers
doc_path, tables_path, report_path, frames_path = sys.argv[1:5]
doc, tables, report = open(doc_path).read(), open(tables_path).read(), json.load(open(report_path))

def paste(doc, marker, body):
    pasted = paste_between_markers(doc, marker, body + "\n")
    if pasted is None:
        sys.exit(f"{doc_path} has no <!-- {marker}:begin --> ... <!-- {marker}:end -->")
    return pasted

body = tables.split("\n", 1)[1].strip()  # without the page's own heading
doc = paste(doc, "fidelity-table", body + "\n\nWhole run: %.0f s." % report["wall_s"])
frames = open(frames_path).read().split("\n", 1)[1].strip().replace("\n### ", "\n#### ")
doc = paste(doc, "fidelity-frames", frames)
open(doc_path, "w").write(doc)
print(f"fidelity-doc: updated {doc_path}", file=sys.stderr)
PY
