#!/usr/bin/env python3
"""bench_mpi.py — 1 against 2 MPI ranks (docs/scaling.md), interleaved in one run.

usage: scripts/bench_mpi.py [--vbcl ./vbcl] [--repeats 3] [--threads 1]

Each rank stands for a node: PoCL is held to --threads host threads per rank
(POCL_MAX_PTHREAD_COUNT), so that two ranks on this machine use as many cores as two
one-core nodes would. Runs, alternating np=1 and np=2 --repeats times:
  still      scenes/quickstart.json at 400x400 (tiles over ranks): the render's wall time
             (--stats-json time_ms.render, on rank 0) and the whole mpirun's;
  animation  frames 0-3 of scenes/thesis/a6_eta_animation.json at 128x128 (the frame
             queue): the whole mpirun's wall time.
Prints the medians and the speedup (np=1 time / np=2 time), and for the still image the
tiles and pixels each rank traced, from which the bytes it sent follow (docs/scaling.md).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time


def mpirun(np_, args, env):
    root = ["--allow-run-as-root"] if os.geteuid() == 0 else []
    cmd = ["mpirun"] + root + ["--oversubscribe", "-np", str(np_)] + args
    t0 = time.time()
    r = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)}: exit {r.returncode}: {r.stderr[-2000:]}")
    return time.time() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vbcl", default="./vbcl")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--threads", type=int, default=1, help="PoCL threads per rank")
    a = ap.parse_args()
    env = dict(os.environ, POCL_MAX_PTHREAD_COUNT=str(a.threads))
    vbcl = os.path.abspath(a.vbcl)
    res = {(k, n): [] for k in ("still", "still_render", "animation") for n in (1, 2)}
    last = {}
    with tempfile.TemporaryDirectory() as tmp:
        # warm the kernel cache once
        subprocess.run([vbcl, "scenes/quickstart.json", "-q", "--width", "16", "--height", "16",
                        "-o", f"{tmp}/w.png"], check=True, env=env)
        subprocess.run([vbcl, "scenes/thesis/a6_eta_animation.json", "-q", "--frames", "0",
                        "--width", "16", "--height", "16", "-o", f"{tmp}/w_#.png"], check=True,
                       env=env)
        for rep in range(a.repeats):
            for n in (1, 2):
                js = f"{tmp}/still{n}.json"
                wall = mpirun(n, [vbcl, "scenes/quickstart.json", "-q", "-o", f"{tmp}/s.exr",
                                  "--stats-json", js], env)
                doc = json.load(open(js))
                res[("still", n)].append(wall)
                res[("still_render", n)].append(doc["time_ms"]["render"] / 1000.0)
                last[n] = doc
                wall = mpirun(n, [vbcl, "scenes/thesis/a6_eta_animation.json", "-q", "--frames",
                                  "0:3", "--width", "128", "--height", "128",
                                  "-o", f"{tmp}/a_##.exr"], env)
                res[("animation", n)].append(wall)
                print(f"repeat {rep + 1}, np={n}: still render "
                      f"{res[('still_render', n)][-1]:.2f} s (mpirun {res[('still', n)][-1]:.2f} s), "
                      f"animation {wall:.2f} s", flush=True)
    for k, label in (("still_render", "still image, render (rank 0's time_ms.render)"),
                     ("still", "still image, whole mpirun"),
                     ("animation", "animation, 4 frames, whole mpirun")):
        m1, m2 = statistics.median(res[(k, 1)]), statistics.median(res[(k, 2)])
        print(f"{label}: np=1 {m1:.2f} s, np=2 {m2:.2f} s, speedup {m1 / m2:.2f}")
    doc = last[2]
    tile = doc["tiles"]["max_pixels"]
    for d in doc["devices"]:
        print(f"still, np=2: rank {d['rank']} traced {d['tiles']} tiles of up to {tile} pixels, "
              f"{d['rays']} rays, busy {d['busy_ms']:.0f} ms")


if __name__ == "__main__":
    main()
