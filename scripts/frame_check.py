#!/usr/bin/env python3
"""frame_check.py — one scene at every scale and position: the same image and ray tree.

A glass sphere with absorption and a volume texture (bombed spheres of another glass) over
a floor, lit by one spherical light, is rendered as written (the unit scene) and with the
whole scene (camera, light, objects, extinction, the light's intensity by s^2 so that its
radiance stays) scaled by 1e-6, 1e-3, 1e3, 1e6 or moved by 1e3, 1e4, 1e5 along x, y and z.
Each variant is compared with the unit render: RMS and largest difference per value,
and the ray-tree counters of --stats-json (rays by kind, interfaces split). Prints one
line per case, "frame: CASE: ok ..." or "frame: CASE: FAILED ...", and the kernel time of
each against the unit scene's (a ratio: measured, not asserted; docs/architecture.md,
"Scale"). Exit status 1 when a case fails.

usage: scripts/frame_check.py --vbcl build/vbcl [--size 64x48] [--only REGEX] [--out DIR]
"""
import argparse
import json
import math
import os
import re
import struct
import subprocess
import sys
import tempfile

RMS_MAX = 1e-3  # the bounds (docs/testing.md, "Scale and position")
DIFF_MAX = 0.05
COUNT_REL = 0.005
COUNTERS = [("rays", "primary"), ("rays", "shadow"), ("rays", "total"),
            ("ray_tree", "reflected"), ("ray_tree", "transmitted"), ("ray_tree", "tir"),
            ("ray_tree", "pass_through"), ("ray_tree", "interfaces")]


def scene(scale, shift):
    """The test scene with every length multiplied by scale, then moved by shift."""
    def p(v):
        return [scale * v[i] + shift[i] for i in range(3)]

    def xf(s, t):
        return {"scale": s * scale, "translate": p(t)}
    return {
        "image": {"width": 64, "height": 48},
        "camera": {"eye": p([0.3, 1.6, 4.2]), "look_at": p([0, 0.2, 0]), "fov": 40},
        "render": {"max_depth": 6, "seed": 7, "shadow_samples": 4},
        "lights": [{"centre": p([2.5, 4, 3]), "radius": 0.6 * scale,
                    "flux": 900 * scale * scale}],
        "materials": {
            "floor": {"diffuse": [0.75, 0.7, 0.6]},
            "glass": {"k_local": 0.05, "k_global": 0.95, "eta": 1.5,
                      "extinction": [0.4 / scale, 0.15 / scale, 0.05 / scale]},
            "inner": {"k_local": 0.1, "k_global": 0.9, "eta": 1.33,
                      "diffuse": [0.9, 0.3, 0.2]},
        },
        "objects": [
            {"shape": "box", "size": [6, 0.2, 6], "material": "floor",
             "transform": xf(1, [0, -1.1, 0])},
            {"shape": "sphere", "level": 4, "material": "glass",  # placed by its centre
             "radius": scale, "centre": p([0, 0, 0]),
             "texture": {"generate": "bomb --count 12 --size 10:22 --seed 5 --no-overlap "
                                     "--level 2", "material": "inner"}},
        ],
    }


CASES = [("scale 1e-6", 1e-6, (0, 0, 0)), ("scale 1e-3", 1e-3, (0, 0, 0)),
         ("scale 1e3", 1e3, (0, 0, 0)), ("scale 1e6", 1e6, (0, 0, 0))]
for d in (1e3, 1e4, 1e5):
    for axis, name in enumerate("xyz"):
        shift = [0.0, 0.0, 0.0]
        shift[axis] = d
        CASES.append((f"moved {d:.0e} {name}".replace("e+0", "e"), 1.0, tuple(shift)))


def read_pfm(path):
    with open(path, "rb") as f:
        assert f.readline().strip() == b"PF"
        w, h = map(int, f.readline().split())
        s = float(f.readline())
        n = w * h * 3
        data = struct.unpack(("<" if s < 0 else ">") + f"{n}f", f.read(4 * n))
    return w, h, data


def render(vbcl, doc, size, tmp, tag):
    w, h = size
    doc["image"]["width"], doc["image"]["height"] = w, h
    path = os.path.join(tmp, tag + ".json")
    with open(path, "w") as f:
        json.dump(doc, f)
    img, st = os.path.join(tmp, tag + ".pfm"), os.path.join(tmp, tag + ".stats.json")
    r = subprocess.run([vbcl, path, "-q", "-o", img, "--stats-json", st],
                       capture_output=True, text=True)
    if r.returncode:
        return None, None, r.stderr.strip()
    with open(st) as f:
        return read_pfm(img)[2], json.load(f), ""


def counter(stats, key):
    v = stats
    for k in key:
        v = v.get(k, {}) if isinstance(v, dict) else {}
    return v if isinstance(v, (int, float)) else None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vbcl", default="build/vbcl")
    ap.add_argument("--size", default="64x48")
    ap.add_argument("--only", help="cases whose name this regular expression matches")
    ap.add_argument("--out", help="keep the scenes, images and stats here")
    a = ap.parse_args()
    size = tuple(int(x) for x in a.size.split("x"))
    tmp = a.out or tempfile.mkdtemp(prefix="vbcl-frame-")
    os.makedirs(tmp, exist_ok=True)
    render(a.vbcl, scene(1.0, (0, 0, 0)), size, tmp, "warm")  # kernels and texture cached
    unit, ustats, err = render(a.vbcl, scene(1.0, (0, 0, 0)), size, tmp, "unit")
    if unit is None:
        print(f"frame: the unit scene failed: {err}")
        return 1
    failed = 0
    print(f"| case | RMS | largest difference | counters off (worst) | kernel time / unit |")
    print(f"|---|---|---|---|---|")
    for name, s, shift in CASES:
        if a.only and not re.search(a.only, name):
            continue
        tag = re.sub(r"[^a-z0-9]+", "_", name)
        img, st, err = render(a.vbcl, scene(s, shift), size, tmp, tag)
        if img is None:
            print(f"frame: {name}: FAILED: the render failed: {err}")
            failed += 1
            continue
        diff = [abs(x - y) for x, y in zip(img, unit)]
        rms = math.sqrt(sum(d * d for d in diff) / len(diff))
        worst = max(diff)
        off, what = 0.0, ""
        for key in COUNTERS:
            u, v = counter(ustats, key), counter(st, key)
            if u is None or v is None:
                continue
            rel = abs(v - u) / max(u, 1)
            if rel > off:
                off, what = rel, f"{'.'.join(key)} {v} against {u}"
        ratio = st["time_ms"]["kernels"] / max(ustats["time_ms"]["kernels"], 1e-9)
        ok = rms <= RMS_MAX and worst <= DIFF_MAX and off <= COUNT_REL
        failed += not ok
        print(f"| {name} | {rms:.2e} | {worst:.2e} | {off * 100:.2f}% {what} | {ratio:.2f} |")
        print(f"frame: {name}: {'ok' if ok else 'FAILED'}: RMS {rms:.2e} (<= {RMS_MAX:g}), "
              f"largest difference {worst:.2e} (<= {DIFF_MAX:g}), counters within "
              f"{off * 100:.2f}% (<= {COUNT_REL * 100:g}%){': ' + what if what else ''}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
