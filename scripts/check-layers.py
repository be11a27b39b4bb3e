#!/usr/bin/env python3
"""Checks that no file under src/ includes a file of a higher layer (docs/architecture.md#layers).

Every `#include "..."` in src/ is resolved against src/ (the include root), then against the
including file's own folder; includes that resolve under shaders/ (the structs and constants GLSL
shares with C++, which include nothing of src/) and system headers are not layered. A file's layer
is its first folder under src/, except that src/techniques/<technique>/views/ is the layer "views"
(a technique's visualisers, built on inspect/). Exits 1 naming each include that runs up, and each
src/ folder no layer names, so a new folder has to be placed in the order before it is used.

Usage: scripts/check-layers.py [project root]   (default: the checkout this script lies in)
"""
import os
import re
import sys

# Lowest first: a file may include files of its own layer and of the layers before it.
LAYERS = ["core", "gpu", "platform", "scene", "graph", "capture", "reference", "techniques", "run",
          "lesson", "inspect", "views", "handout", "app"]
RANK = {name: i for i, name in enumerate(LAYERS)}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def layer_of(rel):
    """The layer of a path relative to src/ ("techniques/lpv/views/x.cpp" -> "views")."""
    parts = rel.split("/")
    if len(parts) >= 4 and parts[0] == "techniques" and parts[2] == "views":
        return "views"
    return parts[0] if len(parts) > 1 else ""


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))
    src = os.path.join(root, "src")
    shaders = os.path.join(root, "shaders")
    problems = []
    checked = 0
    for folder in sorted(os.listdir(src)):
        if os.path.isdir(os.path.join(src, folder)) and folder not in RANK:
            problems.append(f"src/{folder}/: a folder no layer names (add it to LAYERS here and to "
                            "docs/architecture.md#layers)")
    for dirpath, _, files in os.walk(src):
        for name in sorted(files):
            if not name.endswith((".h", ".cpp")):
                continue
            path = os.path.join(dirpath, name)
            rel = os.path.relpath(path, src).replace(os.sep, "/")
            own = layer_of(rel)
            with open(path, encoding="utf-8", errors="replace") as f:
                for number, line in enumerate(f, 1):
                    m = INCLUDE.match(line)
                    if not m:
                        continue
                    target = m.group(1)
                    if os.path.isfile(os.path.join(src, target)):
                        target_rel = os.path.normpath(target).replace(os.sep, "/")
                    elif os.path.isfile(os.path.join(dirpath, target)):
                        target_rel = os.path.relpath(os.path.join(dirpath, target), src).replace(os.sep, "/")
                    elif os.path.isfile(os.path.join(shaders, target)):
                        continue
                    else:
                        continue  # not a project file (a package's header found through -I)
                    checked += 1
                    theirs = layer_of(target_rel)
                    if own in RANK and theirs in RANK and RANK[theirs] > RANK[own]:
                        problems.append(f"src/{rel}:{number}: includes {target_rel}: layer {own} includes the "
                                        f"higher layer {theirs}")
    for p in problems:
        print(p)
    if problems:
        print(f"check-layers: {len(problems)} problem(s); the order, lowest first: {' < '.join(LAYERS)}")
        return 1
    print(f"check-layers: {checked} includes in src/, none runs up ({' < '.join(LAYERS)})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
