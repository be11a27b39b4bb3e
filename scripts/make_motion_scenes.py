#!/usr/bin/env python3
"""Writes the animated scenes of the suite from the still ones (python3 standard library only).

  scenes/cornell-box-moving.gltf  the Cornell box with a 10 cm box flying through it: it crosses
                                  above the tall block from left to right and back, turning about
                                  its vertical axis (translation LINEAR, rotation CUBICSPLINE), 2 s.
  scenes/sponza-sun-sweep.gltf    Crytek Sponza with its sun on an animated node: the sun turns
                                  60 degrees in azimuth about the vertical (rotation LINEAR), 2 s.
                                  It reuses scenes/sponza/ by reference (buffer and textures), so
                                  only the JSON is new.

Each file is the still scene's JSON plus one extra buffer (a base64 data: URI) holding the new
mesh and the animation's key times and values. Output is byte-for-byte reproducible:
  python3 scripts/make_motion_scenes.py
"""

import base64
import json
import math
import os
import struct

from gltf_writer import axis_box_polygons, flat_shaded_arrays, r6, write_json

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
SCENES = os.path.join(ROOT, "scenes")
DURATION = 2.0  # seconds, both scenes


class ExtraBuffer:
    """Appends views and accessors to an existing glTF document, in a new embedded buffer."""

    def __init__(self, doc):
        self.doc = doc
        self.index = len(doc["buffers"])
        self.data = bytearray()

    def accessor(self, values, type_, component_type=5126, target=None, with_bounds=False):
        while len(self.data) % 4:
            self.data.append(0)
        fmt = {5123: "H", 5126: "f"}[component_type]
        raw = struct.pack("<%d%s" % (len(values), fmt), *values)
        view = {"buffer": self.index, "byteOffset": len(self.data), "byteLength": len(raw)}
        if target is not None:
            view["target"] = target
        self.data.extend(raw)
        self.doc["bufferViews"].append(view)
        n = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[type_]
        acc = {"bufferView": len(self.doc["bufferViews"]) - 1, "componentType": component_type,
               "count": len(values) // n, "type": type_}
        if with_bounds:
            acc["min"] = [r6(min(values[i::n])) for i in range(n)]
            acc["max"] = [r6(max(values[i::n])) for i in range(n)]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def finish(self):
        while len(self.data) % 4:
            self.data.append(0)
        self.doc["buffers"].append({
            "byteLength": len(self.data),
            "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(self.data)).decode("ascii"),
        })


def quat_about_y(degrees):
    h = math.radians(degrees) / 2.0
    return [0.0, math.sin(h), 0.0, math.cos(h)]


def quat_multiply(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return [aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz]


def cornell_box_moving():
    with open(os.path.join(SCENES, "cornell-box.gltf"), encoding="utf-8") as f:
        doc = json.load(f)
    extra = ExtraBuffer(doc)
    # A 10 cm box centred on its node's origin, flat shaded, a light yellow diffuse material.
    h = 0.05
    polygons = axis_box_polygons([-h, -h, -h], [h, h, h])
    positions, normals, indices = flat_shaded_arrays(polygons)
    pos = extra.accessor(positions, "VEC3", target=34962, with_bounds=True)
    nrm = extra.accessor(normals, "VEC3", target=34962)
    idx = extra.accessor(indices, "SCALAR", 5123, target=34963)
    doc["materials"].append({"name": "moving-box", "pbrMetallicRoughness": {
        "baseColorFactor": [0.8, 0.75, 0.3, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}})
    doc["meshes"].append({"name": "moving-box", "primitives": [{
        "attributes": {"POSITION": pos, "NORMAL": nrm}, "indices": idx,
        "material": len(doc["materials"]) - 1, "mode": 4}]})
    # It flies above the tall block (0.33 m high) from the red wall's side to the green wall's
    # side and back, under the spot (0.538 m).
    start = [0.12, 0.40, 0.28]
    doc["nodes"].append({"name": "moving-box", "mesh": len(doc["meshes"]) - 1,
                         "translation": start, "rotation": [0.0, 0.0, 0.0, 1.0]})
    node = len(doc["nodes"]) - 1
    doc["scenes"][0]["nodes"].append(node)
    times = [0.0, 1.0, 2.0]
    translations = start + [0.44, 0.40, 0.28] + [0.28, 0.40, 0.28]
    # CUBICSPLINE rotation about +y: 0, 45, 90 degrees, each key with in- and out-tangents of
    # 45 degrees per second (the derivative of the quaternion of a steady turn).
    rate = math.radians(45.0) / 2.0  # d(half angle)/dt
    rotations = []
    for t in times:
        q = quat_about_y(45.0 * t)
        half = math.radians(45.0 * t) / 2.0
        tangent = [0.0, math.cos(half) * rate, 0.0, -math.sin(half) * rate]
        rotations += tangent + q + tangent
    time_acc = extra.accessor([float(t) for t in times], "SCALAR", with_bounds=True)
    doc["animations"] = [{
        "name": "box-flight",
        "samplers": [
            {"input": time_acc, "output": extra.accessor(translations, "VEC3"), "interpolation": "LINEAR"},
            {"input": time_acc, "output": extra.accessor([r6(v) for v in rotations], "VEC4"),
             "interpolation": "CUBICSPLINE"},
        ],
        "channels": [
            {"sampler": 0, "target": {"node": node, "path": "translation"}},
            {"sampler": 1, "target": {"node": node, "path": "rotation"}},
        ],
    }]
    extra.finish()
    write_json(os.path.join(SCENES, "cornell-box-moving.gltf"), doc)


def sponza_sun_sweep():
    with open(os.path.join(SCENES, "sponza", "sponza.gltf"), encoding="utf-8") as f:
        doc = json.load(f)
    # The buffer and textures stay in scenes/sponza/.
    for kind in ("buffers", "images"):
        for item in doc.get(kind, []):
            if "uri" in item and not item["uri"].startswith("data:"):
                item["uri"] = "sponza/" + item["uri"]
    extra = ExtraBuffer(doc)
    sun = next(i for i, n in enumerate(doc["nodes"]) if n.get("name") == "sun")
    rest = doc["nodes"][sun]["rotation"]
    # The sun turns about the vertical from 30 degrees one side of its rest azimuth to 30 the other
    # side (its elevation stays): five keys, spherical interpolation between them.
    times = [0.0, 0.5, 1.0, 1.5, 2.0]
    rotations = []
    for t in times:
        rotations += [r6(v) for v in quat_multiply(quat_about_y(-30.0 + 30.0 * t), rest)]
    doc["nodes"][sun]["rotation"] = rotations[0:4]
    doc["animations"] = [{
        "name": "sun-sweep",
        "samplers": [{"input": extra.accessor([float(t) for t in times], "SCALAR", with_bounds=True),
                      "output": extra.accessor(rotations, "VEC4"), "interpolation": "LINEAR"}],
        "channels": [{"sampler": 0, "target": {"node": sun, "path": "rotation"}}],
    }]
    extra.finish()
    write_json(os.path.join(SCENES, "sponza-sun-sweep.gltf"), doc)


if __name__ == "__main__":
    cornell_box_moving()
    sponza_sun_sweep()
