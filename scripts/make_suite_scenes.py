#!/usr/bin/env python3
"""Writes the fidelity suite's own scenes (python3 standard library only, deterministic output).

The fidelity suite (`voxlab fidelity`, docs/fidelity.md) is cornell-box, sponza and the scenes
below: the classic cases of the global-illumination literature that one or two tuned scenes
cannot cover. Each is written to scenes/<name>.gltf; scenes/suite.json lists the whole suite
(name, interior or exterior, what the scene tests) and scenes/README.md says it in prose. Both
are generated here from SUITE, so the list and its descriptions live in one place.

Lights: voxlab's techniques shadow the scene's first light with its shadow map (ShadowMapStage;
a point light's is six cube faces). The point-lit scene of the suite (corridor) is a convex room
of single-sided walls in which the light sees every surface: it measures range, not shadows.

Walls of the closed rooms are solid slabs 20 cm thick (six faces each), as real walls are:
a wall of zero thickness has its lit outside and its dark inside in the same voxels, which no
voxel technique can separate. The one thin wall of the suite (two-rooms) is 4 cm, under one
voxel at the default resolution, on purpose.

Usage: python3 scripts/make_suite_scenes.py [--root DIR]
"""

import argparse
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_writer import GltfBuilder, axis_box_polygons, normalize, oriented, sub, write_json  # noqa: E402

WHITE = (0.75, 0.75, 0.72)
WARM_FLOOR = (0.6, 0.45, 0.3)
GREY = (0.5, 0.5, 0.5)
BLUE = (0.2, 0.35, 0.7)
RED = (0.7, 0.12, 0.08)
GREEN = (0.15, 0.5, 0.12)
ORANGE = (0.8, 0.4, 0.15)
SLAB = 0.2  # wall, floor and ceiling thickness of the closed rooms (metres)


def look_rotation(eye, target):
    """Quaternion (x, y, z, w) turning a node's -Z to look from eye at target, +Y kept up."""
    f = normalize(sub(target, eye))
    # Yaw about +y, then pitch about the node's +x: -Z -> f.
    yaw = math.atan2(-f[0], -f[2])
    pitch = math.asin(max(-1.0, min(1.0, f[1])))
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    # q = q_yaw(y) * q_pitch(x)
    return (round(cy * sp, 6), round(sy * cp, 6), round(-sy * sp, 6), round(cy * cp, 6))


def sun_rotation(azimuth_deg, elevation_deg):
    """Rotation of a directional light node whose -Z travels along scene/scene.h's sunDirection:
    -(cos(el) sin(az), sin(el), cos(el) cos(az))."""
    az, el = math.radians(azimuth_deg), math.radians(elevation_deg)
    d = (-math.cos(el) * math.sin(az), -math.sin(el), -math.cos(el) * math.cos(az))
    return look_rotation((0.0, 0.0, 0.0), d)


def slab(lo, hi, k=1.0):
    return axis_box_polygons([c * k for c in lo], [c * k for c in hi])


def closed_room(b, size, materials, k=1.0, skip=()):
    """Floor, ceiling and four walls around the interior [0, size] as solid slabs SLAB thick.
    materials: dict with floor, ceiling, north (z = 0), south, west (x = 0), east. skip: names
    of slabs the caller builds itself (a ceiling with a hole)."""
    x, y, z = size
    t = SLAB
    parts = {
        "floor": ([-t, -t, -t], [x + t, 0.0, z + t]),
        "ceiling": ([-t, y, -t], [x + t, y + t, z + t]),
        "west": ([-t, 0.0, 0.0], [0.0, y, z]),
        "east": ([x, 0.0, 0.0], [x + t, y, z]),
        "north": ([-t, 0.0, -t], [x + t, y, 0.0]),
        "south": ([-t, 0.0, z], [x + t, y, z + t]),
    }
    for name, (lo, hi) in parts.items():
        if name in skip:
            continue
        b.add_mesh_node(name, materials[name], slab(lo, hi, k))


def skylight_room(path):
    """A closed 4 x 3 x 4 m room lit only by the sun through a 1.2 m square opening in its
    ceiling: a bright patch on the floor near the east wall, everything else indirect."""
    b = GltfBuilder("voxlab scripts/make_suite_scenes.py (skylight room)")
    white = b.add_material("white", WHITE)
    floor = b.add_material("floor", WARM_FLOOR)
    blue = b.add_material("blue-wall", BLUE)
    mats = {"floor": floor, "ceiling": white, "west": white, "east": white, "north": white, "south": blue}
    closed_room(b, (4.0, 3.0, 4.0), mats, skip=("ceiling",))
    t, y = SLAB, 3.0
    hole = (1.4, 2.6, 1.4, 2.6)  # x0, x1, z0, z1
    pieces = [
        ([-t, y, -t], [hole[0], y + t, 4.0 + t]),
        ([hole[1], y, -t], [4.0 + t, y + t, 4.0 + t]),
        ([hole[0], y, -t], [hole[1], y + t, hole[2]]),
        ([hole[0], y, hole[3]], [hole[1], y + t, 4.0 + t]),
    ]
    b.add_mesh_node("ceiling", white, [p for lo, hi in pieces for p in slab(lo, hi)])
    b.add_light("sun", {"type": "directional", "color": [1.0, 0.95, 0.85], "intensity": 20.0},
                (2.0, 6.0, 2.0), sun_rotation(240.0, 65.0))
    eye, target = (0.35, 1.6, 0.35), (3.0, 0.7, 3.0)
    b.add_camera("camera", eye, look_rotation(eye, target), 1.1, aspect=1.0, znear=0.01, zfar=30.0)
    b.write(path)


def two_rooms(path):
    """Two 3 x 2.5 x 3 m rooms side by side, joined by a 0.9 m door gap in a 4 cm wall. A spot
    light under room A's ceiling; the camera stands in room B, which gets light only through the
    door (a little directly, on its floor) and what leaks through the thin wall."""
    b = GltfBuilder("voxlab scripts/make_suite_scenes.py (two rooms)")
    white = b.add_material("white", WHITE)
    floor = b.add_material("floor", GREY)
    green = b.add_material("green-wall", GREEN)
    divider = b.add_material("divider", WHITE)
    mats = {"floor": floor, "ceiling": white, "west": green, "east": white, "north": white, "south": white}
    closed_room(b, (6.04, 2.5, 3.0), mats)
    x0, x1 = 3.0, 3.04
    door = (1.0, 1.9, 2.0)  # z0, z1, height
    pieces = [
        ([x0, 0.0, 0.0], [x1, 2.5, door[0]]),
        ([x0, 0.0, door[1]], [x1, 2.5, 3.0]),
        ([x0, door[2], door[0]], [x1, 2.5, door[1]]),
    ]
    b.add_mesh_node("divider", divider, [p for lo, hi in pieces for p in slab(lo, hi)])
    b.add_light("room-a-spot", {"type": "spot", "color": [1.0, 0.9, 0.75], "intensity": 60.0,
                                "spot": {"innerConeAngle": 0.8, "outerConeAngle": 1.05}},
                (1.5, 2.45, 1.5), look_rotation((0, 0, 0), (0.0, -1.0, 0.0001)))
    eye, target = (5.75, 1.6, 2.75), (3.0, 0.9, 1.3)
    b.add_camera("camera", eye, look_rotation(eye, target), 1.1, aspect=1.0, znear=0.01, zfar=30.0)
    b.write(path)


def open_courtyard(path):
    """A white 8 x 8 m floor with red, green and blue walls on three sides and a white block,
    open to the sky above and to the south: a sun and a constant sky (scene extras
    sky_radiance), the exterior case where most light arrives directly."""
    b = GltfBuilder("voxlab scripts/make_suite_scenes.py (open courtyard)")
    white = b.add_material("white", WHITE)
    red = b.add_material("red-wall", RED)
    green = b.add_material("green-wall", GREEN)
    blue = b.add_material("blue-wall", BLUE)
    b.add_mesh_node("floor", white, [oriented([[-4.0, 0.0, -4.0], [4.0, 0.0, -4.0], [4.0, 0.0, 4.0],
                                               [-4.0, 0.0, 4.0]], [0.0, 1.0, 0.0])])
    b.add_mesh_node("west-wall", red, slab([-3.4, 0.0, -3.0], [-3.2, 2.5, 3.0]))
    b.add_mesh_node("north-wall", green, slab([-3.4, 0.0, -3.4], [3.4, 2.5, -3.2]))
    b.add_mesh_node("east-wall", blue, slab([3.2, 0.0, -3.0], [3.4, 2.5, 3.0]))
    b.add_mesh_node("block", white, slab([-0.6, 0.0, -1.2], [0.6, 1.2, 0.0]))
    b.add_light("sun", {"type": "directional", "color": [1.0, 0.95, 0.85], "intensity": 3.0},
                (0.0, 8.0, 0.0), sun_rotation(150.0, 45.0))
    eye, target = (0.5, 2.6, 6.0), (0.0, 0.6, -1.0)
    b.add_camera("camera", eye, look_rotation(eye, target), 1.0, aspect=1.0, znear=0.01, zfar=60.0)
    b.doc["scenes"][0]["extras"] = {"sky_radiance": 0.3}
    b.write(path)


def uv_sphere(centre, radius, rings=16, segments=32):
    points = [(centre[0], centre[1] + radius, centre[2])]
    for i in range(1, rings):
        theta = math.pi * i / rings
        for j in range(segments):
            phi = 2.0 * math.pi * j / segments
            points.append((centre[0] + radius * math.sin(theta) * math.cos(phi), centre[1] + radius * math.cos(theta),
                           centre[2] + radius * math.sin(theta) * math.sin(phi)))
    points.append((centre[0], centre[1] - radius, centre[2]))
    last = len(points) - 1
    tris = []
    for j in range(segments):  # outward winding (counter-clockwise seen from outside)
        tris.append((0, 1 + (j + 1) % segments, 1 + j))
    for i in range(rings - 2):
        for j in range(segments):
            a, c = 1 + i * segments + j, 1 + i * segments + (j + 1) % segments
            tris += [(a, c, a + segments), (c, c + segments, a + segments)]
    base = 1 + (rings - 2) * segments
    for j in range(segments):
        tris.append((last, base + j, base + (j + 1) % segments))
    return points, tris


def cylinder(centre_xz, radius, height, segments=32):
    points = []
    for y in (0.0, height):
        for j in range(segments):
            phi = 2.0 * math.pi * j / segments
            points.append((centre_xz[0] + radius * math.cos(phi), y, centre_xz[1] + radius * math.sin(phi)))
    points.append((centre_xz[0], height, centre_xz[1]))
    top = len(points) - 1
    tris = []
    for j in range(segments):
        a, c = j, (j + 1) % segments
        tris += [(a, a + segments, c), (c, a + segments, c + segments), (top, c + segments, a + segments)]
    return points, tris


def spheres_room(path, k=1.0):
    """A closed 3 x 2.5 x 3 m room with three spheres and a column on its floor under a spot
    light: voxelized curves, contact shadows and ambient occlusion. k scales every length
    (100: the same room in centimetres) and the spot's intensity by k^2, so the picture is the
    same (I / d^2)."""
    b = GltfBuilder("voxlab scripts/make_suite_scenes.py (spheres room%s)" % ("" if k == 1.0 else ", x%g" % k))
    white = b.add_material("white", WHITE)
    floor = b.add_material("floor", GREY)
    red = b.add_material("red-wall", RED)
    mats = {"floor": floor, "ceiling": white, "west": red, "east": white, "north": white, "south": white}
    closed_room(b, (3.0, 2.5, 3.0), mats, k=k)
    objects = [
        ("sphere-large", b.add_material("sphere-large", (0.8, 0.8, 0.8)), uv_sphere((2.0, 0.55, 2.0), 0.55)),
        ("sphere-medium", b.add_material("sphere-medium", (0.75, 0.6, 0.3)), uv_sphere((0.9, 0.35, 1.9), 0.35)),
        ("sphere-small", b.add_material("sphere-small", (0.3, 0.5, 0.75)), uv_sphere((1.9, 0.2, 0.9), 0.2)),
        ("column", b.add_material("column", (0.75, 0.75, 0.72)), cylinder((0.7, 0.8), 0.18, 1.8)),
    ]
    for name, mat, (points, tris) in objects:
        scaled = [tuple(c * k for c in p) for p in points]
        b.add_node({"name": name, "mesh": b.add_indexed_mesh(name, mat, scaled, tris)})
    b.add_light("ceiling-spot", {"type": "spot", "color": [1.0, 0.9, 0.75], "intensity": 40.0 * k * k,
                                 "spot": {"innerConeAngle": 0.7, "outerConeAngle": 1.0}},
                (1.6 * k, 2.45 * k, 1.5 * k), look_rotation((0, 0, 0), (0.0, -1.0, 0.0001)))
    eye, target = (1.5 * k, 1.7 * k, -0.0 * k + 0.15 * k), (1.5 * k, 0.5 * k, 1.8 * k)
    b.add_camera("camera", eye, look_rotation(eye, target), 1.1, aspect=1.0, znear=0.01 * k, zfar=30.0 * k)
    b.write(path)


def corridor(path):
    """A closed corridor 1.6 m wide, 2.4 m high and 12 m long, lit by a point light near its
    orange end wall; the camera looks down it from the far end. Light must travel 12 m. The
    walls are single surfaces facing in (a convex room: the point light sees every surface)."""
    b = GltfBuilder("voxlab scripts/make_suite_scenes.py (corridor)")
    white = b.add_material("white", WHITE)
    floor = b.add_material("floor", GREY)
    orange = b.add_material("end-wall", ORANGE)
    x, y, z = 1.6, 2.4, 12.0
    faces = axis_box_polygons([0.0, 0.0, 0.0], [x, y, z], faces_outward=False)
    # axis_box_polygons order: -x, +x, -y (floor), +y (ceiling), -z (end wall), +z
    b.add_mesh_node("walls", white, [faces[0], faces[1], faces[3], faces[5]])
    b.add_mesh_node("floor", floor, [faces[2]])
    b.add_mesh_node("end-wall", orange, [faces[4]])
    b.add_light("end-lamp", {"type": "point", "color": [1.0, 0.9, 0.75], "intensity": 20.0}, (0.8, 1.9, 0.6))
    eye, target = (0.8, 1.5, 11.7), (0.8, 1.1, 0.0)
    b.add_camera("camera", eye, look_rotation(eye, target), 0.9, aspect=1.0, znear=0.01, zfar=40.0)
    b.write(path)


# The suite: every scene `voxlab fidelity` runs by default, in this order. interior: a closed
# (or nearly closed) building whose indirect light matters most; the energy bands of the
# technique issues hold there. Scenes without a generator here come with their own script.
SUITE = [
    ("cornell-box", True, None, "the Cornell box from its published measurements, a spot under the ceiling: "
     "colour bleeding, two boxes, the scene most defaults were first tuned on (scripts/make_scenes.py)"),
    ("sponza", True, None, "Crytek Sponza, a sun through the open roof: 262k triangles, alpha-masked leaves, "
     "textures, a large building lit from above (scripts/make_sponza.py)"),
    ("skylight-room", True, skylight_room, "a closed room lit only by the sun through an opening in its ceiling: "
     "indirect-dominant, the case where missing indirect energy shows most"),
    ("two-rooms", True, two_rooms, "two rooms joined by a door gap in a 4 cm wall, the spot in the room the camera "
     "does not see: occlusion and light leaking through a wall thinner than a voxel"),
    ("corridor", True, corridor, "a 12 m corridor lit by a point light at its far end: how far indirect light "
     "travels (range)"),
    ("spheres-room", True, spheres_room, "three spheres and a column in a closed room under a spot: voxelized curves, "
     "contact shadows, ambient occlusion"),
    ("spheres-room-cm", True, lambda p: spheres_room(p, 100.0), "spheres-room with every length in centimetres: "
     "every number should equal spheres-room's (no absolute lengths)"),
    ("open-courtyard", False, open_courtyard, "coloured walls around a white floor under a sun and a constant sky "
     "(scene extras sky_radiance 0.3): the exterior case, most light direct"),
]

# The animated scenes (scripts/make_motion_scenes.py writes them from the still ones): `voxlab
# run --frames N` plays their glTF animation over 'duration' seconds; 'frames' is how many frames
# the temporal runs take. They are not in the still-image suite above.
ANIMATED = [
    ("cornell-box-moving", True, 16, 2.0, "the Cornell box with a 10 cm box flying above the tall block and "
     "turning: a moving object (re-voxelized every frame), its shadow and bounce moving with it"),
    ("sponza-sun-sweep", True, 16, 2.0, "Crytek Sponza with its sun turning 60 degrees in azimuth: a light move "
     "(geometry still), shadows sweeping across the courtyard"),
]


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--root", default=os.path.dirname(here), help="project root (default: this repo)")
    args = parser.parse_args()
    scenes = os.path.join(args.root, "scenes")
    os.makedirs(scenes, exist_ok=True)
    for name, _, make, _ in SUITE:
        if make is not None:
            make(os.path.join(scenes, name + ".gltf"))
            print("wrote", os.path.join("scenes", name + ".gltf"))
    write_json(os.path.join(scenes, "suite.json"), {
        "_comment": "The fidelity suite, written by scripts/make_suite_scenes.py: the scenes `voxlab fidelity` runs "
                    "by default. interior: the technique energy bands hold there (docs/fidelity.md).",
        "scenes": [{"name": n, "interior": i, "tests": t} for n, i, _, t in SUITE],
        "animated": [{"name": n, "interior": i, "frames": f, "duration": d, "tests": t}
                     for n, i, f, d, t in ANIMATED]})
    lines = ["# Scenes", "",
             "Every glTF/GLB file here (or folder `<name>/<name>.gltf`) is a scene: `voxlab list` names them, "
             "`--scene NAME` loads one. The fidelity suite (`voxlab fidelity`, docs/fidelity.md) is listed in "
             "suite.json; this file and that one are written by scripts/make_suite_scenes.py.", "",
             "| scene | class | what it tests |", "|---|---|---|"]
    for name, interior, _, tests in SUITE:
        lines.append("| `%s` | %s | %s |" % (name, "interior" if interior else "exterior", tests))
    lines += ["", "Animated scenes (suite.json's `animated`: frames and duration in seconds; `voxlab run --frames N` "
              "plays them), written by scripts/make_motion_scenes.py:", "",
              "| scene | frames | duration | what it tests |", "|---|---|---|---|"]
    for name, _, frames, duration, tests in ANIMATED:
        lines.append("| `%s` | %d | %g s | %s |" % (name, frames, duration, tests))
    with open(os.path.join(scenes, "README.md"), "w", encoding="utf-8", newline="\n") as f:
        f.write("\n".join(lines) + "\n")
    print("wrote scenes/suite.json, scenes/README.md")


if __name__ == "__main__":
    main()
