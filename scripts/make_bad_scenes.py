#!/usr/bin/env python3
"""Writes malformed glTF files for the loader's error tests into tests/data/bad/, one per defect
class (python3 standard library only, deterministic output). Each starts from the same valid
one-triangle file and breaks exactly one thing.

Usage: python3 scripts/make_bad_scenes.py [--root DIR]
"""

import argparse
import copy
import os
import struct
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_writer import GltfBuilder, write_json  # noqa: E402

TRIANGLE = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]]


def triangle_doc(positions=None, indices=(0, 1, 2), mode=4):
    """A valid glTF with one indexed triangle (u16 indices) and an embedded buffer."""
    b = GltfBuilder("voxlab scripts/make_bad_scenes.py")
    pos = [c for p in (positions or TRIANGLE) for c in p]
    mat = b.add_material("white", (0.8, 0.8, 0.8))
    pa = b.add_accessor(pos, "VEC3", 5126, len(pos) // 3)
    ia = b.add_accessor(list(indices), "SCALAR", 5123, len(indices))
    b.doc["meshes"].append({"name": "triangle", "primitives": [
        {"attributes": {"POSITION": pa}, "indices": ia, "material": mat, "mode": mode}]})
    b.add_node({"name": "triangle", "mesh": 0})
    return b.finish()


def write_bytes(path, data):
    with open(path, "wb") as f:
        f.write(data)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--root", default=os.path.dirname(here))
    args = parser.parse_args()
    out = os.path.join(args.root, "tests", "data", "bad")
    os.makedirs(out, exist_ok=True)

    files = {}

    # An external buffer file that is not there.
    doc = triangle_doc()
    doc["buffers"][0]["uri"] = "missing-buffer.bin"
    files["missing-buffer.gltf"] = doc

    # Index 7 in a primitive with 3 vertices.
    files["index-out-of-range.gltf"] = triangle_doc(indices=(0, 1, 7))

    # Non-finite positions (json cannot carry them; they live in the binary buffer).
    files["nan-position.gltf"] = triangle_doc(positions=[TRIANGLE[0], [float("nan"), 0.0, 0.0], TRIANGLE[2]])
    files["inf-position.gltf"] = triangle_doc(positions=[TRIANGLE[0], TRIANGLE[1], [0.0, float("inf"), -1.0]])

    # JSON of the wrong types: an accessor count given as a string.
    doc = triangle_doc()
    doc["accessors"][0]["count"] = "3"
    files["wrong-types.gltf"] = doc

    # Node 0 -> node 1 -> node 0.
    doc = triangle_doc()
    doc["nodes"] = [{"name": "a", "mesh": 0, "children": [1]}, {"name": "b", "children": [0]}]
    doc["scenes"][0]["nodes"] = [0]
    files["node-cycle.gltf"] = doc

    # A required extension voxlab cannot decode.
    doc = triangle_doc()
    doc["extensionsUsed"] = ["KHR_draco_mesh_compression"]
    doc["extensionsRequired"] = ["KHR_draco_mesh_compression"]
    files["unsupported-required-extension.gltf"] = doc

    # A glTF 1.0 file: objects keyed by id instead of arrays, version "1.0".
    files["gltf-1.0.gltf"] = {
        "asset": {"version": "1.0"},
        "scene": "defaultScene",
        "scenes": {"defaultScene": {"nodes": ["node0"]}},
        "nodes": {"node0": {"meshes": ["mesh0"]}},
        "meshes": {"mesh0": {"primitives": [{"attributes": {"POSITION": "acc0"}, "mode": 4}]}},
        "accessors": {"acc0": {"bufferView": "view0", "byteOffset": 0, "componentType": 5126,
                               "count": 3, "type": "VEC3"}},
        "bufferViews": {"view0": {"buffer": "buf0", "byteOffset": 0, "byteLength": 36}},
        "buffers": {"buf0": {"uri": "data:application/octet-stream;base64,"
                                    "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAAAAAAIC/", "byteLength": 36}},
    }

    # Only a LINES primitive: nothing to render.
    files["no-triangles.gltf"] = triangle_doc(indices=(0, 1, 1, 2), mode=1)

    # An accessor that claims more elements than its buffer view holds.
    doc = triangle_doc()
    doc["accessors"][0]["count"] = 1000
    files["accessor-out-of-range.gltf"] = doc

    # Base-colour textures: a file that is not there, and one stb cannot decode.
    def textured(uri):
        doc = triangle_doc()
        doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
        doc["textures"] = [{"source": 0}]
        doc["images"] = [{"uri": uri}]
        return doc
    files["missing-texture.gltf"] = textured("missing-texture.png")
    files["corrupt-texture.gltf"] = textured("corrupt-texture.png")

    # An alphaMode that glTF does not define.
    doc = triangle_doc()
    doc["materials"][0]["alphaMode"] = "CUTOUT"
    files["bad-alpha-mode.gltf"] = doc

    for name, doc in files.items():
        write_json(os.path.join(out, name), doc)
    # Not an image in any format stb_image reads.
    write_bytes(os.path.join(out, "corrupt-texture.png"), b"\x89PNG\r\n\x1a\n but then nothing of a PNG follows")

    # Garbage and an empty file.
    write_bytes(os.path.join(out, "not-json.gltf"),
                b"this is not JSON {{ \"asset\": \n\x00\x01\xff garbage\n" + struct.pack("<4I", 1, 2, 3, 4))
    write_bytes(os.path.join(out, "empty-file.gltf"), b"")

    for name in sorted(list(files) + ["not-json.gltf", "empty-file.gltf"]):
        print("wrote", os.path.relpath(os.path.join(out, name), args.root))


if __name__ == "__main__":
    main()
