#!/usr/bin/env python3
"""gallery.cornell_box: `voxlab gallery --scene cornell-box` shows every technique of `voxlab list`,
and its numbers are docs/fidelity.md's (the rows at default parameters), its pictures exist and
the page links them.

Tolerance: fidelity.md prints RMSE/MAE to 4 decimals, PSNR to 2, MRE/SSIM/mean ratio to 3. Two runs
of vct-grid differ by one RGBA8 step in a few voxels (inject's atomic averaging order; the EGL
test measured RMSE 1.5e-5 between two runs), which can move a rounded value by one unit of its
last digit, so each number may differ from the table by at most one such unit."""
import json, os, re, subprocess, sys

exe, root, out = sys.argv[1:4]
subprocess.run([exe, "gallery", "--scene", "cornell-box", "--bench-runs", "1", "--out", out], check=True)
page = json.load(open(os.path.join(out, "cornell-box.json")))
html = open(os.path.join(out, "cornell-box.html")).read()
listed = [t["id"] for t in json.loads(subprocess.run([exe, "list", "--json"], check=True, capture_output=True,
                                                      text=True).stdout)["techniques"]]
failures = []
def fail(msg):
    failures.append(msg)
    print("FAIL", msg)

if [t["id"] for t in page["techniques"]] != listed:
    fail(f"gallery techniques {[t['id'] for t in page['techniques']]} != voxlab list {listed}")

# docs/fidelity.md rows at defaults: technique, output (stage/output), mode, numbers.
table = {}
doc = open(os.path.join(root, "docs", "fidelity.md")).read()
# The gallery renders the Cornell box: only its table (other scenes' tables follow it).
if "<!-- fidelity-table:begin -->" in doc:
    doc = doc.split("<!-- fidelity-table:begin -->", 1)[1].split("<!-- fidelity-table:end -->", 1)[0]
for line in doc.splitlines():
    cells = [c.strip() for c in line.strip().strip("|").split("|")]
    if len(cells) != 10 or cells[1] != "defaults":
        continue
    output = re.sub(r" \(.*\)$", "", cells[2])
    table[(cells[0], output)] = {"mode": cells[3], "rmse": (cells[4], 4), "psnr": (cells[5], 2), "mae": (cells[6], 4),
                                 "mre": (cells[7], 3), "ssim": (cells[8], 3), "mean_ratio": (cells[9], 3)}
if not table:
    fail("no rows at defaults in docs/fidelity.md")

seen = set()
for t in page["techniques"]:
    if not t["frame_cpu_ms_median"] > 0:
        fail(f"{t['id']}: no time per frame")
    finals = [o for o in t["outputs"] if o["final"]]
    if len(finals) != 1:
        fail(f"{t['id']}: {len(finals)} final images")
    for o in t["outputs"]:
        for key in ("image", "reference_image", "error_image"):
            if key in o:
                if not os.path.isfile(os.path.join(out, o[key])):
                    fail(f"{o['address']}: {key} {o[key]} missing")
                if f'src="{o[key]}"' not in html:
                    fail(f"{o['address']}: the page does not show {o[key]}")
        r = o.get("reference_error")
        if not r or "skipped" in r:
            continue
        key = (t["id"], o["address"].split("/", 1)[1])
        if key not in table:
            fail(f"{o['address']} (mode {r['mode']}) has no row at defaults in docs/fidelity.md")
            continue
        seen.add(key)
        row = table[key]
        if row["mode"] != r["mode"]:
            fail(f"{o['address']}: mode {r['mode']}, fidelity.md says {row['mode']}")
        for name in ("rmse", "psnr", "mae", "mre", "ssim", "mean_ratio"):
            text, digits = row[name]
            got = r[name]
            if got is None or text == "inf":
                if not (got is None and text == "inf"):
                    fail(f"{o['address']} {name}: {got} vs {text}")
                continue
            if abs(got - float(text)) > 1.0 * 10 ** -digits + 1e-12:
                fail(f"{o['address']} {name}: gallery {got:.{digits}f}, docs/fidelity.md {text}")
        print(f"ok {o['address']} vs {r['mode']}: rmse {r['rmse']:.4f} ssim {r['ssim']:.3f}")
    if any("indirect term" in o["role"] for o in t["outputs"]):
        print(f"ok {t['id']}: indirect term {[o['address'] for o in t['outputs'] if 'indirect term' in o['role']]}")
for key in table:
    if key not in seen:
        fail(f"docs/fidelity.md row {key} is not in the gallery")

# A scene without checked-in references (any scene `voxlab list` names works; Sponza will have none
# until scripts/make-references.sh renders them): every technique still gets its row, and each
# tagged output says that no reference exists instead of showing numbers.
other = os.path.join(out, "no-reference")
subprocess.run([exe, "gallery", "--scene", os.path.join(root, "tests/data/scenes/furnace-box.gltf"), "--size", "64x64",
                "--bench-runs", "1", "--out", other], check=True)
page2 = json.load(open(os.path.join(other, "furnace-box.json")))
html2 = open(os.path.join(other, "furnace-box.html")).read()
if [t["id"] for t in page2["techniques"]] != listed:
    fail(f"furnace-box gallery techniques {[t['id'] for t in page2['techniques']]} != {listed}")
tagged = [o for t in page2["techniques"] for o in t["outputs"] if "reference_mode" in o]
if not tagged or any("reference_error" in o for o in tagged):
    fail(f"furnace-box: expected tagged outputs without reference numbers, got {tagged}")
if html2.count("no reference image for mode") != len(tagged):
    fail(f"furnace-box page: {html2.count('no reference image for mode')} 'no reference' notes for {len(tagged)} tagged outputs")
if failures:
    sys.exit(1)
print(f"gallery matches docs/fidelity.md ({len(seen)} rows)")
