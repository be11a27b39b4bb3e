#!/usr/bin/python3
"""Writes scenes/sponza/ (Crytek Sponza for voxlab) from the shared glTF copy.

  scenes/sponza/sponza.gltf    the source's JSON with: a root node scaling centimetres to metres,
                               base-colour textures only (normal maps dropped: no renderer in
                               voxlab reads them), a KHR_lights_punctual directional sun and two
                               cameras (the first, the nave view, is the default)
  scenes/sponza/sponza.bin     the source's buffer, byte for byte
  scenes/sponza/textures/      base-colour textures reduced to at most MAX_TEXTURE px a side
                               (Lanczos): JPEG for opaque materials, PNG (RGBA) for MASK ones

Usage: /usr/bin/python3 scripts/make_sponza.py [--source /work/shared/scenes/sponza] [--root DIR]
Needs python3-pil (scripts/setup.sh installs it). Deterministic for a given Pillow version.
"""

import argparse
import json
import math
import os
import shutil
import sys

try:
    from PIL import Image
except ImportError:  # pragma: no cover - reported as one line
    sys.exit("make_sponza.py: needs Pillow (Debian package python3-pil; scripts/setup.sh installs it)")

MAX_TEXTURE = 1024        # longest side of a reduced texture, px
JPEG_QUALITY = 90
CM_TO_M = 0.01            # the source is in centimetres (Khronos Sponza units)

# The sun: a directional light through the open roof onto the floor and the lower gallery on the
# -z side. Direction the light travels (unit after normalisation): mostly down, tilted towards -z
# and slightly along +x, so the columns cast shadows across the nave floor.
SUN_DIRECTION = (0.15, -1.0, -0.25)
SUN_COLOR = [1.0, 0.93, 0.82]
# Irradiance (W/m^2) on a surface facing the sun. The radiance voxels are RGBA8 in [0, 1]: a floor
# of albedo ~0.6 facing the sun reflects 0.6 / pi * E * cos, which stays below 1 for E = 5.
SUN_IRRADIANCE = 5.0

# Cameras (metres, after the root scale): name, position, point looked at, vertical fov (rad).
CAMERAS = [
    # The nave along the long (x) axis, from the +x end at eye height, looking towards the lion.
    ("nave", (11.0, 1.7, -0.4), (-10.0, 3.2, 0.0), 1.05),
    # The sunlit floor and the curtains of the -z gallery, from the +z side of the court.
    ("lit-floor-curtains", (4.0, 2.2, 1.6), (0.0, 0.6, -3.2), 1.05),
]


def normalize(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def quat_from_basis(right, up, back):
    """Quaternion (x, y, z, w) of the rotation whose matrix has columns right, up, back."""
    m = [[right[0], up[0], back[0]], [right[1], up[1], back[1]], [right[2], up[2], back[2]]]
    tr = m[0][0] + m[1][1] + m[2][2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        w, x, y, z = 0.25 * s, (m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s
    elif m[0][0] > m[1][1] and m[0][0] > m[2][2]:
        s = math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]) * 2
        w, x, y, z = (m[2][1] - m[1][2]) / s, 0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s
    elif m[1][1] > m[2][2]:
        s = math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]) * 2
        w, x, y, z = (m[0][2] - m[2][0]) / s, (m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s
    else:
        s = math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]) * 2
        w, x, y, z = (m[1][0] - m[0][1]) / s, (m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s
    return [round(c, 6) for c in (x, y, z, w)]


def look_rotation(forward, world_up=(0.0, 1.0, 0.0)):
    """Rotation turning the node's -Z into 'forward' with +Y as close to world_up as possible."""
    f = normalize(forward)
    if abs(f[1]) > 0.999:
        world_up = (0.0, 0.0, -1.0)
    right = normalize(cross(f, world_up))
    up = cross(right, f)
    return quat_from_basis(right, up, [-c for c in f])


def reduce_texture(src, dst_dir, stem, with_alpha):
    img = Image.open(src)
    img.load()
    scale = min(1.0, MAX_TEXTURE / max(img.size))
    size = (max(1, round(img.size[0] * scale)), max(1, round(img.size[1] * scale)))
    if with_alpha:
        img = img.convert("RGBA")
    else:
        img = img.convert("RGB")
    if size != img.size:
        img = img.resize(size, Image.LANCZOS)
    if with_alpha:
        name = stem + ".png"
        img.save(os.path.join(dst_dir, name), optimize=True)
        mime = "image/png"
    else:
        name = stem + ".jpg"
        img.save(os.path.join(dst_dir, name), quality=JPEG_QUALITY, optimize=True)
        mime = "image/jpeg"
    return name, mime, size


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--source", default=os.path.join(os.path.dirname(os.path.dirname(here)), "shared", "scenes", "sponza"),
                        help="folder with Sponza.gltf (default: ../shared/scenes/sponza beside the checkout)")
    parser.add_argument("--root", default=os.path.dirname(here), help="project root (default: this repo)")
    args = parser.parse_args()
    src_gltf = os.path.join(args.source, "Sponza.gltf")
    if not os.path.isfile(src_gltf):
        sys.exit("make_sponza.py: no Sponza.gltf in '%s' (pass --source DIR)" % args.source)
    with open(src_gltf) as f:
        doc = json.load(f)

    out = os.path.join(args.root, "scenes", "sponza")
    tex_dir = os.path.join(out, "textures")
    if os.path.isdir(tex_dir):
        shutil.rmtree(tex_dir)
    os.makedirs(tex_dir)

    # Base-colour textures only, each image reduced once; texture indices renumbered.
    masked_images = set()
    for m in doc["materials"]:
        bct = m.get("pbrMetallicRoughness", {}).get("baseColorTexture")
        m.pop("normalTexture", None)
        m.pop("extras", None)
        if bct is not None and m.get("alphaMode") == "MASK":
            masked_images.add(doc["textures"][bct["index"]]["source"])
    new_textures, new_images, texture_map, image_map = [], [], {}, {}
    report = []
    for m in doc["materials"]:
        pbr = m.get("pbrMetallicRoughness", {})
        bct = pbr.get("baseColorTexture")
        if bct is None:
            continue
        old = bct["index"]
        if old not in texture_map:
            tex = doc["textures"][old]
            src_image = tex["source"]
            if src_image not in image_map:
                image = doc["images"][src_image]
                stem = image.get("name") or os.path.splitext(os.path.basename(image["uri"]))[0]
                name, mime, size = reduce_texture(os.path.join(args.source, image["uri"]), tex_dir, stem,
                                                  src_image in masked_images)
                image_map[src_image] = len(new_images)
                new_images.append({"uri": "textures/" + name, "mimeType": mime, "name": stem})
                report.append("%s %dx%d" % (name, size[0], size[1]))
            texture_map[old] = len(new_textures)
            new_textures.append({"source": image_map[src_image], "sampler": tex.get("sampler", 0)})
        bct["index"] = texture_map[old]
    doc["textures"] = new_textures
    doc["images"] = new_images

    # Geometry: the same buffer; a root node turns centimetres into metres.
    shutil.copyfile(os.path.join(args.source, doc["buffers"][0]["uri"]), os.path.join(out, "sponza.bin"))
    doc["buffers"][0]["uri"] = "sponza.bin"
    nodes = doc["nodes"]
    root = len(nodes)
    nodes.append({"name": "sponza-metres", "scale": [CM_TO_M] * 3, "children": list(doc["scenes"][0]["nodes"])})
    scene_nodes = [root]

    # Cameras first in the scene's node list: the loader makes the first one the default.
    doc["cameras"] = []
    for name, pos, target, yfov in CAMERAS:
        forward = [t - p for t, p in zip(target, pos)]
        doc["cameras"].append({"name": name, "type": "perspective",
                               "perspective": {"yfov": yfov, "znear": 0.05, "zfar": 80.0, "aspectRatio": 1.0}})
        nodes.append({"name": name, "camera": len(doc["cameras"]) - 1, "translation": list(pos),
                      "rotation": look_rotation(forward)})
        scene_nodes.insert(len(scene_nodes) - 1, len(nodes) - 1)

    doc["extensionsUsed"] = ["KHR_lights_punctual"]
    doc["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"name": "sun", "type": "directional", "color": SUN_COLOR, "intensity": SUN_IRRADIANCE}]}}
    nodes.append({"name": "sun", "rotation": look_rotation(SUN_DIRECTION, (0.0, 0.0, -1.0)),
                  "extensions": {"KHR_lights_punctual": {"light": 0}}})
    scene_nodes.append(len(nodes) - 1)
    doc["scenes"][0]["nodes"] = scene_nodes
    doc["asset"]["generator"] = "voxlab scripts/make_sponza.py from " + doc["asset"].get("generator", "?")

    with open(os.path.join(out, "sponza.gltf"), "w") as f:
        json.dump(doc, f, indent=1, sort_keys=True)
        f.write("\n")
    total = sum(os.path.getsize(os.path.join(tex_dir, n)) for n in os.listdir(tex_dir))
    print("wrote scenes/sponza/sponza.gltf, sponza.bin and %d textures (%.1f MB):" % (len(new_images), total / 1e6))
    for line in report:
        print("  " + line)


if __name__ == "__main__":
    main()
