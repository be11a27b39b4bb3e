#!/usr/bin/env python3
"""voxlab figure writes a labelled, self-contained SVG (inspect/figure.h).

Three figures of vct-grid on the Cornell box at 64x64 (a 32^3 grid):
- cone-trace/indirect-diffuse: the title is the address, a note names the changed parameter, two
  pictures (the output, 32x32: cone.resolution=half traces one pixel per 2x2 block, and the
  reference of mode indirect-1, stored at 512x512: the PNGs embedded as data URIs decode to those
  sizes), captions "indirect-diffuse" and "reference (indirect-1)", no
  colour bar (a radiance is shown tone mapped, not false colour);
- the same with --no-reference: one picture;
- gbuffer/depth: a false-colour view, so a colour bar whose two end labels are numbers, low below
  high, and no reference (depth declares no reference mode).
Usage: figure_check.py VOXLAB OUT
"""
import base64, os, shutil, struct, subprocess, sys
import xml.etree.ElementTree as ET

exe, out = sys.argv[1:3]
shutil.rmtree(out, ignore_errors=True)
os.makedirs(out)
NS = "{http://www.w3.org/2000/svg}"
problems = []


def figure(name, *args):
    path = os.path.join(out, name + ".svg")
    subprocess.run([exe, "figure", "--technique", "vct-grid", "--set", "voxel.resolution=32", "--size", "64x64",
                    "--width", "400", "--out", path, *args], check=True)
    return ET.parse(path).getroot()


def by_class(root, tag, cls):
    return [e for e in root.iter(NS + tag) if e.get("class") == cls]


def png_size(uri):
    data = base64.b64decode(uri.split(",", 1)[1])
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        return None
    return struct.unpack(">II", data[16:24])


def expect(what, got, want):
    if got != want:
        problems.append(f"{what}: got {got!r}, want {want!r}")
    print(("ok " if got == want else "FAIL ") + f"{what}: {got!r}")


root = figure("indirect", "--output", "cone-trace/indirect-diffuse")
expect("indirect title", [t.text for t in by_class(root, "text", "title")], ["vct-grid/cone-trace/indirect-diffuse@0"])
expect("indirect notes name the parameter", any("voxel.resolution=32" in (t.text or "") for t in by_class(root, "text", "note")), True)
expect("indirect picture sizes", [png_size(i.get("href")) for i in by_class(root, "image", "picture")], [(32, 32), (512, 512)])
expect("indirect captions", [t.text for t in by_class(root, "text", "caption")], ["indirect-diffuse", "reference (indirect-1)"])
expect("indirect colour bar", len(by_class(root, "rect", "colour-bar")), 0)

root = figure("no-reference", "--output", "cone-trace/indirect-diffuse", "--no-reference")
expect("--no-reference pictures", len(by_class(root, "image", "picture")), 1)

root = figure("depth", "--output", "gbuffer/depth")
expect("depth pictures", [png_size(i.get("href")) for i in by_class(root, "image", "picture")], [(64, 64)])
expect("depth colour bar", len(by_class(root, "rect", "colour-bar")), 1)
low, high = (by_class(root, "text", c) for c in ("bar-low", "bar-high"))
try:
    lo, hi = float(low[0].text), float(high[0].text)
    expect("depth bar range low < high", lo < hi, True)
except (IndexError, ValueError, TypeError) as e:
    problems.append(f"depth colour bar labels are not numbers: {e}")

for p in problems:
    print("FAIL " + p)
sys.exit(1 if problems else 0)
