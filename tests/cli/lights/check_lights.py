#!/usr/bin/env python3
"""Checks of the default sun, the light parameters and scaled scenes, looping over every technique
`voxlab list` names (no technique ids here).

  check_lights.py VOXLAB default-light OUT_DIR [--shading X,Y,Z X,Y,Z] SCENE...
      Each SCENE has no light: every technique must say so on stderr and in the manifest
      ("light": "default sun (scene has none)"), the same for the camera when the file has none
      ("camera": "framing camera (scene has none)"; a file's own camera is kept and named "scene
      camera 'NAME'"), and write a final image that is neither black nor flat. With --shading FROM AT (the
      raw Sponza) each technique is also run from --look-from FROM --look-at AT, and that image
      must be shadowed and indirectly lit: over the pixels the G-buffer
      covers, a fraction in the direct light's shadow, a fraction with indirect light above zero
      (also among the shadowed ones) and a luma spread of the final image (MIN_* below); a
      technique declaring light.0.azimuth is run again with the sun turned
      (--set light.0.azimuth=210 --set light.0.elevation=35), which must change its final image.
      A SCENE path that does not exist (the raw Sponza outside the repository) is reported and
      left out.
  check_lights.py VOXLAB same-picture OUT_DIR TOLERANCES.json SCALE SCENE_A SCENE_B
      SCENE_B is SCENE_A with every length x SCALE: every technique's final image of B must match
      A's within the snapshot tolerance of that output (tests/golden/tolerances.json), plus a
      few values of float rounding when SCALE is not a power of two (rounding_allowance). Parameters declared in m or 1/m are scaled
      with the scene (LENGTH_UNITS); every other parameter keeps its default.

Runs are small (96x96, voxel grids at 64 where a technique declares voxel.resolution) to keep
the suite fast; the settings are chosen from the declared parameters, never by technique.
"""
import json
import math
import os
import struct
import subprocess
import sys
import zlib

DEFAULT_SUN = "default sun (scene has none)"
FRAMING_CAMERA = "framing camera (scene has none)"
SIZE = "96x96"


def read_png(path):
    """8-bit RGB/RGBA PNG -> (width, height, channels, bytes)."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    pos, idat, w = 8, b"", 0
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, colour = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and colour in (2, 6), f"{path}: only 8-bit RGB/RGBA"
            ch = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    raw = zlib.decompress(idat)
    stride = w * ch
    out = bytearray()
    prev = bytearray(stride)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - ch] if i >= ch else 0
            b = prev[i]
            c = prev[i - ch] if i >= ch else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        out += line
        prev = line
    return w, h, ch, bytes(out)


def scene_has_camera(path):
    """Whether a glTF (JSON) or GLB file has a camera: the loader adds the framing camera otherwise."""
    data = open(path, "rb").read()
    if data[:4] == b"glTF":  # GLB: 12-byte header, then the JSON chunk (length, type, data)
        n = struct.unpack("<I", data[12:16])[0]
        data = data[20:20 + n]
    return bool(json.loads(data).get("cameras"))


def techniques(exe):
    listing = json.loads(subprocess.run([exe, "list", "--json"], check=True, capture_output=True, text=True).stdout)
    return listing["techniques"]


def small_settings(tech):
    names = {p["name"] for s in tech["stages"] for p in s.get("parameters", [])}
    return ["--set", "voxel.resolution=64"] if "voxel.resolution" in names else []


def run(exe, tech, scene, out, extra=(), final_only=True):
    cmd = [exe, "run", "--technique", tech["id"], "--scene", scene, "--size", SIZE, "--out", out]
    cmd += ["--final-only"] if final_only else []
    cmd += small_settings(tech) + list(extra)
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=900)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)}: exit {r.returncode}\n{r.stderr}")
    manifest = json.load(open(os.path.join(out, "manifest.json")))
    final = None
    for s in manifest["stages"]:
        for o in s["outputs"]:
            if o.get("final"):
                final = o
    if final is None:
        sys.exit(f"{tech['id']} on {scene}: the manifest lists no final output")
    return r, manifest, final


def read_exr(path):
    """(w, h, [channel values per pixel]) of an EXR, pixels in the order of the PNG voxlab writes
    beside it (row 0 first), read through `oiiotool --dumpdata` (openimageio-tools, installed by
    scripts/setup.sh)."""
    text = subprocess.run(["oiiotool", "--dumpdata", path], check=True, capture_output=True, text=True).stdout
    lines = text.splitlines()
    w, h = (int(v) for v in lines[0].split(":", 1)[1].split(",")[0].split("x"))
    px = [None] * (w * h)
    for line in lines[1:]:
        head, _, vals = line.partition("):")
        if not head.strip().startswith("Pixel ("):
            continue
        x, y = (int(v) for v in head.strip()[len("Pixel ("):].split(","))
        px[y * w + x] = tuple(float(v) for v in vals.split())
    if any(p is None for p in px):
        sys.exit(f"{path}: oiiotool --dumpdata did not list every pixel")
    return w, h, px


def luminance_stats(path):
    w, h, ch, px = read_png(path)
    lum = [0.2126 * px[i] + 0.7152 * px[i + 1] + 0.0722 * px[i + 2] for i in range(0, len(px), ch)]
    mean = sum(lum) / len(lum)
    sd = (sum((v - mean) ** 2 for v in lum) / len(lum)) ** 0.5
    return mean, sd


def shading_outputs(tech):
    """Addresses of the outputs the shading checks read, found from the declarations (never by
    technique): the G-buffer's world position ("position": w = 1 where a surface is covered), the
    last image approximating the "direct" reference mode and the last approximating an
    "indirect*" mode. None where a technique has no such output."""
    cover = direct = indirect = None
    for st in tech["stages"]:
        for o in st.get("outputs", []):
            if o["kind"] != "image2d":
                continue
            mode = o.get("reference_mode", "")
            if o["name"] == "position": cover = o["address"]
            if mode == "direct": direct = o["address"]
            if mode.startswith("indirect"): indirect = o["address"]
    return cover, direct, indirect


def exr_of(out, manifest, address):
    stage, name = address.split("/")[1:3]
    for s in manifest["stages"]:
        for o in s["outputs"]:
            if s["id"] == stage and o["name"] == name:
                return os.path.join(out, [f for f in o["files"] if f.endswith(".exr")][0])
    sys.exit(f"{address}: not in the manifest of {out}")


def shading_stats(out, manifest, final_png, tech):
    """Over the covered pixels (the G-buffer's w = 1): the fraction in the direct light's shadow
    (direct = 0), the fraction with indirect light above zero, that fraction among the shadowed
    ones, and the final image's luma standard deviation (8-bit steps). {} without a G-buffer."""
    cover, direct, indirect = shading_outputs(tech)
    if cover is None:
        return {}
    w, h, cov = read_exr(exr_of(out, manifest, cover))
    covered = [i for i, p in enumerate(cov) if p[3] > 0.0]
    st = {"covered": len(covered) / len(cov)}
    if not covered:
        sys.exit(f"{tech['id']}: the G-buffer covers no pixel of {out}")
    fw, fh, ch, px = read_png(os.path.join(out, final_png))
    if (fw, fh) != (w, h):
        sys.exit(f"{tech['id']}: final image {fw}x{fh} and G-buffer {w}x{h} differ in size")
    lum = [0.2126 * px[i * ch] + 0.7152 * px[i * ch + 1] + 0.0722 * px[i * ch + 2] for i in covered]
    mean = sum(lum) / max(len(lum), 1)
    st["covered_sd"] = (sum((v - mean) ** 2 for v in lum) / max(len(lum), 1)) ** 0.5

    def sampled(address):  # an image of any size, looked up at each covered pixel (nearest)
        iw, ih, vals = read_exr(exr_of(out, manifest, address))
        return [sum(vals[(i // w) * ih // h * iw + (i % w) * iw // w][:3]) for i in covered]
    shadowed = None
    if direct is not None:
        d = sampled(direct)
        shadowed = [k for k, v in enumerate(d) if v <= 0.0]
        st["shadowed"] = len(shadowed) / max(len(covered), 1)
    if indirect is not None:
        ind = sampled(indirect)
        st["indirect"] = sum(1 for v in ind if v > 0.0) / max(len(covered), 1)
        if shadowed:
            st["indirect_in_shadow"] = sum(1 for k in shadowed if ind[k] > 0.0) / len(shadowed)
    return st


# Shading thresholds (default-light --shading): fractions of the covered pixels and 8-bit steps,
# about half of the least measured over the techniques that have the output. Measured on the raw
# Sponza from inside the nave (lights.cmake's view; 96x96, 64^3, LP_NUM_THREADS=2, 2026-12-02;
# covered 0.781 of the image): shadowed 0.952 (lrsm 0.497: its soft shadow leaves fewer exact
# zeros), so lit 0.048 (lrsm 0.503); indirect above zero 0.542 (voxel-path-tracing), 0.591
# (near-field), 0.909..1.0 (clipmap, lpv, lrsm, svo, vct-grid); among the shadowed pixels 0.519
# (voxel-path-tracing) .. 1.0; luma sd of the covered pixels 19.1 (volumetric) .. 22.4 (vct-grid).
# From the framing camera (outside the walls) the same techniques gave indirect light in 0 (near-
# field, voxel-path-tracing) to 1.0 of the pixels while the path tracer's indirect-1 is above zero
# in 0.07 % of them: hence the inside view.
MIN_SHADOWED, MIN_LIT, MIN_INDIRECT, MIN_INDIRECT_IN_SHADOW, MIN_COVERED_SD = 0.25, 0.024, 0.27, 0.26, 9.5


def default_light(exe, out_dir, scenes, turn, shading_view=None):
    failures = []
    for scene in scenes:
        for tech in techniques(exe):
            out = os.path.join(out_dir, os.path.basename(scene), tech["id"])
            r, manifest, final = run(exe, tech, scene, out)
            png = [f for f in final["files"] if f.endswith(".png")][0]
            mean, sd = luminance_stats(os.path.join(out, png))
            said = DEFAULT_SUN in r.stderr
            framed = FRAMING_CAMERA in r.stderr
            line = (f"{tech['id']:12s} {os.path.basename(scene)}: mean {mean:.1f}/255, sd {sd:.1f}, "
                    f"stderr names the default sun: {said}, the framing camera: {framed}, "
                    f"manifest light: {manifest.get('light')!r}, camera: {manifest.get('camera')!r}")
            print(line)
            # Thresholds: a black image has mean 0 and a flat one sd 0. Measured on no-light-blocks
            # (96x96, 8-bit steps, 2026-12-02): means 11.9 (lrsm) .. 42.5 (volumetric, haze), sd
            # 40.5..43.1, voxelization (voxels shown, not lit) 13.8 / 4.3; before the default sun
            # the lit techniques gave mean 0. 2 steps of mean and 2 of sd separate lit from black / flat.
            if not said: failures.append(line + ": stderr lacks the default-sun line")
            if manifest.get("light") != DEFAULT_SUN: failures.append(line + ": manifest light is wrong")
            # A scene without a camera (no-light-blocks, the raw Sponza) gets the framing camera,
            # said on stderr and in the manifest like the sun; one with a camera (2CylinderEngine
            # has one) keeps it, and neither says so.
            if scene_has_camera(scene):
                if framed: failures.append(line + ": stderr names a framing camera, but the scene has one")
                if not str(manifest.get("camera", "")).startswith("scene camera '"):
                    failures.append(line + ": manifest camera is not the scene's")
            else:
                if not framed: failures.append(line + ": stderr lacks the framing-camera line")
                if manifest.get("camera") != FRAMING_CAMERA: failures.append(line + ": manifest camera is wrong")
            if mean < 2.0: failures.append(line + ": final image is black")
            if sd < 2.0: failures.append(line + ": final image is flat")
            if shading_view:
                # From inside (the framing camera sees the outside of the walls, where the path
                # tracer's indirect-1 is above zero in 0.07 % of the covered pixels: no indirect
                # light to check there).
                only = [a for a in shading_outputs(tech) if a] + [tech["final_output"]]
                inside = out + "-inside"
                extra = [x for a in only for x in ("--only", a)] + ["--look-from", shading_view[0], "--look-at", shading_view[1]]
                _, m3, f3 = run(exe, tech, scene, inside, extra, final_only=False)
                st = shading_stats(inside, m3, [f for f in f3["files"] if f.endswith(".png")][0], tech)
                print(f"{'':12s} shading: " + ", ".join(f"{k} {v:.3f}" for k, v in st.items()))
                # Each check where the technique has the output: voxelization has no G-buffer
                # (the checks above only), volumetric no indirect term.
                if "shadowed" in st and st["shadowed"] < MIN_SHADOWED:
                    failures.append(line + f": only {st['shadowed']:.3f} of the covered pixels are in shadow")
                if "shadowed" in st and 1.0 - st["shadowed"] < MIN_LIT:
                    failures.append(line + f": only {1.0 - st['shadowed']:.3f} of the covered pixels are lit directly")
                if "indirect" in st and st["indirect"] < MIN_INDIRECT:
                    failures.append(line + f": indirect light in only {st['indirect']:.3f} of the covered pixels")
                if "indirect_in_shadow" in st and st["indirect_in_shadow"] < MIN_INDIRECT_IN_SHADOW:
                    failures.append(line + f": indirect light in only {st['indirect_in_shadow']:.3f} of the shadowed pixels")
                if "covered_sd" in st and st["covered_sd"] < MIN_COVERED_SD:
                    failures.append(line + f": the covered pixels are flat (luma sd {st['covered_sd']:.1f})")
            if turn and any(p["name"] == "light.0.azimuth" for st in tech["stages"] for p in st.get("parameters", [])):
                # The same run with the sun turned (--set light.0.*): the parameters reach the
                # manifest and the final image changes.
                out2 = out + "-turned"
                _, m2, f2 = run(exe, tech, scene, out2, ["--set", "light.0.azimuth=210", "--set", "light.0.elevation=35"])
                p = m2["parameters"]
                moved = read_png(os.path.join(out2, png))[3] != read_png(os.path.join(out, png))[3]
                print(f"{'':12s} turned to azimuth {p['light.0.azimuth']}, elevation {p['light.0.elevation']}: image changed: {moved}")
                if p["light.0.azimuth"] != "210" or p["light.0.elevation"] != "35":
                    failures.append(line + ": --set light.0.* did not reach the manifest")
                if not moved:
                    failures.append(line + ": turning the sun did not change the final image")
    if failures:
        sys.exit("\n".join(failures))


# Parameters whose declared unit is a world length (or its inverse) describe the scene's physical
# size, not the technique's sampling: a coefficient in 1/m (e.g. a medium's sigma_s) is a property
# of the medium, so the scaled scene gets it scaled (the same haze, measured in the scene's own
# unit). None is declared so today (volumetric's media are optical depths over the scene's extent);
# the rule stays for the next one.
# Every other parameter must already be scale-free (in voxels, texels, fractions of the bounds).
LENGTH_UNITS = {"m": 1.0, "1/m": -1.0}

# Rounding allowance: a scale that is not a power of two makes the scaled scene's floats round
# differently (every position x100), which moves a few 8-bit values of a final image. Measured on
# the Cornell box x100 at 96x96 (27648 values) after the shadow map's lengths were made relative:
# 0 values (lpv, svo, near-field, volumetric, voxelization) or 1 value (lrsm: 1 step,
# voxel-path-tracing and vct-grid: 2 steps, clipmap: 4 steps, a voxel on a cell face that the
# scaled floats round to the other side); before, every lit technique differed by up to 76 steps
# (rmse 0.011..0.012; the spot's near plane and the 1 cm normal offset), and clipmap with a voxel
# size in powers of two of metres in 22111 values by up to 118 steps. A power-of-two scale scales
# every float exactly: no allowance, any difference is a length in absolute units. Measured again
# 2026-12-02: 0 values (lpv, near-field, svo, voxelization), 1 value by 1 step (clipmap, lrsm),
# 2 by 1 step (volumetric), 1 by 2 steps (vct-grid, voxel-path-tracing). Since lrsm's shadow cone
# reads finer mips (cone.shadow-lod-bias -1, 2026-12-02), one lrsm value moves by 6 steps at x100
# (a shadow-cone sample on a texel face); at x128 lrsm is exact, so the difference is rounding.
# Measured again 2026-12-06 after lrsm's two depth lobes per layer: lrsm 7 values, worst 9 steps at
# x100 (near-field, svo, voxel-path-tracing 1 value, volumetric 2, by 1-3 steps; the rest 0).
ROUNDING_VALUES, ROUNDING_STEPS = 12, 10


def rounding_allowance(scale):
    exponent = math.log2(scale)
    return (0, 0) if exponent == round(exponent) else (ROUNDING_VALUES, ROUNDING_STEPS)


def scaled_settings(tech, scale):
    out = []
    for st in tech["stages"]:
        for p in st.get("parameters", []):
            power = LENGTH_UNITS.get(p.get("unit", ""))
            if power is None:
                continue
            try:
                value = float(p["default"])
            except ValueError:
                continue
            out += ["--set", f"{p['name']}={value * scale ** power!r}"]
    return sorted(set(zip(out[::2], out[1::2])))


def same_picture(exe, out_dir, tolerances, scale, scene_a, scene_b):
    """Every technique's final image of scene_b (scene_a with every length x scale) must equal
    scene_a's within the snapshot tolerance of that output plus the rounding allowance."""
    tol = json.load(open(tolerances))
    scale = float(scale)
    failures = []
    for tech in techniques(exe):
        pngs = []
        extra = [a for pair in scaled_settings(tech, scale) for a in pair]
        for scene, settings in ((scene_a, []), (scene_b, extra)):
            out = os.path.join(out_dir, os.path.basename(scene), tech["id"])
            _, _, final = run(exe, tech, scene, out, settings)
            png = [f for f in final["files"] if f.endswith(".png")]
            if not png:
                sys.exit(f"{tech['id']}: the final output has no PNG to compare")
            pngs.append(os.path.join(out, png[0]))
        address = tech["final_output"]
        t = tol["outputs"].get(address, tol["default"])
        a, b = read_png(pngs[0]), read_png(pngs[1])
        if a[:3] != b[:3]:
            sys.exit(f"{address}: image sizes differ: {a[:3]} vs {b[:3]}")
        steps = [abs(x - y) for x, y in zip(a[3], b[3])]
        allowed_steps = int(t["max_abs"] * 255.0 + 1e-6)  # 8-bit steps the snapshot tolerance admits
        differing = sum(1 for d in steps if d > allowed_steps)
        extra_values, extra_steps = rounding_allowance(scale)
        allowed = int(t.get("max_fraction", 0.0) * len(steps)) + extra_values
        worst = max(steps) if steps else 0
        line = (f"{address}: scaled x{scale:g} vs original: {differing} of {len(steps)} values differ "
                f"by more than {allowed_steps} steps (allowed: {allowed}, up to {allowed_steps + extra_steps} steps), "
                f"worst {worst} steps"
                + (f"; scaled {' '.join(extra[1::2])}" if extra else ""))
        print(line)
        if differing > allowed or worst > allowed_steps + extra_steps:
            failures.append(line)
    if failures:
        sys.exit("the scaled scene renders differently:\n" + "\n".join(failures))


def main():
    exe, mode, out_dir = sys.argv[1:4]
    os.makedirs(out_dir, exist_ok=True)
    if mode == "default-light":
        args = sys.argv[4:]
        view = None
        if "--shading" in args:  # --shading FROM AT: the shading checks from --look-from FROM --look-at AT
            k = args.index("--shading")
            view = args[k + 1:k + 3]
            args = args[:k] + args[k + 3:]
        scenes = [s for s in args if os.path.exists(s) or not s.endswith((".gltf", ".glb"))]
        for s in args:
            if s not in scenes: print(f"{s} is not there: not checked")
        default_light(exe, out_dir, scenes, turn=True, shading_view=view)
    elif mode == "same-picture":
        same_picture(exe, out_dir, *sys.argv[4:8])
    else:
        sys.exit(f"unknown mode {mode}; valid: default-light, same-picture")


if __name__ == "__main__":
    main()
