#!/usr/bin/env python3
"""Writes voxlab's scenes (python3 standard library only, deterministic output).

  scenes/cornell-box.gltf                the Cornell box from the published measurements (in metres)
  tests/data/scenes/cornell-box-x100.gltf  the Cornell box with every length x100 (scale invariance)
  tests/data/scenes/no-light-blocks.gltf floor and two blocks, no light, no camera (default sun)
  tests/data/scenes/no-light-blocks-x1_128.gltf  the same with every length x1/128 (scale invariance)
  tests/data/scenes/furnace-box.gltf     closed cube room seen from inside (white-furnace tests)
  tests/data/scenes/wall-floor.gltf      a floor and one tall wall (ambient-occlusion tests)
  tests/data/scenes/floor-ceiling.gltf   a floor under a parallel ceiling 0.3 m above it (AO test A2)
  tests/data/scenes/corner.gltf          a floor and two tall walls meeting in a corner (AO test A4)
  tests/data/scenes/thin-wall.gltf       a 1 cm wall splitting a closed room (light-leak tests)
  tests/data/scenes/thin-wall-spot.gltf  the same lit by a spot light (lrsm's leak test)
  tests/data/scenes/cornell-box-panel-only.gltf  the Cornell box lit only by its emissive panel
  tests/data/scenes/leak-rooms.gltf      the same two rooms, a spot light in one, the camera in the
                                         other (vct-grid's leak through a one-voxel wall)
  tests/data/scenes/dense-sheet.gltf     18432 sub-voxel triangles on a 2-triangle floor (voxelization sweep)
  tests/data/scenes/huge-triangles.gltf  4 huge triangles at odd angles (voxelization sweep)
  tests/data/scenes/voxel-ties-R.gltf    (R = 64, 128, 256) geometry exactly on voxel faces, edges
                                         and corners of the R^3 volume, 45-degree planes (dominant-axis
                                         ties), small and sliver triangles (voxelization exactness)
  tests/data/scenes/boundary-quad.gltf   a 1 x 1 m quad in the middle of its volume: at 64^3 its
                                         plane falls on a voxel boundary up to float rounding
  tests/data/scenes/long-hall.gltf       strongly non-cubic bounds (4 x 0.5 x 1 m) with tilted,
                                         small and sliver triangles
  tests/data/scenes/furnace-colour.gltf  the furnace box with albedo (0.8, 0.5, 0.2) (one answer per channel)
  tests/data/scenes/lid-floor.gltf       a floor under a small lid, open around (cone weighting test)
  tests/data/scenes/textured-floor.gltf  a floor with a 2 x 2 texture (red, green, blue, grey 128)
                                         under a point light, seen from above (texture paths)
  tests/data/scenes/sunlit-floor.gltf    a floor under a sun shining straight down (volumetric tests)
  tests/data/scenes/sunlit-floor-bright.gltf  the same with a sun 2.5 times as bright
  tests/data/scenes/sunlit-floor-fine.gltf    the same floor as 4608 triangles (several per voxel)
  tests/data/scenes/sunlit-slope.gltf         a 2 x 2 m floor tilted 30 degrees under the same sun
  tests/data/scenes/half-roof.gltf       the floor with a roof over its -x half (volumetric shadow tests)

Usage: python3 scripts/make_scenes.py [--root DIR] [--furnace-albedo 0.5]

scenes/sponza/ (Crytek Sponza) comes from the shared source files instead: scripts/make_sponza.py.
"""

import argparse
import base64
import math
import os
import struct
import sys
import zlib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_writer import (GltfBuilder, axis_box_polygons, box_polygons, centroid, oriented,  # noqa: E402
                         sub)

MM = 0.001  # the published data is in millimetres

WHITE = (0.725, 0.71, 0.68)
RED = (0.63, 0.065, 0.05)
GREEN = (0.14, 0.45, 0.091)

# Quaternions (x, y, z, w) that turn a node's -Z (camera view / light direction) elsewhere.
LOOK_PLUS_Z = (0.0, 1.0, 0.0, 0.0)                            # 180 deg about +y: -Z -> +Z
LOOK_DOWN = (-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5))       # -90 deg about +x: -Z -> -Y


def mm(points):
    return [[c * MM for c in p] for p in points]


def cornell_box(path, scale=1.0, spot=True):
    """The Cornell box; 'scale' multiplies every length (positions, the camera's clip range) and
    the spot light's radiant intensity by scale^2, so irradiance I / d^2 (and the picture) is the
    same: 100 gives the box in centimetres-as-metres (scale-invariance test). spot=False gives
    the spot light intensity 0, so the emissive panel is the only light (a scene without lights
    would get a default sun)."""
    def k(x):
        return x if scale == 1.0 else x * scale

    b = GltfBuilder("voxlab scripts/make_scenes.py (Cornell box, published measurements)"
                    + ("" if scale == 1.0 else " scaled by %g" % scale))
    ceiling_y = 548.8 * MM
    room_centre = [k(0.278), k(0.2744), k(0.2796)]

    def mmk(points):
        return [[k(c) for c in p] for p in mm(points)]

    def wall(name, albedo, points_mm):
        pts = mmk(points_mm)
        poly = oriented(pts, sub(room_centre, centroid(pts)))  # faces into the room
        b.add_mesh_node(name, b.add_material(name, albedo), [poly])

    wall("floor", WHITE, [(552.8, 0, 0), (0, 0, 0), (0, 0, 559.2), (549.6, 0, 559.2)])
    wall("ceiling", WHITE, [(556, 548.8, 0), (556, 548.8, 559.2), (0, 548.8, 559.2), (0, 548.8, 0)])
    wall("back-wall", WHITE, [(549.6, 0, 559.2), (0, 0, 559.2), (0, 548.8, 559.2), (556, 548.8, 559.2)])
    wall("left-wall-red", RED, [(552.8, 0, 0), (549.6, 0, 559.2), (556, 548.8, 559.2), (556, 548.8, 0)])
    wall("right-wall-green", GREEN, [(0, 0, 559.2), (0, 0, 0), (0, 548.8, 0), (0, 548.8, 559.2)])

    short_top = [(130, 65), (82, 225), (240, 272), (290, 114)]
    tall_top = [(423, 247), (265, 296), (314, 456), (472, 406)]
    b.add_mesh_node("short-block", b.add_material("short-block", WHITE),
                    box_polygons([(k(x * MM), k(z * MM)) for x, z in short_top], k(165 * MM)))
    b.add_mesh_node("tall-block", b.add_material("tall-block", WHITE),
                    box_polygons([(k(x * MM), k(z * MM)) for x, z in tall_top], k(330 * MM)))

    # Small emissive panel 1 mm below the ceiling, facing down. Emission is kept at 1 because it
    # feeds an 8-bit radiance grid; the spot light below carries the actual lighting.
    y = ceiling_y - 0.001
    panel = [[0.213, y, 0.227], [0.343, y, 0.227], [0.343, y, 0.332], [0.213, y, 0.332]]
    b.add_mesh_node("light-panel", b.add_material("light-panel", WHITE, emissive=(1.0, 1.0, 1.0)),
                    [oriented([[k(c) for c in p] for p in panel], [0.0, -1.0, 0.0])])

    # Spot light 1 cm under the ceiling at the panel centre, pointing straight down. Intensity is
    # radiant intensity (W/sr): irradiance on the floor below is I / d^2 = 3 W/m^2 (times colour).
    light_pos = (0.278, round(ceiling_y - 0.0108, 4), 0.2795)  # (0.278, 0.538, 0.2795)
    d = light_pos[1]
    intensity = round(3.0 * d * d, 4)  # 0.8683 W/sr
    b.add_light("ceiling-spot", {
        "type": "spot", "color": [1.0, 0.85, 0.65], "intensity": k(k(intensity)) if spot else 0.0,
        "spot": {"innerConeAngle": 0.6, "outerConeAngle": 1.3},
    }, tuple(k(c) for c in light_pos), LOOK_DOWN)

    # The published camera: (278, 273, -800) mm looking +z, 35 mm lens on 25 mm film.
    yfov = 2.0 * math.atan(0.025 / 2.0 / 0.035)  # 0.6860 rad = 39.3 deg
    b.add_camera("camera", (k(0.278), k(0.273), k(-0.8)), LOOK_PLUS_Z, round(yfov, 4), aspect=1.0,
                 znear=k(0.01), zfar=k(10.0))
    b.write(path)


def no_light_blocks(path, scale=1.0):
    """A 2 x 2 m floor with two grey blocks and nothing else: no light, no camera, so the loader
    adds its default sun and framing camera (the scene a new user's own glTF file often is).
    'scale' multiplies every length (1/128: the same blocks 1.6 cm wide, for the scale-invariance
    test of the default sun, its orthographic shadow map and the framing camera; a power of two
    scales every float exactly, so any difference is a length in absolute units, not rounding)."""
    b = GltfBuilder("voxlab scripts/make_scenes.py (no light, no camera)"
                    + ("" if scale == 1.0 else " scaled by %g" % scale))
    grey = b.add_material("grey", (0.6, 0.6, 0.6))
    red = b.add_material("red", (0.7, 0.15, 0.1))
    floor = [[-scale, 0.0, -scale], [scale, 0.0, -scale], [scale, 0.0, scale], [-scale, 0.0, scale]]
    b.add_mesh_node("floor", grey, [oriented(floor, [0.0, 1.0, 0.0])])
    b.add_mesh_node("tall-block", red, box_polygons([(x * scale, z * scale) for x, z in
                                                     [(-0.6, -0.4), (-0.2, -0.4), (-0.2, 0.0), (-0.6, 0.0)]], 0.8 * scale))
    b.add_mesh_node("low-block", grey, box_polygons([(x * scale, z * scale) for x, z in
                                                    [(0.2, 0.1), (0.6, 0.1), (0.6, 0.5), (0.2, 0.5)]], 0.3 * scale))
    b.write(path)


def furnace_box(path, albedo):
    """Closed unit cube [-0.5, 0.5]^3 with inward faces, uniform albedo (a number or an RGB
    triple), no emission, no lights."""
    b = GltfBuilder("voxlab scripts/make_scenes.py (white furnace box)")
    rgb = tuple(albedo) if isinstance(albedo, tuple) else (albedo, albedo, albedo)
    mat = b.add_material("furnace-white", rgb)
    b.add_mesh_node("furnace-room", mat, axis_box_polygons([-0.5, -0.5, -0.5], [0.5, 0.5, 0.5],
                                                           faces_outward=False))
    b.add_camera("camera", (0.0, 0.0, 0.3), (0.0, 0.0, 0.0, 1.0), 1.2, aspect=1.0, znear=0.01, zfar=10.0)
    b.write(path)


def wall_floor(path):
    """Floor 2 x 2 m at y = 0 (facing +y) and a wall x -1..1, 2 m tall, at z = 0.1 facing the
    origin (-z). At the origin V = 1/2 (1 + d / sqrt(d^2 + h^2)) for an infinitely long wall,
    d = 0.1, h = 2 (the wall here is 2 m wide, so that formula is an approximation)."""
    b = GltfBuilder("voxlab scripts/make_scenes.py (wall and floor)")
    grey = b.add_material("grey", (0.5, 0.5, 0.5))
    floor = [[-1.0, 0.0, -1.0], [1.0, 0.0, -1.0], [1.0, 0.0, 1.0], [-1.0, 0.0, 1.0]]
    b.add_mesh_node("floor", grey, [oriented(floor, [0.0, 1.0, 0.0])])
    wall = [[-1.0, 0.0, 0.1], [1.0, 0.0, 0.1], [1.0, 2.0, 0.1], [-1.0, 2.0, 0.1]]
    b.add_mesh_node("wall", grey, [oriented(wall, [0.0, 0.0, -1.0])])
    # Looking at the wall from the open side, slightly from above.
    b.add_camera("camera", (0.0, 1.0, -3.0), LOOK_PLUS_Z, 0.9, aspect=1.0, znear=0.01, zfar=20.0)
    b.write(path)


def floor_ceiling(path):
    """Floor 2 x 2 m at y = 0 (facing up) under a ceiling of the same size at y = 0.3 (facing down),
    open at the sides. With binary visibility within a range R the cosine-weighted visible fraction
    at the floor's centre is (h / R)^2 for R small against the plates (the technical note's A2)."""
    b = GltfBuilder("voxlab scripts/make_scenes.py (floor under a ceiling)")
    grey = b.add_material("grey", (0.5, 0.5, 0.5))
    b.add_mesh_node("floor", grey, [oriented([[-1.0, 0.0, -1.0], [1.0, 0.0, -1.0], [1.0, 0.0, 1.0], [-1.0, 0.0, 1.0]],
                                             [0.0, 1.0, 0.0])])
    b.add_mesh_node("ceiling", grey, [oriented([[-1.0, 0.3, -1.0], [1.0, 0.3, -1.0], [1.0, 0.3, 1.0], [-1.0, 0.3, 1.0]],
                                               [0.0, -1.0, 0.0])])
    b.add_camera("camera", (0.0, 0.25, 0.0), LOOK_DOWN, 1.4, aspect=1.0, znear=0.01, zfar=10.0)
    b.write(path)


def corner(path):
    """Floor 2 x 2 m at y = 0 (facing up), a wall at z = 1 (facing -z) and one at x = 1 (facing -x),
    both 2 m tall, meeting in the corner (1, y, 1). At the corner itself the visible fraction is 1/4
    for an unlimited range (the technical note's A4); the camera looks down at the floor by the corner."""
    b = GltfBuilder("voxlab scripts/make_scenes.py (corner of two walls)")
    grey = b.add_material("grey", (0.5, 0.5, 0.5))
    b.add_mesh_node("floor", grey, [oriented([[-1.0, 0.0, -1.0], [1.0, 0.0, -1.0], [1.0, 0.0, 1.0], [-1.0, 0.0, 1.0]],
                                             [0.0, 1.0, 0.0])])
    b.add_mesh_node("wall-z", grey, [oriented([[-1.0, 0.0, 1.0], [1.0, 0.0, 1.0], [1.0, 2.0, 1.0], [-1.0, 2.0, 1.0]],
                                              [0.0, 0.0, -1.0])])
    b.add_mesh_node("wall-x", grey, [oriented([[1.0, 0.0, -1.0], [1.0, 0.0, 1.0], [1.0, 2.0, 1.0], [1.0, 2.0, -1.0]],
                                              [-1.0, 0.0, 0.0])])
    b.add_camera("camera", (0.6, 1.0, 0.6), LOOK_DOWN, 1.0, aspect=1.0, znear=0.01, zfar=10.0)
    b.write(path)


def thin_wall(path, spot=False):
    """Closed room x -1..1, y 0..1, z -0.5..0.5 (inward faces) split at x = 0 by a 1 cm thick wall
    (closed box, outward faces). A point light sits in the left (-x) half only; any light in the
    right half that did not bounce around the wall is a leak. The wall seals the halves, so the
    right half's true radiance is exactly 0. spot: a spot light under the left half's ceiling
    pointing down instead (1 W/sr, outer cone 60 degrees), for techniques that need a light's map
    (RSM, shadow map: lrsm's thin-wall leak)."""
    b = GltfBuilder("voxlab scripts/make_scenes.py (thin wall%s)" % (", spot" if spot else ""))
    room = b.add_material("room-white", (0.7, 0.7, 0.7))
    wall = b.add_material("thin-wall", (0.7, 0.7, 0.7))
    b.add_mesh_node("room", room, axis_box_polygons([-1.0, 0.0, -0.5], [1.0, 1.0, 0.5], faces_outward=False))
    b.add_mesh_node("thin-wall", wall, axis_box_polygons([-0.005, 0.0, -0.5], [0.005, 1.0, 0.5]))
    if spot:
        b.add_light("left-spot", {"type": "spot", "color": [1.0, 1.0, 1.0], "intensity": 1.0,
                                  "spot": {"innerConeAngle": 0.8, "outerConeAngle": 1.0472}},
                    (-0.5, 0.95, 0.0), LOOK_DOWN)
    else:
        b.add_light("left-point", {"type": "point", "color": [1.0, 1.0, 1.0], "intensity": 1.0},
                    (-0.5, 0.5, 0.0))
    # Inside the room near the -z wall, looking +z at the divider.
    b.add_camera("camera", (0.0, 0.5, -0.45), LOOK_PLUS_Z, 1.4, aspect=1.0, znear=0.01, zfar=10.0)
    b.write(path)


def leak_rooms(path):
    """Two closed rooms sharing a 1 cm wall (the room x -1..1, y 0..1, z -0.5..0.5 split at x = 0, as
    thin-wall, about one voxel at 128^3): a shadow-mapped spot light in the left room shines down
    at its floor; the camera stands in the right room, which no light can reach (the reference's
    answer there is 0), looking at the wall. Whatever the right room shows leaked through it."""
    b = GltfBuilder("voxlab scripts/make_scenes.py (leak rooms)")
    room = b.add_material("room-white", (0.7, 0.7, 0.7))
    wall = b.add_material("shared-wall", (0.7, 0.7, 0.7))
    b.add_mesh_node("room", room, axis_box_polygons([-1.0, 0.0, -0.5], [1.0, 1.0, 0.5], faces_outward=False))
    b.add_mesh_node("shared-wall", wall, axis_box_polygons([-0.005, 0.0, -0.5], [0.005, 1.0, 0.5]))
    b.add_light("left-spot", {"type": "spot", "color": [1.0, 1.0, 1.0], "intensity": 1.0,
                              "spot": {"innerConeAngle": 0.5, "outerConeAngle": 0.7}},
                (-0.5, 0.95, 0.0), LOOK_DOWN)
    # In the right room near its far (+x) wall, looking -x at the shared wall.
    b.add_camera("camera", (0.95, 0.5, 0.0), (0.0, math.sqrt(0.5), 0.0, math.sqrt(0.5)), 1.4, aspect=1.0,
                 znear=0.01, zfar=10.0)
    b.write(path)


def dense_sheet(path):
    """A 1 m wavy sheet of 2 * 96^2 triangles above a floor of two large triangles: at 64^3 each
    sheet triangle is ~0.2 voxel^2, the floor triangles ~2000 voxel^2 (both hybrid classes).
    Same surface as denseScene() in tests/unit/test_voxelization.cpp (float rounding aside)."""
    b = GltfBuilder("voxlab scripts/make_scenes.py (dense sheet)")
    grey = b.add_material("grey", (0.7, 0.7, 0.7))
    n = 96
    points, tris = [], []
    for j in range(n + 1):
        for i in range(n + 1):
            x, z = i / n, j / n
            points.append((x, 0.3 + 0.12 * math.sin(7.0 * x + 1.0) * math.cos(5.0 * z) + 0.2 * x * z, z))
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            c = a + n + 1
            tris += [(a, c, a + 1), (a + 1, c, c + 1)]
    f = len(points)
    points += [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (1.0, 0.0, 1.0), (0.0, 0.0, 1.0)]
    tris += [(f, f + 3, f + 1), (f + 1, f + 3, f + 2)]
    b.add_node({"name": "dense-sheet", "mesh": b.add_indexed_mesh("dense-sheet", grey, points, tris)})
    b.write(path)


def huge_triangles(path):
    """Four triangles at odd angles, each crossing most of the unit volume (hugeScene() in
    tests/unit/test_voxelization.cpp)."""
    b = GltfBuilder("voxlab scripts/make_scenes.py (huge triangles)")
    grey = b.add_material("grey", (0.7, 0.7, 0.7))
    points = [(0.0, 0.05, 0.0), (1.0, 0.31, 0.07), (0.13, 0.97, 0.93),
              (1.0, 0.0, 1.0), (0.02, 0.11, 0.8), (0.77, 1.0, 0.05),
              (0.5, 0.0, 0.0), (0.0, 1.0, 0.4), (1.0, 0.6, 1.0),
              (0.9, 0.9, 0.1), (0.1, 0.2, 0.3), (0.6, 0.1, 0.95)]
    tris = [(0, 1, 2), (3, 4, 5), (6, 7, 8), (9, 10, 11)]
    b.add_node({"name": "huge-triangles", "mesh": b.add_indexed_mesh("huge-triangles", grey, points, tris)})
    b.write(path)


def voxel_ties(path, res):
    """Geometry placed exactly on the voxel grid of a res^3 volume. The scene's bounds are
    [0, (res-1)/res]^3 (two marker triangles in opposite corners), so VoxelSpace::fromScene gives
    voxels of exactly 1/res m and voxel coordinate v = res * p + 0.5 for a position p, without
    rounding (every value below is a small dyadic fraction, exact in float32). The pattern is
    designed at 64^3 and scaled by res / 64, so every tie stays a tie at every resolution:
    axis-aligned quads whose planes and edges lie on voxel faces (one per axis), one whose edges
    lie on voxel centres, 45-degree triangles (normals (1,1,0), (0,1,1), (1,0,1): dominant-axis
    ties, planes through voxel edges) and (1,1,1) (through voxel corners), small triangles with
    vertices on voxel corners, edges and faces, and slivers along and across voxel edges."""
    b = GltfBuilder("voxlab scripts/make_scenes.py (voxel ties at %d^3)" % res)
    grey = b.add_material("grey", (0.7, 0.7, 0.7))
    s = res // 64

    def p(v):  # voxel coordinates (at 64^3) -> metres in the res^3 volume
        return tuple((c * s - 0.5) / res for c in v)

    points, tris = [], []

    def tri(a, c, d, scaled=True):
        base = len(points)
        for v in (a, c, d):
            points.append(p(v) if scaled else v)
        tris.append((base, base + 1, base + 2))

    def quad(a, c, d, e):
        tri(a, c, d)
        tri(a, d, e)

    e = (res - 1) / res
    # Bounds markers: the volume's minimum and maximum corners, off the grid's faces.
    tri((0.0, 0.0, 0.0), (2.0 / res, 0.0, 0.0), (0.0, 0.0, 2.0 / res), scaled=False)
    tri((e, e, e), (e, e, e - 2.0 / res), (e - 2.0 / res, e, e), scaled=False)
    # Axis-aligned quads on voxel faces: plane and all four edges on cell boundaries.
    quad((8, 8, 20), (24, 8, 20), (24, 24, 20), (8, 24, 20))      # z = 20
    quad((40, 8, 8), (40, 24, 8), (40, 24, 24), (40, 8, 24))      # x = 40
    quad((8, 44, 30), (8, 44, 46), (24, 44, 46), (24, 44, 30))    # y = 44
    # Plane on a voxel face, edges through cell centres.
    quad((44.5, 40.5, 52), (60.5, 40.5, 52), (60.5, 56.5, 52), (44.5, 56.5, 52))
    # 45-degree planes: x + y = 70, y + z = 60, x + z = 84; and x + y + z = 120.
    tri((30, 40, 40), (50, 20, 40), (40, 30, 56))
    tri((30, 24, 36), (46, 36, 24), (30, 40, 20))
    tri((48, 48, 36), (56, 56, 28), (60, 44, 24))
    tri((48, 36, 36), (36, 48, 36), (36, 36, 48))
    # Small triangles (< 1 voxel^2) with vertices on a corner, an edge and a face of the grid.
    tri((10, 52, 10), (10.5, 52, 10), (10, 52.5, 10.25))
    tri((12, 54.25, 12), (12.75, 54, 12), (12, 54.5, 12.5))
    tri((14.25, 56, 14.5), (14.5, 56.5, 14), (14, 56.75, 14.75))
    # Slivers: along a voxel edge line, across cells at a shallow angle, and a needle on a corner.
    tri((4, 30, 4), (28, 30, 4), (4, 30.0625, 4.0625))
    tri((4.25, 34.25, 6), (28.75, 35.5, 6.5), (4.25, 34.3125, 6))
    tri((30, 4, 50), (30.03125, 4, 62), (30, 4.03125, 62))
    b.add_node({"name": "voxel-ties", "mesh": b.add_indexed_mesh("voxel-ties", grey, points, tris)})
    b.write(path)


def boundary_quad(path):
    """A 1 x 1 m quad at z = 0 facing +z, and two small triangles at z = -0.5 and z = 0.5 that
    put it in the middle of the volume: at 64^3 its plane lies on the boundary between voxel
    layers 31 and 32 (up to the float rounding of the volume's placement). Half-open cells give
    one layer: 64 x 64 = 4096 voxels of the quad."""
    b = GltfBuilder("voxlab scripts/make_scenes.py (quad on a voxel boundary)")
    grey = b.add_material("grey", (0.7, 0.7, 0.7))
    b.add_mesh_node("quad", grey, [oriented([[-0.5, -0.5, 0.0], [0.5, -0.5, 0.0], [0.5, 0.5, 0.0],
                                             [-0.5, 0.5, 0.0]], [0.0, 0.0, 1.0])])
    b.add_mesh_node("markers", grey, [[[0.0, 0.0, -0.5], [0.01, 0.0, -0.5], [0.0, 0.01, -0.5]],
                                      [[0.0, 0.0, 0.5], [0.0, 0.01, 0.5], [0.01, 0.0, 0.5]]])
    b.write(path)


def long_hall(path):
    """Strongly non-cubic bounds, 4 x 0.5 x 1 m: a floor and a tilted roof, a leaning board,
    small triangles and slivers. The volume is a cube around the longest axis, so the short axes
    use only an eighth and a quarter of it."""
    b = GltfBuilder("voxlab scripts/make_scenes.py (long hall)")
    grey = b.add_material("grey", (0.6, 0.6, 0.6))
    polys = [
        oriented([[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [4.0, 0.0, 1.0], [0.0, 0.0, 1.0]], [0.0, 1.0, 0.0]),
        oriented([[0.0, 0.45, 0.0], [4.0, 0.5, 0.0], [4.0, 0.38, 1.0], [0.0, 0.41, 1.0]], [0.0, -1.0, 0.0]),
        [[1.1, 0.02, 0.13], [2.9, 0.31, 0.27], [1.3, 0.4, 0.91]],
    ]
    for i in range(12):  # small triangles at odd positions, ~ 2 x 1 cm
        x, y, z = 0.17 + 0.31 * i, 0.1 + 0.023 * i, 0.07 + 0.071 * i
        polys.append([[x, y, z], [x + 0.021, y + 0.004, z + 0.003], [x + 0.005, y + 0.011, z + 0.013]])
    for i in range(4):  # slivers 1 m long, 1 mm wide
        x, z = 0.3 + 0.8 * i, 0.2 + 0.17 * i
        polys.append([[x, 0.05, z], [x + 1.0, 0.2 + 0.03 * i, z + 0.3], [x, 0.051, z + 0.001]])
    b.add_mesh_node("long-hall", grey, polys)
    b.write(path)


def png_rgb(width, height, pixels):
    """A PNG (8-bit RGB, no filter) of rows of (r, g, b) tuples, top row first."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    raw = b"".join(b"\x00" + bytes(c for px in row for c in px) for row in pixels)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def lid_floor(path):
    """A 0.5 x 0.5 m floor at y = 0 (facing up) and a 0.4 x 0.4 m lid at y = 1 above its centre
    (facing down), nothing else: from the floor's centre the lid fills the sky within 11 degrees
    of the normal and everything else is open. With uniform injected radiance only cones towards the lid
    see light, so the answer depends on how the cones are weighted (cosine or equal)."""
    b = GltfBuilder("voxlab scripts/make_scenes.py (lid over a floor)")
    grey = b.add_material("grey", (0.5, 0.5, 0.5))
    b.add_mesh_node("floor", grey, [oriented([[-0.25, 0.0, -0.25], [0.25, 0.0, -0.25], [0.25, 0.0, 0.25], [-0.25, 0.0, 0.25]],
                                             [0.0, 1.0, 0.0])])
    b.add_mesh_node("lid", grey, [oriented([[-0.2, 1.0, -0.2], [0.2, 1.0, -0.2], [0.2, 1.0, 0.2], [-0.2, 1.0, 0.2]],
                                           [0.0, -1.0, 0.0])])
    b.add_camera("camera", (0.0, 0.5, 0.0), LOOK_DOWN, 1.2, aspect=1.0, znear=0.01, zfar=10.0)
    b.write(path)


TEXTURE_QUADRANTS = [[(255, 0, 0), (0, 255, 0)], [(0, 0, 255), (128, 128, 128)]]  # top row first


def textured_floor(path):
    """A 1 x 1 m floor at y = 0 facing up whose base colour is a 2 x 2 texture (nearest filtering):
    red at u < 0.5, v < 0.5, green at u > 0.5, v < 0.5, blue at u < 0.5, v > 0.5, grey 128 (sRGB,
    linear 0.2158) at u, v > 0.5, with u = x + 0.5 and v = z + 0.5. A point light 0.8 m above the
    centre, a camera 1.2 m above looking down. The texture paths (raster voxelizer, G-buffer,
    inject) must reproduce the four quadrants."""
    b = GltfBuilder("voxlab scripts/make_scenes.py (textured floor)")
    d = b.doc
    png = png_rgb(2, 2, TEXTURE_QUADRANTS)
    d["images"] = [{"uri": "data:image/png;base64," + base64.b64encode(png).decode("ascii")}]
    d["samplers"] = [{"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33071}]
    d["textures"] = [{"source": 0, "sampler": 0}]
    d["materials"].append({"name": "quadrants", "pbrMetallicRoughness": {
        "baseColorFactor": [1.0, 1.0, 1.0, 1.0], "baseColorTexture": {"index": 0},
        "metallicFactor": 0.0, "roughnessFactor": 1.0}})
    corners = [(-0.5, -0.5), (-0.5, 0.5), (0.5, 0.5), (0.5, -0.5)]  # counter-clockwise seen from +y
    positions = [v for x, z in corners for v in (x, 0.0, z)]
    normals = [v for _ in corners for v in (0.0, 1.0, 0.0)]
    uvs = [v for x, z in corners for v in (x + 0.5, z + 0.5)]
    pos = b.add_accessor(positions, "VEC3", 5126, 4, with_bounds=True, target=34962)
    nrm = b.add_accessor(normals, "VEC3", 5126, 4, target=34962)
    uv = b.add_accessor(uvs, "VEC2", 5126, 4, target=34962)
    idx = b.add_accessor([0, 1, 2, 0, 2, 3], "SCALAR", 5123, 6, target=34963)
    d["meshes"].append({"name": "textured-floor", "primitives": [{
        "attributes": {"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv}, "indices": idx, "material": 0, "mode": 4}]})
    b.add_node({"name": "textured-floor", "mesh": len(d["meshes"]) - 1})
    b.add_light("above", {"type": "point", "color": [1.0, 1.0, 1.0], "intensity": 1.0}, (0.0, 0.8, 0.0))
    b.add_camera("camera", (0.0, 1.2, 0.0), LOOK_DOWN, 0.9, aspect=1.0, znear=0.01, zfar=10.0)
def sunlit_floor(path, irradiance, roof):
    """Floor 2 x 2 m at y = 0 lit by a sun shining straight down with irradiance E (W/m^2); with
    'roof', a roof over the floor's -x half (x -1..0) at y = 1 puts the air under it in shadow.
    The camera, inside the medium below the roof's height, looks along +z at 24 degrees below the
    horizon; its top rows see no surface. Without a roof all air is lit; with one, the camera
    sits 5 cm inside the shadow, so rays leaving it towards -x stay in shadow all the way."""
    b = GltfBuilder("voxlab scripts/make_scenes.py (sunlit floor)")
    grey = b.add_material("grey", (0.5, 0.5, 0.5))
    floor = [[-1.0, 0.0, -1.0], [1.0, 0.0, -1.0], [1.0, 0.0, 1.0], [-1.0, 0.0, 1.0]]
    b.add_mesh_node("floor", grey, [oriented(floor, [0.0, 1.0, 0.0])])
    if roof:
        top = [[-1.0, 1.0, -1.0], [0.0, 1.0, -1.0], [0.0, 1.0, 1.0], [-1.0, 1.0, 1.0]]
        b.add_mesh_node("roof", grey, [oriented(top, [0.0, -1.0, 0.0])])
    b.add_light("sun", {"type": "directional", "color": [1.0, 1.0, 1.0], "intensity": irradiance},
                (0.0, 3.0, 0.0), LOOK_DOWN)
    tilt = math.radians(24.0)  # turn -Z to +Z (180 deg about y), then tilt down about x
    b.add_camera("camera", (-0.05 if roof else 0.0, 0.8, -0.9),
                 (0.0, round(math.cos(tilt / 2), 6), round(math.sin(tilt / 2), 6), 0.0),
                 0.7, aspect=1.0, znear=0.01, zfar=20.0)
    b.write(path)


def sunlit_floor_fine(path, n=48):
    """sunlit-floor.gltf's floor and sun, the floor cut into 2 * n^2 triangles (4.2 cm edges): at
    voxel.resolution 64 every voxel of the floor is touched by several triangles, so the fragment
    list holds each voxel several times (as Sponza's finely tessellated meshes do)."""
    b = GltfBuilder("voxlab scripts/make_scenes.py (sunlit floor, fine triangles)")
    grey = b.add_material("grey", (0.5, 0.5, 0.5))
    points, tris = [], []
    for j in range(n + 1):
        for i in range(n + 1):
            points.append((-1.0 + 2.0 * i / n, 0.0, -1.0 + 2.0 * j / n))
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            c = a + n + 1
            tris += [(a, c, a + 1), (a + 1, c, c + 1)]
    b.add_node({"name": "floor", "mesh": b.add_indexed_mesh("floor", grey, points, tris)})
    b.add_light("sun", {"type": "directional", "color": [1.0, 1.0, 1.0], "intensity": 1.0},
                (0.0, 3.0, 0.0), LOOK_DOWN)
    b.add_camera("camera", (0.0, 1.5, 0.0), LOOK_DOWN, 1.2, aspect=1.0, znear=0.01, zfar=20.0)
    b.write(path)


def sunlit_slope(path):
    """A 2 x 2 m floor tilted 30 degrees about z (normal (-sin 30, cos 30, 0)) under the sun of
    sunlit-floor.gltf (straight down, 1 W/m^2): irradiance cos 30, reflected flux 0.5 x 0.866 x 4 =
    1.732 W. A conservative voxelization covers |n|_1 = 1.366 voxels per voxel^2 of it (45 degrees
    would put the plane on voxel edges, a degenerate case of that count)."""
    b = GltfBuilder("voxlab scripts/make_scenes.py (sunlit slope)")
    grey = b.add_material("grey", (0.5, 0.5, 0.5))
    c, s = math.cos(math.radians(30.0)), math.sin(math.radians(30.0))
    slope = [[-c, -s, -1.0], [c, s, -1.0], [c, s, 1.0], [-c, -s, 1.0]]
    b.add_mesh_node("slope", grey, [oriented(slope, [-s, c, 0.0])])
    b.add_light("sun", {"type": "directional", "color": [1.0, 1.0, 1.0], "intensity": 1.0},
                (0.0, 3.0, 0.0), LOOK_DOWN)
    b.add_camera("camera", (0.0, 1.5, 0.0), LOOK_DOWN, 1.2, aspect=1.0, znear=0.01, zfar=20.0)
    b.write(path)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--root", default=os.path.dirname(here), help="project root (default: this repo)")
    parser.add_argument("--furnace-albedo", type=float, default=0.5)
    args = parser.parse_args()
    if not 0.0 <= args.furnace_albedo <= 1.0:
        parser.error("--furnace-albedo must be in [0, 1]")
    scenes = os.path.join(args.root, "scenes")
    tests = os.path.join(args.root, "tests", "data", "scenes")
    os.makedirs(scenes, exist_ok=True)
    os.makedirs(tests, exist_ok=True)
    outputs = [
        (os.path.join(scenes, "cornell-box.gltf"), cornell_box),
        (os.path.join(tests, "cornell-box-x100.gltf"), lambda p: cornell_box(p, 100.0)),
        (os.path.join(tests, "no-light-blocks.gltf"), no_light_blocks),
        (os.path.join(tests, "no-light-blocks-x1_128.gltf"), lambda p: no_light_blocks(p, 1.0 / 128.0)),
        (os.path.join(tests, "furnace-box.gltf"), lambda p: furnace_box(p, args.furnace_albedo)),
        (os.path.join(tests, "wall-floor.gltf"), wall_floor),
        (os.path.join(tests, "floor-ceiling.gltf"), floor_ceiling),
        (os.path.join(tests, "corner.gltf"), corner),
        (os.path.join(tests, "thin-wall.gltf"), thin_wall),
        (os.path.join(tests, "thin-wall-spot.gltf"), lambda p: thin_wall(p, spot=True)),
        (os.path.join(tests, "leak-rooms.gltf"), leak_rooms),
        (os.path.join(tests, "cornell-box-panel-only.gltf"), lambda p: cornell_box(p, spot=False)),
        (os.path.join(tests, "dense-sheet.gltf"), dense_sheet),
        (os.path.join(tests, "huge-triangles.gltf"), huge_triangles),
        (os.path.join(tests, "boundary-quad.gltf"), boundary_quad),
        (os.path.join(tests, "long-hall.gltf"), long_hall),
        (os.path.join(tests, "furnace-colour.gltf"), lambda p: furnace_box(p, (0.8, 0.5, 0.2))),
        (os.path.join(tests, "lid-floor.gltf"), lid_floor),
        (os.path.join(tests, "textured-floor.gltf"), textured_floor),
        (os.path.join(tests, "sunlit-floor.gltf"), lambda p: sunlit_floor(p, 1.0, False)),
        (os.path.join(tests, "sunlit-floor-bright.gltf"), lambda p: sunlit_floor(p, 2.5, False)),
        (os.path.join(tests, "half-roof.gltf"), lambda p: sunlit_floor(p, 1.0, True)),
        (os.path.join(tests, "sunlit-floor-fine.gltf"), sunlit_floor_fine),
        (os.path.join(tests, "sunlit-slope.gltf"), sunlit_slope),
    ] + [(os.path.join(tests, "voxel-ties-%d.gltf" % r), (lambda r: lambda p: voxel_ties(p, r))(r))
         for r in (64, 128, 256)]
    for path, fn in outputs:
        fn(path)
        print("wrote", os.path.relpath(path, args.root))


if __name__ == "__main__":
    main()
