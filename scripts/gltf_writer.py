"""Minimal deterministic glTF 2.0 writer (python3 standard library only).

Used by scripts/make_scenes.py and scripts/make_bad_scenes.py. Geometry is given as quads or
triangles with flat normals; everything goes into one buffer embedded as a base64 data: URI, so
each .gltf is a single self-contained file. Output is byte-for-byte reproducible.
"""

import base64
import json
import math
import struct


def sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def add(a, b):
    return [a[0] + b[0], a[1] + b[1], a[2] + b[2]]


def scale(a, s):
    return [a[0] * s, a[1] * s, a[2] * s]


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def normalize(a):
    n = math.sqrt(dot(a, a))
    return [a[0] / n, a[1] / n, a[2] / n]


def centroid(points):
    s = [0.0, 0.0, 0.0]
    for p in points:
        s = add(s, p)
    return scale(s, 1.0 / len(points))


def newell_normal(points):
    """Unit normal of a (possibly slightly non-planar) polygon, counter-clockwise = front."""
    n = [0.0, 0.0, 0.0]
    for i, p in enumerate(points):
        q = points[(i + 1) % len(points)]
        n[0] += (p[1] - q[1]) * (p[2] + q[2])
        n[1] += (p[2] - q[2]) * (p[0] + q[0])
        n[2] += (p[0] - q[0]) * (p[1] + q[1])
    return normalize(n)


def flat_shaded_arrays(polygons):
    """Flat-shaded vertex arrays of CCW-front polygons: flat positions and normals (3 floats per
    vertex, each polygon's own vertices with its Newell normal) and triangle-fan indices."""
    positions, normals, indices = [], [], []
    for poly in polygons:
        n = newell_normal(poly)
        base = len(positions) // 3
        for p in poly:
            positions.extend(float(c) for c in p)
            normals.extend(n)
        for k in range(1, len(poly) - 1):
            indices.extend([base, base + k, base + k + 1])
    return positions, normals, indices


def oriented(points, facing):
    """Returns the polygon wound so that its front (CCW) normal points along 'facing'."""
    if dot(newell_normal(points), facing) < 0.0:
        return list(reversed(points))
    return list(points)


def r6(x):
    """Rounds for stable JSON text (and avoids -0.0)."""
    v = round(float(x), 6)
    return 0.0 if v == 0.0 else v


class GltfBuilder:
    def __init__(self, generator="voxlab scripts/gltf_writer.py"):
        self.doc = {
            "asset": {"version": "2.0", "generator": generator},
            "scene": 0,
            "scenes": [{"name": "scene", "nodes": []}],
            "nodes": [],
            "meshes": [],
            "materials": [],
            "accessors": [],
            "bufferViews": [],
            "buffers": [],
        }
        self.data = bytearray()

    # --- raw data -----------------------------------------------------------------------------
    def _align(self):
        while len(self.data) % 4:
            self.data.append(0)

    def add_view(self, raw, target=None):
        self._align()
        view = {"buffer": 0, "byteOffset": len(self.data), "byteLength": len(raw)}
        if target is not None:
            view["target"] = target
        self.data.extend(raw)
        self.doc["bufferViews"].append(view)
        return len(self.doc["bufferViews"]) - 1

    def add_accessor(self, values, type_, component_type, count, with_bounds=False, target=None):
        fmt = {5121: "B", 5123: "H", 5125: "I", 5126: "f"}[component_type]
        raw = struct.pack("<%d%s" % (len(values), fmt), *values)
        view = self.add_view(raw, target)
        acc = {"bufferView": view, "componentType": component_type, "count": count, "type": type_}
        if with_bounds:
            n = {"VEC3": 3, "VEC2": 2, "SCALAR": 1}[type_]
            acc["min"] = [r6(min(values[i::n])) for i in range(n)]
            acc["max"] = [r6(max(values[i::n])) for i in range(n)]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    # --- materials, meshes, nodes --------------------------------------------------------------
    def add_material(self, name, albedo, emissive=(0.0, 0.0, 0.0)):
        mat = {
            "name": name,
            "pbrMetallicRoughness": {
                "baseColorFactor": [r6(albedo[0]), r6(albedo[1]), r6(albedo[2]), 1.0],
                "metallicFactor": 0.0,
                "roughnessFactor": 1.0,
            },
        }
        if any(e != 0.0 for e in emissive):
            mat["emissiveFactor"] = [r6(e) for e in emissive]
        self.doc["materials"].append(mat)
        return len(self.doc["materials"]) - 1

    def add_polygon_mesh(self, name, material, polygons):
        """polygons: list of CCW-front polygons (3 or 4 points), flat shaded."""
        positions, normals, indices = flat_shaded_arrays(polygons)
        vcount = len(positions) // 3
        pos = self.add_accessor(positions, "VEC3", 5126, vcount, with_bounds=True, target=34962)
        nrm = self.add_accessor(normals, "VEC3", 5126, vcount, target=34962)
        idx_type = 5123 if vcount < 65536 else 5125
        idx = self.add_accessor(indices, "SCALAR", idx_type, len(indices), target=34963)
        self.doc["meshes"].append({
            "name": name,
            "primitives": [{"attributes": {"POSITION": pos, "NORMAL": nrm}, "indices": idx,
                            "material": material, "mode": 4}],
        })
        return len(self.doc["meshes"]) - 1

    def add_indexed_mesh(self, name, material, positions, triangles):
        """positions: list of (x, y, z); triangles: list of (i, j, k) into positions, shared
        vertices, no NORMAL attribute (the loader computes normals)."""
        flat = [float(c) for p in positions for c in p]
        idx = [int(i) for t in triangles for i in t]
        vcount = len(positions)
        pos = self.add_accessor(flat, "VEC3", 5126, vcount, with_bounds=True, target=34962)
        idx_type = 5123 if vcount < 65536 else 5125
        ind = self.add_accessor(idx, "SCALAR", idx_type, len(idx), target=34963)
        self.doc["meshes"].append({
            "name": name,
            "primitives": [{"attributes": {"POSITION": pos}, "indices": ind, "material": material, "mode": 4}],
        })
        return len(self.doc["meshes"]) - 1

    def add_node(self, node, root=True):
        self.doc["nodes"].append(node)
        index = len(self.doc["nodes"]) - 1
        if root:
            self.doc["scenes"][0]["nodes"].append(index)
        return index

    def add_mesh_node(self, name, material, polygons):
        mesh = self.add_polygon_mesh(name, material, polygons)
        return self.add_node({"name": name, "mesh": mesh})

    def add_camera(self, name, position, rotation_xyzw, yfov, aspect=None, znear=0.01, zfar=100.0):
        cams = self.doc.setdefault("cameras", [])
        persp = {"yfov": r6(yfov), "znear": r6(znear), "zfar": r6(zfar)}
        if aspect is not None:
            persp["aspectRatio"] = r6(aspect)
        cams.append({"name": name, "type": "perspective", "perspective": persp})
        return self.add_node({"name": name, "camera": len(cams) - 1,
                              "translation": [r6(c) for c in position],
                              "rotation": [r6(c) for c in rotation_xyzw]})

    def add_light(self, name, light, position, rotation_xyzw=None):
        self.doc.setdefault("extensionsUsed", [])
        if "KHR_lights_punctual" not in self.doc["extensionsUsed"]:
            self.doc["extensionsUsed"].append("KHR_lights_punctual")
        ext = self.doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {"lights": []})
        light = dict(light)
        light["name"] = name
        ext["lights"].append(light)
        node = {"name": name, "translation": [r6(c) for c in position],
                "extensions": {"KHR_lights_punctual": {"light": len(ext["lights"]) - 1}}}
        if rotation_xyzw is not None:
            node["rotation"] = [r6(c) for c in rotation_xyzw]
        return self.add_node(node)

    # --- output --------------------------------------------------------------------------------
    def finish(self, external_bin=None):
        self._align()
        buf = {"byteLength": len(self.data)}
        if external_bin is None:
            buf["uri"] = "data:application/octet-stream;base64," + base64.b64encode(bytes(self.data)).decode("ascii")
        else:
            buf["uri"] = external_bin
        self.doc["buffers"] = [buf]
        for key in ("cameras",):
            if key in self.doc and not self.doc[key]:
                del self.doc[key]
        return self.doc

    def write(self, path, external_bin=None):
        doc = self.finish(external_bin)
        write_json(path, doc)


def write_json(path, doc):
    text = json.dumps(doc, indent=1, sort_keys=False, allow_nan=True) + "\n"
    with open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write(text)


def box_polygons(bottom, top_y, faces_outward=True, with_bottom=False, bottom_y=0.0):
    """Prism over the x,z quad 'bottom' from bottom_y to top_y: top + 4 sides (+ bottom)."""
    lo = [[p[0], bottom_y, p[1]] for p in bottom]
    hi = [[p[0], top_y, p[1]] for p in bottom]
    centre = centroid(lo + hi)
    polys = [hi]
    for i in range(4):
        j = (i + 1) % 4
        polys.append([lo[i], lo[j], hi[j], hi[i]])
    if with_bottom:
        polys.append(lo)
    out = []
    for poly in polys:
        facing = sub(centroid(poly), centre)
        if not faces_outward:
            facing = scale(facing, -1.0)
        out.append(oriented(poly, facing))
    return out


def axis_box_polygons(lo, hi, faces_outward=True):
    """Six faces of the axis-aligned box [lo, hi]."""
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    faces = [
        ([[x0, y0, z0], [x0, y0, z1], [x0, y1, z1], [x0, y1, z0]], [-1, 0, 0]),
        ([[x1, y0, z0], [x1, y1, z0], [x1, y1, z1], [x1, y0, z1]], [1, 0, 0]),
        ([[x0, y0, z0], [x1, y0, z0], [x1, y0, z1], [x0, y0, z1]], [0, -1, 0]),
        ([[x0, y1, z0], [x0, y1, z1], [x1, y1, z1], [x1, y1, z0]], [0, 1, 0]),
        ([[x0, y0, z0], [x0, y1, z0], [x1, y1, z0], [x1, y0, z0]], [0, 0, -1]),
        ([[x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]], [0, 0, 1]),
    ]
    out = []
    for poly, n in faces:
        facing = n if faces_outward else scale(n, -1.0)
        out.append(oriented(poly, facing))
    return out
