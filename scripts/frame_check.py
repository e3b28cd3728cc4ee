#!/usr/bin/env python3
"""frame_check.py — one scene at every scale and position: the same image and ray tree.

The scenes of tests/scenes/frame/ (a glass sphere with absorption and a volume texture on a
checkered floor under one light, the same lit by its environment alone, a dispersive prism,
an absorbing glass prism standing on a floor under a spherical and a point light) are
rendered as written (the unit scene; 2 x 2 samples per pixel) and with the whole scene
scaled and moved: every
position of the file p -> s p + t, every length (light radii, objects' scales, a sphere's
radius, pattern sizes) times s, extinctions divided by s, lights' flux and intensity times
s^2 (so that their radiance and the irradiance they give stay). Each variant is compared with
its unit render: RMS and largest difference over every value (channel) of the linear image,
the ray-tree counters of --stats-json (rays by kind, interfaces split, band rays), and the
work (grid cells visited + triangles tested, which the kernel time follows). A case named
"... exact" (a power-of-two scale) must give the unit image bit for bit. Prints one line
per case, "frame: CASE: ok ..." or "frame: CASE: FAILED ...", and the kernel time against the
unit scene's (measured, not asserted: at these sizes it is mostly noise; docs/architecture.md,
"Scale"). Exit status 1 when a case fails.

usage: scripts/frame_check.py --vbcl build/vbcl [--only REGEX] [--out DIR] [--stress]
  --stress   more scales and positions (every decade 1e-6 .. 1e6, moves of 1e3 .. 1e5 along
             every axis, a diagonal and an uneven one) on every scene, 5 x 5 samples per pixel
"""
import argparse
import copy
import json
import math
import os
import re
import struct
import subprocess
import sys
import tempfile

RMS_MAX = 1e-3  # the bounds (docs/testing.md, "frame")
DIFF_MAX = 0.05
COUNT_REL = 0.005
WORK_MAX = 1.2
COUNTERS = [("rays", "primary"), ("rays", "shadow"), ("rays", "total"),
            ("ray_tree", "reflected"), ("ray_tree", "transmitted"), ("ray_tree", "tir"),
            ("ray_tree", "pass_through"), ("ray_tree", "interfaces"), ("ray_tree", "splits"),
            ("ray_tree", "band_rays")]
SCENES = "tests/scenes/frame"
# Every pixel is the mean of 2 x 2 samples (5 x 5 in --stress), as in a user's anti-aliased
# render: a scale that is no power of two or a move by an uneven amount changes the scene's
# floats in their last place, and a sample on a knife edge (a silhouette, a feeler grazing an
# edge, a path at the critical angle) goes the other way; alone, it moves its pixel by the
# whole contrast of that edge over the samples (the glass sphere's unit render has a value
# that moves by 0.057 when the scene moves by 0.3 along x; the prism's thin line 0.57 at
# 144 x 96). With 25 samples one such sample moves a pixel by at most 0.044 on an edge of
# contrast up to 1.1 (the contact scene's brightest, 0.23 against 1.10), within DIFF_MAX; with
# 16 it moved one by 0.056 in the contact scene moved by UNEVEN.
SAMPLES = {False: ["--ssaa", "2"], True: ["--ssaa", "5"]}

# The cases of make test: (name, scene, scale, move).
UNEVEN = (12345.678, -54321.123, 77777.7)
CASES = [("scale 1e-6", "glass_texture", 1e-6, (0, 0, 0)),
         ("scale 1e-3", "glass_texture", 1e-3, (0, 0, 0)),
         ("scale 1e3", "glass_texture", 1e3, (0, 0, 0)),
         ("scale 1e6", "glass_texture", 1e6, (0, 0, 0))]
for _d in (1e3, 1e4, 1e5):
    for _axis, _name in enumerate("xyz"):
        _move = [0.0, 0.0, 0.0]
        _move[_axis] = _d
        CASES.append((f"moved {_d:.0e} {_name}".replace("e+0", "e"), "glass_texture", 1.0,
                      tuple(_move)))
CASES += [
    # where the frame is the identity (the view from 1/16 to 1024) or was not (a look_at
    # 2 to 64 viewing distances away), so that the kernels' own numbers meet the scale
    ("scale 0.02", "glass_texture", 0.02, (0, 0, 0)),
    ("scale 40", "glass_texture", 40.0, (0, 0, 0)),
    ("moved 250 x", "glass_texture", 1.0, (250.0, 0, 0)),
    ("moved 100 xyz", "glass_texture", 1.0, (100.0, -100.0, 100.0)),
    ("scale 1e-3 moved 0.25", "glass_texture", 1e-3, (0.25, 0, 0)),
    # a move by no power of two, far away
    ("moved uneven", "glass_texture", 1.0, UNEVEN),
    ("environment scale 1e-6", "glass_environment", 1e-6, (0, 0, 0)),
    ("environment scale 1e6", "glass_environment", 1e6, (0, 0, 0)),
    ("environment moved 1e5", "glass_environment", 1.0, (1e5, -1e5, 1e5)),
    ("prism scale 1e-6", "prism", 1e-6, (0, 0, 0)),
    ("prism scale 1e6", "prism", 1e6, (0, 0, 0)),
    ("prism moved 1e5", "prism", 1.0, (1e5, -1e5, 1e5)),
    ("contact scale 1e-6", "contact", 1e-6, (0, 0, 0)),
    ("contact scale 1e6", "contact", 1e6, (0, 0, 0)),
    ("contact scale 0.05", "contact", 0.05, (0, 0, 0)),
    ("contact moved 1e5", "contact", 1.0, (1e5, -1e5, 1e5)),
    # a power of two within the frame's identity: every offset and window scales with it,
    # so the image is the same bit for bit
    ("glass scale 4 exact", "glass_texture", 4.0, (0, 0, 0)),
    ("contact scale 1/4 exact", "contact", 0.25, (0, 0, 0)),
]


def stress_cases():
    """make stress: every scene at every decade of scale and at every move."""
    out = []
    for sc in ("glass_texture", "glass_environment", "prism", "contact"):
        for e in range(-6, 7):
            if e:
                out.append((f"{sc} scale 1e{e}", sc, 10.0 ** e, (0, 0, 0)))
        for d in (1e3, 1e4, 1e5):
            for axis, name in enumerate("xyz"):
                move = [0.0, 0.0, 0.0]
                move[axis] = d
                out.append((f"{sc} moved {d:.0e} {name}".replace("e+0", "e"), sc, 1.0,
                            tuple(move)))
            out.append((f"{sc} moved {d:.0e} xyz".replace("e+0", "e"), sc, 1.0, (d, -d, d)))
        out.append((f"{sc} moved uneven", sc, 1.0, UNEVEN))
        out.append((f"{sc} scale 1e-3 moved uneven", sc, 1e-3,
                    tuple(1e-3 * x for x in UNEVEN)))
        out.append((f"{sc} scale 1e3 moved uneven", sc, 1e3, tuple(1e3 * x for x in UNEVEN)))
    return out


def transformed(doc, s, t):
    """The scene doc with every position p -> s p + t and every length times s."""
    doc = copy.deepcopy(doc)

    def p(v):
        return [s * v[i] + t[i] for i in range(3)]

    def times(v, k):
        return [k * x for x in v] if isinstance(v, list) else k * v
    cam = doc["camera"]
    cam["eye"], cam["look_at"] = p(cam["eye"]), p(cam["look_at"])
    for light in doc.get("lights", []):
        light["centre"] = p(light["centre"])
        if "radius" in light:
            light["radius"] *= s
        for key in ("flux", "intensity"):
            if key in light:
                light[key] *= s * s
    for m in doc["materials"].values():
        if "extinction" in m:
            m["extinction"] = times(m["extinction"], 1.0 / s)
        pat = m.get("pattern")
        if pat:
            pat["origin"] = p(pat.get("origin", [0, 0, 0]))
            pat["size"] = times(pat.get("size", 1), s)
    for ob in doc["objects"]:
        xf = ob.get("transform")
        if xf is None and ob["shape"] == "sphere":  # placed by its centre
            ob["centre"] = p(ob.get("centre", [0, 0, 0]))
            ob["radius"] = s * ob.get("radius", 1)
            continue
        xf = xf or {}
        xf["scale"] = times(xf.get("scale", 1), s)
        xf["translate"] = p(xf.get("translate", [0, 0, 0]))
        ob["transform"] = xf
    return doc


def read_pfm(path):
    with open(path, "rb") as f:
        assert f.readline().strip() == b"PF"
        w, h = map(int, f.readline().split())
        s = float(f.readline())
        n = w * h * 3
        data = struct.unpack(("<" if s < 0 else ">") + f"{n}f", f.read(4 * n))
    return w, h, data


def render(vbcl, doc, tmp, tag, grow, options=()):
    doc = copy.deepcopy(doc)
    doc["image"]["width"] *= grow
    doc["image"]["height"] *= grow
    path = os.path.join(tmp, tag + ".json")
    with open(path, "w") as f:
        json.dump(doc, f)
    img, st = os.path.join(tmp, tag + ".pfm"), os.path.join(tmp, tag + ".stats.json")
    r = subprocess.run([vbcl, path, "-q", "-o", img, "--stats-json", st, *options],
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


def work(stats):
    return stats["work"]["cells_visited"] + stats["work"]["triangles_tested"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vbcl", default="build/vbcl")
    ap.add_argument("--only", help="cases whose name this regular expression matches")
    ap.add_argument("--out", help="keep the scenes, images and stats here")
    ap.add_argument("--stress", action="store_true", help="the cases of make stress")
    a = ap.parse_args()
    grow = 1
    tmp = a.out or tempfile.mkdtemp(prefix="vbcl-frame-")
    os.makedirs(tmp, exist_ok=True)
    cases = stress_cases() if a.stress else CASES
    if a.only:
        cases = [c for c in cases if re.search(a.only, c[0])]
    units, failed = {}, 0
    print("| case | RMS | largest difference | counters off (worst) | work / unit | "
          "kernel time / unit |")
    print("|---|---|---|---|---|---|")
    for name, sc, s, move in cases:
        if sc not in units:
            with open(os.path.join(SCENES, sc + ".json")) as f:
                doc = json.load(f)
            opts = SAMPLES[a.stress]
            render(a.vbcl, doc, tmp, sc + "_warm", grow, opts)  # kernels and texture cached
            img, st, err = render(a.vbcl, doc, tmp, sc + "_unit", grow, opts)
            if img is None:
                print(f"frame: the unit scene {sc} failed: {err}")
                return 1
            units[sc] = (doc, img, st)
        doc, unit, ustats = units[sc]
        tag = re.sub(r"[^a-z0-9]+", "_", name)
        img, st, err = render(a.vbcl, transformed(doc, s, move), tmp, tag, grow,
                              SAMPLES[a.stress])
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
        wratio = work(st) / max(work(ustats), 1)
        ratio = st["time_ms"]["kernels"] / max(ustats["time_ms"]["kernels"], 1e-9)
        exact = name.endswith(" exact")
        ok = rms <= RMS_MAX and worst <= DIFF_MAX and off <= COUNT_REL and wratio <= WORK_MAX
        ok = ok and (not exact or (worst == 0 and off == 0))
        failed += not ok
        print(f"| {name} | {rms:.2e} | {worst:.2e} | {off * 100:.2f}% {what} | {wratio:.3f} | "
              f"{ratio:.2f} |")
        print(f"frame: {name}: {'ok' if ok else 'FAILED'}: RMS {rms:.2e} (<= {RMS_MAX:g}), "
              f"largest difference {worst:.2e} (<= {DIFF_MAX:g}), counters within "
              f"{off * 100:.2f}% (<= {COUNT_REL * 100:g}%){': ' + what if what else ''}, "
              f"work {wratio:.3f} of the unit scene's (<= {WORK_MAX:g})"
              f"{'; bit for bit: ' + ('yes' if worst == 0 else 'no') if exact else ''}", flush=True)
    print(f"frame: {len(cases) - failed} of {len(cases)} cases ok")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
