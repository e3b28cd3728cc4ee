#!/usr/bin/env python3
"""bench_rays_compare.py — two or more builds of vbcl-bench-rays on the same scenes, run in
interleaved rounds so that machine noise hits every build alike.

BENCH is a vbcl-bench-rays binary, or a directory holding build/vbcl-bench-rays or
vbcl-bench-rays (a checkout or its build folder). Each round runs every build once per
scene (`--width N --height N --repeats R --json`); each run measures vbcl and Embree on the
same rays, so its ratio vbcl / Embree is what is compared. Reports, per scene and ray kind,
each build's median ratio with the range over the rounds, its median vbcl Mrays/s, and the
median ratio of each later build over the first (of the vbcl / Embree medians; of vbcl's
Mrays/s where a build has no Embree). A bench run that fails (the two sides
disagree, bad input) stops the comparison with its messages and exit status 1.
docs/benchmarks.md, "Against Embree".
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile


def bench_path(arg):
    """The vbcl-bench-rays binary ARG names, or exits with a message."""
    for p in (arg, os.path.join(arg, "build", "vbcl-bench-rays"),
              os.path.join(arg, "vbcl-bench-rays")):
        if os.path.isfile(p) and os.access(p, os.X_OK):
            return p
    sys.exit(f"bench_rays_compare: {arg}: no vbcl-bench-rays binary there")


def run(prog, scene, a, repeats, out):
    """One bench run of `repeats` timed repeats: {kind: (ratio or None, vbcl Mrays/s)}."""
    cmd = [prog, scene, "--width", str(a.size), "--height", str(a.size),
           "--repeats", str(repeats), "--json", out]
    if a.grid:
        cmd += ["--grid", a.grid]
    r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        sys.stderr.write(r.stderr)
        sys.exit(f"bench_rays_compare: {' '.join(cmd)} failed (exit {r.returncode})")
    with open(out) as f:
        info = json.load(f)
    return {k["kind"]: (k.get("ratio"), k["vbcl_mrays_s"]) for k in info["kinds"]}


def main():
    ap = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        usage="%(prog)s [options] BENCH BENCH [BENCH ...] -- SCENE [SCENE ...]")
    ap.add_argument("-n", "--rounds", type=int, default=5, help="interleaved rounds (default 5)")
    ap.add_argument("--size", type=int, default=200, help="camera rays per axis (default 200)")
    ap.add_argument("--repeats", type=int, default=9,
                    help="timed repeats within each bench run (default 9)")
    ap.add_argument("--grid", default=None, help="the renderer's grid (default: the scene's)")
    ap.add_argument("benches", nargs="+", metavar="BENCH",
                    help="a vbcl-bench-rays binary, or a checkout or build folder holding one")
    argv = sys.argv[1:]
    cut = argv.index("--") if "--" in argv else len(argv)
    a = ap.parse_args(argv[:cut])
    if cut == len(argv):
        ap.error("separate the builds from the scenes with --")
    scenes = argv[cut + 1:]
    if len(a.benches) < 2 or not scenes:
        ap.error("at least two builds and one scene")
    if a.rounds < 1 or a.size < 1 or not 1 <= a.repeats <= 64:
        ap.error("--rounds and --size at least 1, --repeats 1 to 64")
    progs = [bench_path(b) for b in a.benches]
    for s in scenes:
        if not os.path.isfile(s):
            sys.exit(f"bench_rays_compare: {s}: no such scene file")
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "rays.json")
        for scene in scenes:
            for p in progs:  # warm the kernel caches
                run(p, scene, a, 1, out)
            res = [dict() for _ in progs]
            for _ in range(a.rounds):
                for i, p in enumerate(progs):
                    for kind, v in run(p, scene, a, a.repeats, out).items():
                        res[i].setdefault(kind, []).append(v)
            report(scene, a, progs, res)


def report(scene, a, progs, res):
    """The table of one scene. Without Embree (a bench built without it) the ratio columns
    are empty and builds are compared by vbcl's Mrays/s alone."""
    print(f"\n{scene}, {a.size}x{a.size}, {a.rounds} interleaved rounds of --repeats {a.repeats}"
          f"{', grid ' + a.grid if a.grid else ''}\n")
    print("| kind | build | vbcl / Embree (median) | range | vbcl Mrays/s | / first build |")
    print("|---|---|---|---|---|---|")
    for kind in res[0]:
        embree = all(v[0] is not None for r in res for v in r.get(kind, []))
        col = 0 if embree else 1
        base = statistics.median(v[col] for v in res[0][kind])
        for i, p in enumerate(progs):
            vs = res[i].get(kind, [])
            if not vs:
                continue
            med = statistics.median(v[col] for v in vs)
            mr = statistics.median(v[1] for v in vs)
            rel = f"{med / base:.3f}" if i and base > 0 else ""
            rs = [v[0] for v in vs] if embree else []
            ratio = (f"{statistics.median(rs):.3f} | {min(rs):.3f} – {max(rs):.3f}" if rs
                     else "— | —")
            print(f"| {kind if i == 0 else ''} | {p} | {ratio} | {mr:.3f} | {rel} |")


if __name__ == "__main__":
    main()
