#!/usr/bin/env python3
"""sweep.html in headless Chromium: the slider swaps the image and moves the plots' markers.

A sweep of vct-grid's cone.aperture over three values (64x64, voxel.resolution=32), then:
- the page opened at "#run=2" (the page reads the address) must show run 2: the final image's src
  is run 2's final_image in sweep.json and every plot's marker sits on that plot's point of run 2;
- a copy with a script appended that, after the load event, sets the slider to 1 and dispatches
  an input event (what dragging it does) must then show run 1 the same way;
- control: run 0 and run 2 differ in image and in at least one marker position, so a page whose
  slider does nothing fails the checks.
--dump-dom prints the DOM after the scripts ran. Exit 77 (skip) only when chromium is missing.
Usage: browser_check.py VOXLAB ROOT OUT
"""
import html.parser, json, os, shutil, subprocess, sys

exe, root, out = sys.argv[1:4]
if not shutil.which("chromium"):
    print("chromium is not installed (scripts/setup.sh installs it): skipping")
    sys.exit(77)
shutil.rmtree(out, ignore_errors=True)
os.makedirs(out)
sweep = os.path.join(out, "sweep")
subprocess.run([exe, "sweep", "--technique", "vct-grid", "--scene", "cornell-box", "--size", "64x64",
                "--set", "voxel.resolution=32", "--param", "cone.aperture=30,45,60", "--out", sweep], check=True)
report = json.load(open(os.path.join(sweep, "sweep.json")))


class Page(html.parser.HTMLParser):
    """The shown image, and per plot (svg id) its marker's position and every point's by run."""

    def __init__(self):
        super().__init__()
        self.final, self.svg, self.markers, self.points, self.label = None, None, {}, {}, None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "img" and a.get("id") == "final":
            self.final = a.get("src")
        elif tag == "svg":
            self.svg = a.get("id")
        elif tag == "circle" and a.get("class") == "marker":
            self.markers[self.svg] = (a["cx"], a["cy"])
        elif tag == "circle" and "data-run" in a:
            self.points.setdefault(self.svg, {})[int(a["data-run"])] = (a["cx"], a["cy"])


def browse(page, fragment=""):
    dom = subprocess.run(["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                          f"--user-data-dir={out}/profile", "--allow-file-access-from-files",
                          "--virtual-time-budget=10000", "--dump-dom", f"file://{page}{fragment}"],
                         capture_output=True, text=True, timeout=120).stdout
    p = Page()
    p.feed(dom)
    return p


def shows(p, k, what):
    run = report["runs"][k]
    problems = []
    if p.final != run["final_image"]:
        problems.append(f"image {p.final}, want {run['final_image']}")
    if len(p.markers) != len(report["plots"]):
        problems.append(f"{len(p.markers)} markers for {len(report['plots'])} plots")
    for svg, marker in p.markers.items():
        if p.points.get(svg, {}).get(k) != marker:
            problems.append(f"{svg}: marker at {marker}, run {k}'s point at {p.points.get(svg, {}).get(k)}")
    print(("FAIL " if problems else "ok ") + f"{what} shows run {k}" + (": " + "; ".join(problems) if problems else ""))
    return not problems


page = os.path.join(sweep, "sweep.html")
ok = shows(browse(page, "#run=2"), 2, "#run=2")
check = os.path.join(sweep, "sweep.check.html")
hook = ("<script>window.addEventListener('load', function () { var s = document.getElementById('slider');"
        " s.value = 1; s.dispatchEvent(new Event('input')); });</script></body>")
open(check, "w").write(open(page).read().replace("</body>", hook))
ok = shows(browse(check), 1, "the slider moved to 1") and ok

# Control: the checks can tell runs apart.
first = browse(page)
moved = [svg for svg in first.points if first.points[svg].get(0) != first.points[svg].get(2)]
if report["runs"][0]["final_image"] == report["runs"][2]["final_image"] or not moved:
    print("FAIL control: runs 0 and 2 have the same image or the same points on every plot")
    ok = False
else:
    ok = shows(first, 0, "control: no fragment") and ok
sys.exit(0 if ok else 1)
