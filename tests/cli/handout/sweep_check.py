#!/usr/bin/env python3
"""A lesson step's sweep in its handout, in headless Chromium.

`voxlab handout` of tests/cli/handout/sweep-lesson.md (one step sweeping cone.aperture over 30, 45
and 60 on a 32^3 grid) must write the sweep (LESSON/sweep-1/sweep.json with three runs), a
sentence under the step naming the measured error of every run, and an <iframe> of the sweep's
slider page. A copy of the handout with a script appended opens in Chromium; after the load event
the script reaches into the frame, sets its slider to 2 and dispatches an input event (what
dragging it does), then writes out the frame's final image and every plot's marker and run-2
point. The frame must show run 2: its final image is sweep.json's run 2 and every marker sits on
run 2's point. Control: before the slider moves the frame shows run 0, whose image differs.
Exit 77 (skip) only when chromium is missing.
Usage: sweep_check.py VOXLAB ROOT OUT
"""
import json, os, re, shutil, subprocess, sys

exe, root, out = sys.argv[1:4]
if not shutil.which("chromium"):
    print("chromium is not installed (scripts/setup.sh installs it): skipping")
    sys.exit(77)
shutil.rmtree(out, ignore_errors=True)
os.makedirs(out)
subprocess.run([exe, "handout", os.path.join(root, "tests/cli/handout/sweep-lesson.md"), "--size", "64x64",
                "--out", out], check=True)
page = os.path.join(out, "sweep-lesson.html")
text = open(page).read()
report = json.load(open(os.path.join(out, "sweep-lesson/sweep-1/sweep.json")))
problems = []
if len(report["runs"]) != 3:
    problems.append(f"sweep.json has {len(report['runs'])} runs, want 3")
errors = ", ".join(f"{run['error']:.3f}" for run in report["runs"])
if errors not in text:
    problems.append(f"the handout does not name the runs' errors ({errors})")
if '<iframe src="sweep-lesson/sweep-1/sweep.html"' not in text:
    problems.append("the handout has no frame of the sweep page")

# The script: move the frame's slider to 'k' (or leave it, k < 0) and write what the frame shows.
probe = """<script>
window.addEventListener('load', function () {
  var d = document.querySelector('.sweep iframe').contentDocument, k = K;
  if (k >= 0) { var s = d.getElementById('slider'); s.value = k; s.dispatchEvent(new Event('input')); }
  var shown = k >= 0 ? k : 0, lines = ['final ' + d.getElementById('final').getAttribute('src')];
  d.querySelectorAll('.plots svg').forEach(function (svg) {
    var m = svg.querySelector('.marker'), p = svg.querySelector('[data-run="' + shown + '"]');
    lines.push(svg.id + ' marker ' + m.getAttribute('cx') + ',' + m.getAttribute('cy') +
               ' point ' + (p ? p.getAttribute('cx') + ',' + p.getAttribute('cy') : 'none'));
  });
  var pre = document.createElement('pre'); pre.id = 'voxlab-check'; pre.textContent = lines.join('\\n');
  document.body.appendChild(pre);
});
</script></body>"""


def browse(k):
    check = os.path.join(out, f"sweep-lesson.check{k}.html")
    open(check, "w").write(text.replace("</body>", probe.replace("K", str(k))))
    dom = subprocess.run(["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                          f"--user-data-dir={out}/profile", "--allow-file-access-from-files",
                          "--virtual-time-budget=10000", "--dump-dom", f"file://{check}"],
                         capture_output=True, text=True, timeout=120).stdout
    m = re.search(r'<pre id="voxlab-check">([^<]*)</pre>', dom)
    return m.group(1).split("\n") if m else []


def final_of(lines):
    return next((l.split(" ", 1)[1] for l in lines if l.startswith("final ")), None)


moved = browse(2)
print("\n".join(moved))
if final_of(moved) != report["runs"][2]["final_image"]:
    problems.append(f"after the slider moved to 2 the frame shows {final_of(moved)}, "
                    f"want {report['runs'][2]['final_image']}")
markers = [l for l in moved if " marker " in l]
if len(markers) != len(report["plots"]):
    problems.append(f"{len(markers)} plots with a marker in the frame, want {len(report['plots'])}")
for line in markers:
    name, _, marker, _, point = line.split(" ")
    if marker != point:
        problems.append(f"{name}: marker at {marker}, run 2's point at {point}")
# Control: untouched, the frame shows run 0, another image, so the check above can fail.
first = browse(-1)
if final_of(first) != report["runs"][0]["final_image"] or final_of(first) == final_of(moved):
    problems.append(f"control: the untouched frame shows {final_of(first)}, want run 0's "
                    f"{report['runs'][0]['final_image']} (and not run 2's)")
for p in problems:
    print("FAIL " + p)
if problems:
    sys.exit(1)
print("the handout embeds the step's sweep page, and its slider works inside the handout")
