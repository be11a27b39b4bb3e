#!/bin/sh
# The fidelity suite at reduced size, as CI runs it: `voxlab fidelity` over every technique and
# every scene of scenes/suite.json at SIZE (default 128x128: the references are 256x256 or 512x512,
# compared box-filtered down; at 64x64 the corridor's small bright end wall aliases, direct
# 0.944), checked against tests/fidelity/bands.json (--check: exit 1 naming
# every number outside its band). Then the page in headless Chromium: a script appended to a copy
# of fidelity.html reports how many images there are and how many loaded, and how many rows and
# cells the table has; every image must load and the table must hold one row per technique (plus
# the header and the references' row) and one cell per scene. A control copy with one image
# missing must report it, so the check can fail.
# Exit 77 (skip) for the page check only when chromium is not installed (scripts/setup.sh installs it).
set -e
exe="$1"; root="$2"; out="$3"; size="${4:-128x128}"
rm -rf "$out"; mkdir -p "$out"
"$exe" fidelity --size "$size" --check "$root/tests/fidelity/bands.json" --out "$out/run" \
  >"$out/fidelity.log" 2>&1 || { cat "$out/fidelity.log"; cat "$out/run/fidelity.md" 2>/dev/null; exit 1; }
cat "$out/fidelity.log"

techniques=$("$exe" list --json | python3 -c 'import json,sys; print(len(json.load(sys.stdin)["techniques"]))')
scenes=$(python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))["scenes"]))' "$root/scenes/suite.json")
python3 - "$out/run/fidelity.json" "$techniques" "$scenes" <<'PY'
import json, sys
report, techniques, scenes = json.load(open(sys.argv[1])), int(sys.argv[2]), int(sys.argv[3])
cells = report["cells"]
assert len(cells) == techniques * scenes, f"{len(cells)} cells, want {techniques} x {scenes}"
failed = [c for c in cells if "error" in c]
assert not failed, f"runs failed: {[(c['technique'], c['scene'], c['error']) for c in failed]}"
compared = sum(1 for c in cells for o in c["outputs"] if "reference_error" in o and "skipped" not in o["reference_error"])
assert compared >= 3 * scenes * (techniques - 2), f"only {compared} outputs compared with a reference"
print(f"fidelity.json: {len(cells)} cells, {compared} outputs compared with a reference")
PY

command -v chromium >/dev/null 2>&1 || { echo "chromium is not installed (scripts/setup.sh installs it): page not checked"; exit 77; }
instrument() {  # page.html -> page.check.html
  sed 's#</body>#<script>\
window.addEventListener("load", function () {\
  var imgs = Array.prototype.slice.call(document.images);\
  var loaded = imgs.filter(function (i) { return i.complete \&\& i.naturalWidth > 0; }).length;\
  var rows = document.querySelectorAll("table.grid tr");\
  var p = document.createElement("pre"); p.id = "voxlab-check";\
  p.textContent = "images=" + imgs.length + " loaded=" + loaded + " rows=" + rows.length +\
    " cells=" + rows[rows.length - 1].querySelectorAll("td").length;\
  document.body.appendChild(p);\
});\
</script></body>#' "$1" > "$2"
}
browse() {
  chromium --headless --no-sandbox --disable-gpu --disable-dev-shm-usage --user-data-dir="$out/profile" \
    --allow-file-access-from-files --virtual-time-budget=20000 --dump-dom "file://$1" 2>"$out/chromium.log" |
    sed -n 's#.*<pre id="voxlab-check">\([^<]*\)</pre>.*#\1#p'
}
instrument "$out/run/fidelity.html" "$out/run/fidelity.check.html"
got=$(browse "$out/run/fidelity.check.html")
images=$(echo "$got" | sed -n 's/images=\([0-9]*\) .*/\1/p')
want="images=$images loaded=$images rows=$((techniques + 2)) cells=$scenes"
[ "$got" = "$want" ] || { echo "FAIL page: got '$got', want '$want'"; cat "$out/chromium.log"; exit 1; }
[ "$images" -ge $((techniques * scenes)) ] || { echo "FAIL page: $images images for $techniques x $scenes cells"; exit 1; }
echo "ok page: $got"
# Control: one image missing must be reported.
first=$(grep -o 'src="[^"]*\.png"' "$out/run/fidelity.html" | head -n 1 | sed 's/src="\(.*\)"/\1/')
sed "s#src=\"$first\"#src=\"no-such-image.png\"#" "$out/run/fidelity.html" > "$out/run/control.html"
instrument "$out/run/control.html" "$out/run/control.check.html"
got=$(browse "$out/run/control.check.html")
case "$got" in
  "images=$images loaded=$((images - 1)) "*) echo "ok control: $got" ;;
  *) echo "FAIL control: got '$got', want one image not loaded"; exit 1 ;;
esac
