#!/usr/bin/env python3
"""A sweep of every technique `voxlab list --json` names, at reduced size, and sweep.json's structure.

Per technique the script picks one parameter from the declarations alone: the first int parameter
(in stage order, not a power of two, not one this script sets) whose range holds its default and a
neighbour, swept over those two values; else the first boolean, swept over false and true. The
runs are 64x64 with voxel.resolution=32 where the technique declares it. sweep.json must hold one
run per value, none failed, each with the values, per-stage CPU times, their total, the GPU bytes
and the final image (on disk); and where the technique has outputs that declare a reference mode,
the compared outputs with energy ratio, RMSE and SSIM and a finite error, and the three plots.
Usage: every_technique.py VOXLAB ROOT OUT
"""
import json, os, re, shutil, subprocess, sys

exe, root, out = sys.argv[1:4]
shutil.rmtree(out, ignore_errors=True)
os.makedirs(out)
listing = json.loads(subprocess.run([exe, "list", "--json"], check=True, capture_output=True, text=True).stdout)
SET = {"voxel.resolution": "32"}


def pick(technique):
    params = [p for s in technique["stages"] for p in s.get("parameters", []) if p["name"] not in SET]
    for p in params:
        m = re.fullmatch(r"(-?\d+)\.\.(-?\d+)", p["range"])
        if p["type"] == "int" and m:
            lo, hi, default = int(m.group(1)), int(m.group(2)), int(p["default"])
            if hi > lo:
                other = default - 1 if default > lo else default + 1
                return p["name"], [str(min(default, other)), str(max(default, other))]
    for p in params:
        if p["type"] == "bool":
            return p["name"], ["false", "true"]
    return None, None


problems = []
for t in listing["techniques"]:
    tid = t["id"]
    name, values = pick(t)
    if name is None:
        problems.append(f"{tid}: no int or bool parameter to sweep")
        continue
    declared = {p["name"] for s in t["stages"] for p in s.get("parameters", [])}
    compared = any("reference_mode" in o for s in t["stages"] for o in s.get("outputs", []))
    folder = os.path.join(out, tid)
    cmd = [exe, "sweep", "--technique", tid, "--scene", "cornell-box", "--size", "64x64",
           "--param", f"{name}={','.join(values)}", "--out", folder]
    for k, v in SET.items():
        if k in declared:
            cmd += ["--set", f"{k}={v}"]
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        problems.append(f"{tid}: {' '.join(cmd[1:])} exited {run.returncode}: {run.stderr.strip()}")
        continue
    report = json.load(open(os.path.join(folder, "sweep.json")))
    where = f"{tid} ({name}={','.join(values)})"
    if report["technique"] != tid or [p["name"] for p in report["parameters"]] != [name]:
        problems.append(f"{where}: technique or parameters wrong in sweep.json")
    if report["parameters"][0]["values"] != values:
        problems.append(f"{where}: values {report['parameters'][0]['values']}")
    if len(report["runs"]) != len(values):
        problems.append(f"{where}: {len(report['runs'])} runs, want {len(values)}")
    for i, r in enumerate(report["runs"]):
        if "failed" in r:
            problems.append(f"{where}: run {i} failed: {r['failed']}")
            continue
        if r["index"] != i or r["values"] != {name: values[i]}:
            problems.append(f"{where}: run {i} has index {r['index']}, values {r['values']}")
        stages = {s["id"] for s in t["stages"]}
        if {s["id"] for s in r["stages"]} != stages or any(s["cpu_ms"] < 0 for s in r["stages"]):
            problems.append(f"{where}: run {i} stages {[s['id'] for s in r['stages']]}")
        if abs(sum(s["cpu_ms"] for s in r["stages"]) - r["total_cpu_ms"]) > 1e-6 * max(1.0, r["total_cpu_ms"]):
            problems.append(f"{where}: run {i} total_cpu_ms is not the sum of the stages'")
        if not r["resource_bytes"] > 0:
            problems.append(f"{where}: run {i} resource_bytes {r['resource_bytes']}")
        if not os.path.getsize(os.path.join(folder, r["final_image"])):
            problems.append(f"{where}: run {i} final image {r['final_image']} is empty")
        if compared:
            measured = [o for o in r["outputs"] if "ssim" in o]
            if not measured or any(not all(k in o for k in ("mean_ratio", "rmse", "ssim", "image")) for o in measured):
                problems.append(f"{where}: run {i} compared outputs {r['outputs']}")
            if not isinstance(r.get("error"), float) or not 0 <= r["error"] <= 2:
                problems.append(f"{where}: run {i} error {r.get('error')}")
    if compared and report["error"]["output"] == "none":
        problems.append(f"{where}: no main compared output")
    for plot in report["plots"]:
        points = open(os.path.join(folder, plot)).read().count('class="point"')
        if points < (len(values) if compared or plot.startswith("time") else 0):
            problems.append(f"{where}: {plot} has {points} points")
    print(f"ok {where}: {len(report['runs'])} runs, error of {report['error']['output']}")

for p in problems:
    print("FAIL", p)
sys.exit(1 if problems else 0)
