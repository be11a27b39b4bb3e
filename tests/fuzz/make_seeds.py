#!/usr/bin/env python3
"""Writes the seed corpus of the scene-loader fuzzer (tests/fuzz/fuzz_scene_loader.cpp) into OUT:
every .gltf of scenes/, tests/data/ (malformed CLI files and fuzz regressions included) as it is
and minified, each one that embeds its buffer also as GLB (JSON chunk + BIN chunk), and one small
scene with an embedded PNG base colour texture so image decoding is reached.

usage: make_seeds.py ROOT OUT
"""
import base64
import json
import pathlib
import struct
import sys
import zlib


def glb(doc, binary):
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    binary += b"\0" * (-len(binary) % 4)
    chunks = struct.pack("<II", len(text), 0x4E4F534A) + text
    if binary:
        chunks += struct.pack("<II", len(binary), 0x004E4942) + binary
    return struct.pack("<III", 0x46546C67, 2, 12 + len(chunks)) + chunks


def as_glb(doc):
    """The document with buffer 0's data URI moved into the BIN chunk, or None."""
    buffers = doc.get("buffers") if isinstance(doc, dict) else None
    if not isinstance(buffers, list) or not buffers or not isinstance(buffers[0], dict):
        return None
    uri = buffers[0].get("uri", "")
    if not isinstance(uri, str) or not uri.startswith("data:") or ";base64," not in uri:
        return None
    data = base64.b64decode(uri.split(";base64,", 1)[1])
    doc = json.loads(json.dumps(doc))
    del doc["buffers"][0]["uri"]
    return glb(doc, data)


def png(width, height, rgba):
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    rows = b"".join(b"\0" + rgba[y * width * 4:(y + 1) * width * 4] for y in range(height))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def textured_quad():
    positions = struct.pack("<12f", 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0)
    uvs = struct.pack("<8f", 0, 1, 1, 1, 1, 0, 0, 0)
    indices = struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    data = positions + uvs + indices
    image = png(2, 2, bytes([255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 128]))
    return {
        "asset": {"version": "2.0"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0}],
        "images": [{"uri": "data:image/png;base64," + base64.b64encode(image).decode()}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                        {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                        {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
        "buffers": [{"byteLength": len(data),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
    }


def main():
    root, out = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    sources = sorted(list((root / "scenes").glob("*.gl*")) + list((root / "tests" / "data").rglob("*.gl*")))
    written = 0
    for src in sources:
        raw = src.read_bytes()
        name = src.relative_to(root).as_posix().replace("/", "_")
        (out / name).write_bytes(raw)
        written += 1
        try:
            doc = json.loads(raw)
        except (ValueError, RecursionError):
            continue
        (out / (name + ".min")).write_text(json.dumps(doc, separators=(",", ":")))
        written += 1
        binary = as_glb(doc)
        if binary:
            (out / (name + ".glb")).write_bytes(binary)
            written += 1
    quad = textured_quad()
    (out / "textured-quad.gltf").write_text(json.dumps(quad, separators=(",", ":")))
    (out / "textured-quad.glb").write_bytes(as_glb(quad))
    print(f"{written + 2} seeds in {out}")


if __name__ == "__main__":
    main()
