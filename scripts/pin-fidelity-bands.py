#!/usr/bin/env python3
"""Writes tests/fidelity/bands.json, the bands CI checks `voxlab fidelity --size 128x128` against,
from a measured report (fidelity.json of such a run). Review the change before committing it.

  build/voxlab fidelity --size 128x128 --out build/fidelity-128
  python3 scripts/pin-fidelity-bands.py build/fidelity-128/fidelity.json [--out tests/fidelity/bands.json]

Two kinds of band:
  - targets, one band for many cells: every technique's direct light within 5 % of the
    reference's on every scene (docs/fidelity.md, "Direct light"), except the techniques listed in
    DIRECT_EXEMPT and the scenes in DIRECT_PINNED_SCENES, which get pinned bands instead (sponza:
    1.046-1.050, inside the target but too near its edge for a band that host differences must not
    cross);
  - pins, one band per technique, scene and output where no target holds yet: the measured energy
    ratio +- PIN_MARGIN (relative), and SSIM no lower than measured - SSIM_MARGIN. A pin catches a
    regression (and an improvement, which then re-pins here); the technique's own target is in
    docs/fidelity.md.
Margins: two runs of the whole suite at 128x128 on llvmpipe (LP_NUM_THREADS=2, Intel Xeon host)
gave identical numbers in every cell; the Sponza textures' colours differ by up to 2 RGBA8 steps
between Intel and AMD hosts (tests/golden/tolerances.json), whose effect on these numbers was not
measured. PIN_MARGIN 0.05 and SSIM_MARGIN 0.03 leave room for that while failing any change of
the light a technique delivers by more than 5 %.
"""
import argparse
import datetime
import json
import os

DIRECT_TARGET = (0.95, 1.05)
DIRECT_EXEMPT = set()  # techniques whose direct light is pinned at its measured value, not held to the target
DIRECT_PINNED_SCENES = {"sponza"}
PIN_MARGIN = 0.05
SSIM_MARGIN = 0.03


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("report")
    parser.add_argument("--out", default=os.path.join(os.path.dirname(here), "tests", "fidelity", "bands.json"))
    args = parser.parse_args()
    report = json.load(open(args.report))
    day = datetime.date.today().isoformat()
    bands = [{"technique": "*", "scene": "*", "output": "direct", "metric": "mean_ratio",
              "min": DIRECT_TARGET[0], "max": DIRECT_TARGET[1],
              "why": "target: direct light within 5 % of the reference on every scene"}]
    exempt = sorted(DIRECT_EXEMPT)
    bands[0]["technique_except"] = exempt
    bands[0]["scene_except"] = sorted(DIRECT_PINNED_SCENES)
    for cell in report["cells"]:
        if "error" in cell:
            raise SystemExit(f"{cell['technique']} on {cell['scene']} failed: {cell['error']}")
        roles = {}
        for o in cell["outputs"]:
            if o.get("role") and "reference_error" in o and "skipped" not in o["reference_error"]:
                roles[o["role"]] = o  # the last of each role in stage order, as voxlab fidelity picks
        for role, o in sorted(roles.items()):
            r = o["reference_error"]
            if role == "direct" and cell["technique"] not in DIRECT_EXEMPT and cell["scene"] not in DIRECT_PINNED_SCENES:
                continue
            ratio, ssim = r["mean_ratio"], r["ssim"]
            measured = f"measured {ratio:.3f} (SSIM {ssim:.3f}) at {report['size']} on {day}"
            bands.append({"technique": cell["technique"], "scene": cell["scene"], "output": role,
                          "metric": "mean_ratio", "min": round(ratio * (1 - PIN_MARGIN), 4),
                          "max": round(ratio * (1 + PIN_MARGIN), 4), "why": "pin: " + measured})
            bands.append({"technique": cell["technique"], "scene": cell["scene"], "output": role,
                          "metric": "ssim", "min": round(max(ssim - SSIM_MARGIN, 0.0), 4),
                          "why": "pin: " + measured})
    doc = {"_comment": "The bands CI checks `voxlab fidelity --size %s` against (tests/fidelity/check_suite.sh), "
                       "written by scripts/pin-fidelity-bands.py from a measured run; its docstring says what the "
                       "margins allow and why." % report["size"],
           "bands": bands}
    with open(args.out, "w", encoding="utf-8", newline="\n") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    print(f"wrote {args.out}: {len(bands)} bands")


if __name__ == "__main__":
    main()
