#!/usr/bin/env python3
"""mitsuba_envmap_check.py — vbcl's image.environment against Mitsuba 3's envmap emitter (not
part of `make test`): a smooth glass sphere (eta 1.5, no absorption) under the same
latitude-longitude image, seen by the same camera in both renderers, and the RMS difference
of the two images beside the noise floor of Mitsuba's (two renders with different seeds).

usage: scripts/mitsuba_envmap_check.py [--vbcl ./vbcl] [--env scenes/images/sky.exr]
           [--size 128] [--spp 1024] [--ssaa 16] [--depth 24] [--rotation 30]
           [--variant scalar_rgb] [--out DIR]
Needs Mitsuba 3 and numpy (`python3 -m venv /tmp/mi && /tmp/mi/bin/pip install mitsuba
numpy`, then run this script with /tmp/mi/bin/python). Writes vbcl.exr, mitsuba_1.exr,
mitsuba_2.exr and the vbcl scene into DIR (a temporary directory by default) and prints:

  rms(vbcl - mitsuba_k)   for each seed k, and against their mean
  rms(mitsuba_1 - mitsuba_2) / sqrt(2)   the noise of one Mitsuba render (the floor)
  excess   sqrt(rms(vbcl - mitsuba)^2 - floor^2): what the noise does not explain

over all pixels, over the pixels whose centre sees the sphere, and over those that see the
environment directly. RMS is of linear radiance, all three channels.

The two scenes are one scene: Mitsuba's camera is `perspective` with fov_axis "y" (vbcl's
fov is vertical; Mitsuba's default is the x axis), a `box` pixel filter (vbcl's --ssaa
averages N x N samples at the subpixel centres: a box), the `path` integrator with
max_depth = vbcl's depth + 1 (Mitsuba counts path segments, vbcl the tree's levels below the
camera ray) and Russian roulette only beyond it, the `envmap` emitter with to_world =
rotate([0, 1, 0], rotation), which is vbcl's "rotation": the same angle, and a `dielectric`
sphere (int_ior 1.5, ext_ior 1). vbcl's sphere is an icosphere of level 7 (327,680
triangles, smooth normals) with k_local 0 and k_global 1; its pruning is lowered to
--min-weight 1e-6 so that dropped branches cannot matter beside the sun's radiance.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

EYE, LOOK, UP, FOV = [0.0, 0.35, 4.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 36.0
RADIUS, ETA = 1.0, 1.5


def vbcl_scene(env, rotation, size, path):
    scene = {
        "description": "mitsuba_envmap_check.py: a glass sphere under an environment",
        "image": {"width": size, "height": size,
                  "environment": {"file": os.path.abspath(env), "rotation": rotation}},
        "camera": {"eye": EYE, "look_at": LOOK, "up": UP, "fov": FOV},
        "render": {"ambient": [0, 0, 0]},
        "materials": {"glass": {"diffuse": [0, 0, 0], "ambient": [0, 0, 0], "k_local": 0,
                                "k_global": 1, "eta": ETA}},
        "objects": [{"shape": "sphere", "radius": RADIUS, "centre": [0, 0, 0], "level": 7,
                     "material": "glass"}],
    }
    with open(path, "w") as f:
        json.dump(scene, f, indent=1)


def render_vbcl(a, scene, out):
    cmd = [a.vbcl, scene, "-q", "-o", out, "--ssaa", str(a.ssaa), "--depth", str(a.depth),
           "--min-weight", "1e-6"]
    t = time.time()
    subprocess.run(cmd, check=True)
    return time.time() - t, " ".join(cmd)


def render_mitsuba(mi, a, seed, out):
    T = mi.ScalarTransform4f
    scene = mi.load_dict({
        "type": "scene",
        "integrator": {"type": "path", "max_depth": a.depth + 1, "rr_depth": a.depth + 2},
        "sensor": {
            "type": "perspective", "fov": FOV, "fov_axis": "y",
            "to_world": T().look_at(origin=EYE, target=LOOK, up=UP),
            "sampler": {"type": "independent", "sample_count": a.spp, "seed": seed},
            "film": {"type": "hdrfilm", "width": a.size, "height": a.size,
                     "rfilter": {"type": "box"}, "pixel_format": "rgb"},
        },
        "sky": {"type": "envmap", "filename": os.path.abspath(a.env),
                "to_world": T().rotate([0, 1, 0], a.rotation)},
        "ball": {"type": "sphere", "center": [0, 0, 0], "radius": RADIUS,
                 "bsdf": {"type": "dielectric", "int_ior": ETA, "ext_ior": 1.0}},
    })
    t = time.time()
    img = mi.render(scene, seed=seed, spp=a.spp)
    mi.util.write_bitmap(out, img, write_async=False)
    return time.time() - t


def read_rgb(mi, path):
    return np.array(mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB,
                                            mi.Struct.Type.Float32, False))[..., :3]


def sphere_mask(size):
    """The pixels whose centre ray meets the sphere (vbcl's pinhole camera)."""
    eye, look = np.array(EYE), np.array(LOOK)
    fwd = (look - eye) / np.linalg.norm(look - eye)
    right = np.cross(fwd, UP)
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    th = math.tan(math.radians(FOV) / 2)
    s = (np.arange(size) + 0.5) / size * 2 - 1
    sx, sy = np.meshgrid(s, -s)
    d = fwd + sx[..., None] * th * right + sy[..., None] * th * up
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    b = d @ eye
    return b * b - (eye @ eye - RADIUS * RADIUS) > 0


def rms(x):
    return float(np.sqrt(np.mean(np.square(x)))) if x.size else float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vbcl", default="./vbcl")
    ap.add_argument("--env", default="scenes/images/sky.exr")
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--ssaa", type=int, default=16)
    ap.add_argument("--depth", type=int, default=24)
    ap.add_argument("--rotation", type=float, default=30.0)
    ap.add_argument("--variant", default="scalar_rgb")
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    try:
        import mitsuba as mi
    except ImportError:
        sys.exit("needs Mitsuba 3: pip install mitsuba (in a virtual environment)")
    mi.set_variant(a.variant)
    out = a.out or tempfile.mkdtemp(prefix="vbcl-mitsuba-")
    os.makedirs(out, exist_ok=True)
    scene = os.path.join(out, "glass_sphere.json")
    vbcl_scene(a.env, a.rotation, a.size, scene)
    paths = {k: os.path.join(out, k + ".exr") for k in ("vbcl", "mitsuba_1", "mitsuba_2")}
    tv, cmd = render_vbcl(a, scene, paths["vbcl"])
    tm = [render_mitsuba(mi, a, seed, paths["mitsuba_%d" % seed]) for seed in (1, 2)]
    v, m1, m2 = (read_rgb(mi, paths[k]) for k in ("vbcl", "mitsuba_1", "mitsuba_2"))
    ball = sphere_mask(a.size)
    print("vbcl: %s  (%.1f s)" % (cmd, tv))
    print("mitsuba %s %s: %d spp, path max_depth %d, box filter  (%.1f s, %.1f s)"
          % (mi.__version__, a.variant, a.spp, a.depth + 1, tm[0], tm[1]))
    print("%dx%d, rotation %g, env %s; mean radiance vbcl %.4f, mitsuba %.4f"
          % (a.size, a.size, a.rotation, a.env, v.mean(), (m1.mean() + m2.mean()) / 2))
    print("| pixels | rms(vbcl - m1) | rms(vbcl - m2) | rms(vbcl - mean) | noise floor "
          "rms(m1 - m2)/sqrt2 | excess |")
    print("|---|---|---|---|---|---|")
    for name, sel in (("all", np.ones_like(ball)), ("sphere", ball), ("environment", ~ball)):
        d1, d2 = rms((v - m1)[sel]), rms((v - m2)[sel])
        dm = rms((v - (m1 + m2) / 2)[sel])
        floor = rms((m1 - m2)[sel]) / math.sqrt(2)
        excess = math.sqrt(max(0.0, (d1 * d1 + d2 * d2) / 2 - floor * floor))
        print("| %s (%d) | %.4g | %.4g | %.4g | %.4g | %.4g |"
              % (name, int(sel.sum()), d1, d2, dm, floor, excess))
    print("images in", out)


if __name__ == "__main__":
    main()
