#!/usr/bin/env python3
"""bench.py — `make bench`: the thesis's own measurements and ours, in seven parts.

  1. thesis   the table of thesis section 4.1.5 on the figure A.4 scene: anti-aliasing
              threshold x ray-tree depth x dispersion -> rendering, anti-aliasing and
              dispersion time and the total, beside the thesis's 1995 figures;
  2. grid     throughput (Mrays/s by ray kind) across top-level grid sizes 5^3 .. 128^3,
              the thesis's 20^3 and auto, with sub-grids (two levels) and without (one),
              on scenes from about 100 to 184,000 triangles;
  3. error    run time against error (RMSE and PSNR against a converged reference) for
              anti-aliasing thresholds (scripts/bench_aa.py) and for band counts;
  4. build    kernel build time, cold (empty caches) and warm, per feature set;
  5. embree   Mrays/s per ray kind against Embree 3 on the same triangles and rays
              (build/vbcl-bench-rays, tests/bench/bench_rays.c; vbcl alone without Embree);
  6. drivers  Mrays/s by ray kind on every OpenCL device vbcl sees (PoCL; Intel's CPU
              runtime too after `. "$(scripts/intel-ocl.sh)"`), to pick a driver;
  7. accel    figure A.4 at 400x400 by acceleration structure: the thesis's grid 20 with
              sub-grids, as its one level, auto and auto with one level.

usage: scripts/bench.py [--quick] [--parts thesis,grid,error,build,embree,drivers,accel]
                        [--vbcl ./vbcl] [--out bench-out] [--size N] [--repeats N]
                        [--bench-rays PATH]

Writes OUT/<part>.csv, OUT/<part>.md and, for parts 2 and 3, OUT/<part>.png; OUT/bench.md
collects the markdown tables with the machine and device they were measured on. Times come
from `vbcl --stats-json` (docs/stats.md): device times from OpenCL event profiling, wall
times around the render.
--quick runs every part on tiny images (part of `make test`, so the benchmark cannot rot);
its numbers only show that each part runs.
"""
import argparse
import csv
import json
import os
import platform
import re
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_aa  # noqa: E402  (installs numpy and matplotlib if missing)
from bench_aa import np, plt, read_pfm, read_stats_json  # noqa: E402

A4 = "scenes/thesis/a4_two_prisms.json"

# Thesis section 4.1.5 (seconds, IRIS Indigo, 400x400, grid 20x20x20): threshold, depth,
# dispersion, rendering time, anti-alias time, effect of dispersion, total time.
THESIS_ROWS = [
    (1.0, 6, False, 42.03, 0, None, 81.03),
    (0.8, 6, False, 43.90, 0, None, 82.95),
    (0.6, 6, False, 42.36, 0.1, None, 83.1),
    (0.4, 6, False, 42.68, 5.0, None, 89.17),
    (0.2, 6, False, 42.67, 18.87, None, 102.1),
    (0.1, 6, False, 42.89, 27.19, None, 112.5),
    (0.05, 6, False, 42.64, 44.9, None, 128.54),
    (0.02, 6, False, 42.71, 93.96, None, 174.31),
    (0.6, 7, False, 48.20, 0.12, None, 88.1),
    (0.6, 8, False, 54.05, 0.14, None, 93.19),
    (0.6, 9, False, 62.46, 0.30, None, 101.96),
    (0.6, 10, False, 74.99, 0.34, None, 115.13),  # printed as threshold "0.610"
    (0.02, 6, True, 42.67, 95.23, 430.248, 614.148),
]
THESIS_QUICK = [THESIS_ROWS[0], THESIS_ROWS[5], THESIS_ROWS[8], THESIS_ROWS[12]]

# Part 2: scenes from ~100 to ~184,000 triangles (name, path, extra options).
GRID_SCENES = [
    ("boxes (106 tris)", "scenes/bench/boxes.json", []),
    ("quickstart (6,038 tris)", "scenes/quickstart.json", []),
    ("glass_bombed_sphere (94,724 tris, glass)", "scenes/glass_bombed_sphere.json",
     ["--shadow-samples", "4"]),
    ("spheres36 (184,322 tris)", "scenes/bench/spheres36.json", []),
]
GRID_SIZES = ["5", "8", "16", "20", "32", "64", "128", "auto"]
GRID_SCENES_QUICK = GRID_SCENES[:2]
GRID_SIZES_QUICK = ["5", "16", "auto"]
# The grid's levels: "two" is --grid N (automatic sub-grids), "one" is --grid N:1.
GRID_LEVELS = [("two", ""), ("one", ":1")]

BANDS = [1, 2, 4, 6, 8, 16, 32]
BANDS_QUICK = [1, 4]

# The numbers the parts use, from `vbcl --stats-json` (docs/stats.md): name -> JSON path.
STAT_FIELDS = {
    "build_ms": ("program", "build_ms"),
    "camera_ms": ("time_ms", "camera"),
    "intersect_ms": ("time_ms", "intersect"),
    "shading_ms": ("time_ms", "shading"),
    "tree_ms": ("time_ms", "ray_trees"),
    "dispersion_ms": ("time_ms", "dispersive_subtrees"),
    "render_ms": ("time_ms", "render"),
    "write_ms": ("time_ms", "write"),
    "total_ms": ("time_ms", "total"),
    "aa_contrast_ms": ("aa", "contrast_ms"),
    "aa_refine_ms": ("aa", "refine_ms"),
    "aa_reconstruct_ms": ("aa", "reconstruct_ms"),
    "rays_primary": ("rays", "primary"),
    "rays_refine": ("rays", "refinement"),
    "rays_shadow": ("rays", "shadow"),
    "rays_total": ("rays", "total"),
    "reflected": ("ray_tree", "reflected"),
    "transmitted": ("ray_tree", "transmitted"),
    "band_rays": ("ray_tree", "band_rays"),
    "spp": ("samples", "per_pixel_mean"),
    "triangles": ("scene", "triangles"),
}


def run_stats(vbcl, scene, opts, env=None):
    """Runs vbcl with --stats-json; returns the numbers of STAT_FIELDS, "from" (how the
    program came: binary, source, source_driver_cache) and "grid" ("XxYxZ")."""
    doc = read_stats_json(vbcl, scene, opts, env)
    st = {k: float(doc[g][f]) for k, (g, f) in STAT_FIELDS.items()}
    st["from"] = doc["program"]["from"]
    st["grid"] = "x".join(str(n) for n in doc["grid"]["resolution"])
    return st


# A setting whose first run takes longer than this (ms) is not repeated: its run-to-run
# spread is a small part of it, and repeating the slow settings would take most of the
# full bench's 20 minutes (docs/benchmarks.md).
LONG_RUN_MS = 3000


def median_stats(vbcl, scene, opts, repeats):
    """The run of median total time of `repeats` runs (one when the first is long)."""
    runs = [run_stats(vbcl, scene, opts)]
    if runs[0]["total_ms"] <= LONG_RUN_MS:
        runs += [run_stats(vbcl, scene, opts) for _ in range(repeats - 1)]
    runs.sort(key=lambda s: s["total_ms"])
    return runs[len(runs) // 2]


def write_table(out, name, rows, fields, title, note=""):
    with open(os.path.join(out, name + ".csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    lines = [f"### {title}", ""]
    if note:
        lines += [note, ""]
    lines.append("| " + " | ".join(fields) + " |")
    lines.append("|" + "---|" * len(fields))
    for r in rows:
        lines.append("| " + " | ".join(str(r.get(k, "")) for k in fields) + " |")
    text = "\n".join(lines) + "\n"
    with open(os.path.join(out, name + ".md"), "w") as f:
        f.write(text)
    print(text, flush=True)
    return text


def with_dispersion(scene):
    """The scene with the thesis's dispersion on every dielectric (eq. 16-17, its rays)."""
    with open(scene) as f:
        data = json.load(f)
    for m in data["materials"].values():
        if m.get("k_global", 0) > 0:
            m["dispersion"] = {"model": "thesis", "spread": 0.03}
    data.setdefault("render", {})["bands"] = "thesis"
    path = os.path.join(os.path.dirname(scene), f".bench_disp_{os.getpid()}.json")
    with open(path, "w") as f:
        json.dump(data, f)
    return path


def part_thesis(a, out):
    rows_in = THESIS_QUICK if a.quick else THESIS_ROWS
    size = a.size or (12 if a.quick else 400)
    # --quick: one feeler per light and two refinement levels, so that it takes seconds
    quick = ["--shadow-samples", "1", "--aa-max-level", "2"] if a.quick else []
    # one run per row unless --repeats says otherwise: the rows take 2 s to minutes each, and
    # the 13 of them once take most of the full bench's budget (docs/benchmarks.md)
    reps = a.repeats_given or 1
    disp_scene = with_dispersion(A4)
    rows = []
    try:
        for thr, depth, disp, t_render, t_aa, t_disp, t_total in rows_in:
            scene = disp_scene if disp else A4
            opts = ["--width", str(size), "--height", str(size), "--aa", str(thr),
                    "--depth", str(depth), "-o", os.path.join(a.tmp, "thesis.pfm")] + quick
            # a deeper tree or dispersion is another program: build it (and let PoCL compile
            # its kernels) first, so that no row includes a cold build: on a tiny image with
            # the row's anti-aliasing, then unrefined at the row's size (PoCL compiles a
            # kernel again for each work-group size it is launched with)
            for warm in (["--width", "8", "--height", "8", "--aa", str(thr)],
                         ["--width", str(size), "--height", str(size), "--aa", "0"]):
                run_stats(a.vbcl, scene, warm + ["--depth", str(depth), "-o",
                                                 os.path.join(a.tmp, "warm.pfm")])
            st = median_stats(a.vbcl, scene, opts, reps)
            aa = st["aa_contrast_ms"] + st["aa_refine_ms"] + st["aa_reconstruct_ms"]
            rows.append({
                "threshold": thr, "depth": depth, "dispersion": "on" if disp else "off",
                "render_s": f"{(st['render_ms'] - aa) / 1000:.2f}",
                "aa_s": f"{aa / 1000:.2f}",
                "dispersion_s": f"{st['dispersion_ms'] / 1000:.2f}" if disp else "N/A",
                "total_s": f"{st['total_ms'] / 1000:.2f}",
                "spp": f"{st['spp']:.2f}",
                "thesis_render_s": t_render, "thesis_aa_s": t_aa,
                "thesis_dispersion_s": "N/A" if t_disp is None else t_disp,
                "thesis_total_s": t_total,
                "speedup": f"{t_total / (st['total_ms'] / 1000):.1f}",
            })
            print(f"thesis: {thr} depth {depth} disp {disp}: {rows[-1]}", flush=True)
    finally:
        os.remove(disp_scene)
    fields = ["threshold", "depth", "dispersion", "render_s", "aa_s", "dispersion_s", "total_s",
              "spp", "thesis_render_s", "thesis_aa_s", "thesis_dispersion_s", "thesis_total_s",
              "speedup"]
    note = (f"`{A4}` at {size}x{size} (the thesis: 400x400), grid 20 as in the thesis, "
            f"{'median of ' + str(reps) if reps > 1 else 'one run per row'}. render_s: the render's wall time less the anti-aliasing "
            "stages' device time; aa_s: contrast, refinement and reconstruction (device); "
            "dispersion_s: the band launch of tree_trace_secondary, the dispersive subtrees (device, inside render_s "
            "and aa_s); total_s: the whole run (scene, grid, warm program, render, write). "
            "thesis_*: section 4.1.5, seconds on an SGI IRIS Indigo (1995); speedup: "
            "thesis_total_s / total_s.")
    return write_table(out, "thesis_table", rows, fields, "Thesis section 4.1.5 on figure A.4",
                       note)


def kernel_ms(st):
    """Device time of the tracing kernels: intersect, shading, ray trees, dispersion."""
    return st["intersect_ms"] + st["shading_ms"] + st["tree_ms"] + st["dispersion_ms"]


def throughput(st):
    """Mrays/s of the stages every throughput table shows: primary (camera rays over the
    intersect kernel), secondary (reflected and transmitted rays over the ray-tree kernel),
    all (every ray over the tracing kernels), and those kernels' time."""
    kern = kernel_ms(st)
    secondary = st["reflected"] + st["transmitted"]
    return {
        "primary_mrays_s": f"{st['rays_primary'] / (st['intersect_ms'] * 1e3):.2f}",
        "secondary_mrays_s": (f"{secondary / (st['tree_ms'] * 1e3):.3f}"
                              if st["tree_ms"] > 0 else ""),
        "all_mrays_s": f"{st['rays_total'] / (kern * 1e3):.2f}",
        "kernel_ms": f"{kern:.1f}",
    }


def grid_row(label, g, levels, st):
    """One row of the grid part from the median stats of one (scene, grid, levels)."""
    shading = st["shading_ms"] + st["tree_ms"]
    return dict(throughput(st), **{
        "scene": label, "triangles": int(st["triangles"]), "grid": g, "levels": levels,
        "cells": st["grid"],
        "shading_mrays_s": (f"{(st['rays_primary'] + st['rays_shadow']) / (shading * 1e3):.2f}"
                            if st["shading_ms"] > 0 else ""),
    })


def part_grid(a, out):
    scenes = GRID_SCENES_QUICK if a.quick else GRID_SCENES
    sizes = GRID_SIZES_QUICK if a.quick else GRID_SIZES
    size = a.size or (16 if a.quick else 128)
    rows = []
    for label, scene, extra in scenes:
        run_stats(a.vbcl, scene, ["--width", "8", "--height", "8"] + extra)  # warm
        for g in sizes:
            for levels, suffix in GRID_LEVELS:
                opts = ["--width", str(size), "--height", str(size), "--grid", g + suffix,
                        "--no-camera-tiles", "-o", os.path.join(a.tmp, "grid.pfm")] + extra
                row = grid_row(label, g, levels, median_stats(a.vbcl, scene, opts, a.repeats))
                rows.append(row)
                print(f"grid: {row}", flush=True)
    fields = ["scene", "triangles", "grid", "levels", "cells", "primary_mrays_s",
              "shading_mrays_s", "secondary_mrays_s", "all_mrays_s", "kernel_ms"]
    note = (f"{size}x{size}, median of {a.repeats} (one run where it takes over "
            f"{LONG_RUN_MS / 1000:g} s). grid: the top level (`--grid N`); levels: "
            "two = with automatic sub-grids in crowded top cells, one = `--grid N:1`; 20 is the "
            "thesis's grid (marked in the plot). primary: "
            "camera rays over the intersect "
            "kernel's time (walking the grid: `--no-camera-tiles`); shading: primary rays plus all shadow feelers over the shading and "
            "ray-tree kernels' time; secondary: reflected and transmitted rays over the "
            "ray-tree kernel's time (which also traces their feelers); all: every ray over "
            "all tracing kernels' time.")
    text = write_table(out, "grid_throughput", rows, fields,
                       "Throughput across grid sizes", note)
    fig, axes = plt.subplots(1, len(scenes), figsize=(4.2 * len(scenes), 3.8), squeeze=False)
    for ax, (label, _, _) in zip(axes[0], scenes):
        for levels, style in (("two", "o-"), ("one", "s--")):
            rs = [r for r in rows if r["scene"] == label and r["levels"] == levels]
            xs = list(range(len(rs)))
            ax.plot(xs, [float(r["all_mrays_s"]) for r in rs], style,
                    label=f"all rays, {levels} level{'s' if levels == 'two' else ''}")
        ax.set_xticks(xs)
        ax.set_xticklabels([r["grid"] for r in rs], fontsize=8)
        if "20" in [r["grid"] for r in rs]:  # the thesis's grid
            ax.axvline([r["grid"] for r in rs].index("20"), color="0.6", lw=0.8, ls=":")
            ax.annotate("thesis", ([r["grid"] for r in rs].index("20"), 0.02),
                        xycoords=("data", "axes fraction"), fontsize=7, color="0.4",
                        xytext=(2, 0), textcoords="offset points")
        ax.set_xlabel("top-level grid (cells per axis)")
        ax.set_ylabel("Mrays/s")
        ax.set_yscale("log")
        ax.set_title(label, fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "grid_throughput.png"), dpi=110)
    return text


def part_error(a, out):
    # anti-aliasing thresholds: bench_aa.py as it is
    cmd = [sys.executable, os.path.join(os.path.dirname(__file__), "bench_aa.py"),
           "--vbcl", a.vbcl, "--out", out, "--repeats", str(a.repeats)]
    subprocess.run(cmd + (["--quick"] if a.quick else []), check=True)
    # band counts: prism_dispersion against 64 bands
    scene = "scenes/prism_dispersion.json"
    w, h = (16, 12) if a.quick else (240, 160)
    ref_bands = 16 if a.quick else 64
    ref_path = os.path.join(a.tmp, "bands_ref.pfm")
    base = ["--width", str(w), "--height", str(h)]
    ref_st = run_stats(a.vbcl, scene, base + ["--bands", str(ref_bands), "-o", ref_path])
    ref = np.clip(read_pfm(ref_path), 0.0, 1.0)
    rows = []
    for nb in (BANDS_QUICK if a.quick else BANDS) + ["thesis"]:
        img_path = os.path.join(a.tmp, "bands.pfm")
        opts = base + ["--bands", str(nb), "-o", img_path]
        run_stats(a.vbcl, scene, opts)  # builds this band count's stack size class
        st = median_stats(a.vbcl, scene, opts, a.repeats)
        img = np.clip(read_pfm(img_path), 0.0, 1.0)
        rmse = float(np.sqrt(np.mean((img - ref) ** 2)))
        rows.append({"bands": nb, "render_ms": f"{st['render_ms']:.1f}",
                     "dispersion_ms": f"{st['dispersion_ms']:.1f}",
                     "band_rays": int(st["band_rays"]), "rmse": f"{rmse:.5f}",
                     "psnr_db": f"{20 * np.log10(1 / rmse):.2f}" if rmse > 0 else "inf"})
        print(f"bands: {rows[-1]}", flush=True)
    note = (f"`{scene}` at {w}x{h} against {ref_bands} bands ({ref_st['render_ms'] / 1000:.1f} s), "
            f"linear RGB clamped to [0, 1], median of {a.repeats} (one run where it takes "
            f"over {LONG_RUN_MS / 1000:g} s); render_ms is the render's "
            "wall time, dispersion_ms the dispersive subtrees' device time. \"thesis\": the "
            "thesis's 1 red, 2 green, 3 blue rays (pure primaries, not CIE weights).")
    text = write_table(out, "bands_time_error", rows,
                       ["bands", "render_ms", "dispersion_ms", "band_rays", "rmse", "psnr_db"],
                       "Run time against error: band counts", note)
    fig, ax = plt.subplots(figsize=(5.2, 4.2))
    for r in rows:
        x, y = float(r["render_ms"]) / 1000, max(float(r["rmse"]), 1e-7)
        ax.plot([x], [y], "o", color="C1" if r["bands"] == "thesis" else "C0")
        ax.annotate(str(r["bands"]), (x, y), textcoords="offset points", xytext=(4, 4),
                    fontsize=8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("render time (s)")
    ax.set_ylabel(f"RMSE vs {ref_bands} bands")
    ax.set_title(f"prism_dispersion {w}x{h}: bands", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "bands_time_error.png"), dpi=110)
    with open(os.path.join(out, "aa_time_error.csv")) as f:
        aa_rows = list(csv.DictReader(f))
    aa_text = write_table(out, "aa_time_error", aa_rows,
                          ["scene", "size", "method", "param", "render_ms",
                           "samples_per_pixel", "rmse", "psnr_db", "us_per_sample", "us_per_ray"],
                          "Run time against error: anti-aliasing",
                          "Against `--ssaa 16` of the same scene with another seed "
                          "(scripts/bench_aa.py).")
    with open(os.path.join(out, "aa_path_cost.csv")) as f:
        path_rows = list(csv.DictReader(f))
    path_text = write_table(out, "aa_path_cost", path_rows,
                            ["scene", "size", "samples_per_pixel", "variant", "rounds",
                             "uniform_us_per_sample", "tracing_us_per_sample", "tracing_ratio",
                             "refinement_us_per_sample", "refinement_ratio"],
                            "Per sample: refinement against uniform supersampling",
                            "The same samples through both paths: the quadtree forced to one "
                            "level in every pixel (`--aa 1 --aa-min-level L --aa-max-level L`) "
                            "against `--ssaa 2^L`, interleaved rounds, medians; ratios are "
                            "medians of per-round ratios. Tracing: refinement's batches "
                            "(aa.refine_ms) per refined sample; refinement: with the contrast "
                            "passes, split stores and nearest-sample resolve; uniform: all its "
                            "kernels per sample (scripts/bench_aa.py).")
    return aa_text + "\n" + path_text + "\n" + text


# Part 7: figure A.4 by acceleration structure (--grid), at the thesis's 400x400: the
# thesis's grid 20 with sub-grids (the default), as the thesis's one level (20:1), auto and
# auto without sub-grids; each unrefined (threshold 1.0, the table's first row) and the
# two-level ones also at the figure's own threshold 0.1.
ACCEL_GRIDS = [("20", "two levels (default)"), ("20:1", "one level, as the thesis"),
               ("auto", "two levels"), ("auto:1", "one level")]


def part_accel(a, out):
    size = a.size or (12 if a.quick else 400)
    quick = ["--shadow-samples", "1", "--aa-max-level", "2"] if a.quick else []
    rows = []
    # the grid is data, not code: one program serves every row; build it and compile its
    # kernels (anti-aliasing's too) once
    run_stats(a.vbcl, A4, ["--width", "8", "--height", "8", "--aa", "0.1", "-o",
                           os.path.join(a.tmp, "warm.pfm")])
    for thr in (1.0, 0.1):
        for g, label in ACCEL_GRIDS:
            if thr != 1.0 and g.endswith(":1"):
                continue
            opts = ["--width", str(size), "--height", str(size), "--aa", str(thr), "--grid", g,
                    "-o", os.path.join(a.tmp, "accel.pfm")] + quick
            st = median_stats(a.vbcl, A4, opts, a.repeats)
            kern = kernel_ms(st)
            rows.append({"threshold": thr, "grid": g, "structure": label, "cells": st["grid"],
                         "total_s": f"{st['total_ms'] / 1000:.2f}",
                         "render_s": f"{st['render_ms'] / 1000:.2f}",
                         "rays": int(st["rays_total"]),
                         "mrays_s": f"{st['rays_total'] / (st['render_ms'] * 1e3):.2f}",
                         "kernel_s": f"{kern / 1000:.2f}"})
            print(f"accel: {rows[-1]}", flush=True)
    for r in rows:  # each against the default (grid 20, two levels) at its threshold
        base = next(b for b in rows if b["threshold"] == r["threshold"] and b["grid"] == "20")
        r["vs_default"] = f"{float(r['total_s']) / float(base['total_s']):.2f}"
    note = (f"`{A4}` at {size}x{size}, median of {a.repeats} (one run where it takes over "
            f"{LONG_RUN_MS / 1000:g} s). total_s: the whole run; render_s: the render's wall "
            "time; mrays_s: every ray over render_s; kernel_s: the tracing kernels' device "
            "time (every pass); vs_default: total_s against grid 20 with sub-grids at the "
            "same threshold.")
    return write_table(out, "accel", rows,
                       ["threshold", "grid", "structure", "cells", "total_s", "render_s", "rays",
                        "mrays_s", "kernel_s", "vs_default"],
                       "Figure A.4 by acceleration structure", note)


def part_build(a, out):
    scenes = [("opaque (quickstart)", "scenes/quickstart.json"),
              ("glass and textures (glass_bombed_sphere)", "scenes/glass_bombed_sphere.json"),
              ("dispersion (prism_dispersion)", "scenes/prism_dispersion.json")]
    if a.quick:
        scenes = scenes[:1]
    rows = []
    # one cold and one warm run per scene unless --repeats says otherwise: a cold build
    # takes 10 - 20 s here, and its spread is a small part of it
    for label, scene in scenes:
        for k in range(a.repeats_given or 1):
            with tempfile.TemporaryDirectory() as cache:
                # both caches empty: vbcl's program binaries and PoCL's compiled kernels
                # (--quick, a check that the part runs: PoCL's cache kept, no compile)
                env = dict(os.environ, VBCL_CACHE_DIR=cache)
                if not a.quick:
                    env["POCL_CACHE_DIR"] = cache + "/pocl"
                opts = ["--width", "8", "--height", "8", "-o", os.path.join(a.tmp, "b.png")]
                t0 = time.time()
                cold = run_stats(a.vbcl, scene, opts, env)
                cold_wall = time.time() - t0
                t0 = time.time()
                warm = run_stats(a.vbcl, scene, opts, env)
                warm_wall = time.time() - t0
            rows.append({"features": label, "run": k + 1,
                         "cold_build_ms": f"{cold['build_ms']:.1f}",
                         "cold_first_render_ms": f"{cold['render_ms']:.1f}",
                         "cold_process_s": f"{cold_wall:.2f}",
                         "warm_build_ms": f"{warm['build_ms']:.1f}",
                         "warm_first_render_ms": f"{warm['render_ms']:.1f}",
                         "warm_process_s": f"{warm_wall:.2f}"})
            print(f"build: {rows[-1]}", flush=True)
    note = ("An 8x8 render with empty caches (cold: clBuildProgram from source; PoCL's own "
            "kernel cache, POCL_CACHE_DIR, emptied too), then again with the caches the first "
            "run filled (warm: clCreateProgramWithBinary from vbcl's cache, or on PoCL, where "
            "vbcl stores no binary, clBuildProgram served by PoCL's kernel cache). "
            "build_ms includes each kernel's first launch on no work, where PoCL compiles its "
            "work-group function; first_render_ms: the render's wall time; process_s: the "
            "whole command (texture generation comes from its own cache in both)." +
            (" --quick keeps PoCL's kernel cache, so its cold run compiles nothing there."
             if a.quick else ""))
    return write_table(out, "build_time", rows,
                       ["features", "run", "cold_build_ms", "cold_first_render_ms",
                        "cold_process_s", "warm_build_ms", "warm_first_render_ms",
                        "warm_process_s"],
                       "Kernel build time, cold and warm", note)


def list_devices(vbcl, env=None):
    """(index, "platform / device") of every OpenCL device vbcl sees."""
    text = subprocess.run([vbcl, "--list-devices"], capture_output=True, text=True,
                          env=env).stdout
    return [(int(m.group(1)), m.group(2)) for m in re.finditer(r"^(\d+): (.*)$", text, re.M)]


def part_drivers(a, out):
    """Mrays/s by ray kind on every OpenCL device this process sees (with Intel's runtime
    after `. "$(scripts/intel-ocl.sh)"`), so a user can see which driver to pick."""
    scenes = [("quickstart (opaque)", "scenes/quickstart.json", []),
              ("glass_bombed_sphere (glass)", "scenes/glass_bombed_sphere.json",
               ["--shadow-samples", "4"])]
    if a.quick:
        scenes = scenes[:1]
    size = a.size or (16 if a.quick else 160)
    rows = []
    devices = list_devices(a.vbcl)
    for label, scene, extra in scenes:
        runs = {index: [] for index, _ in devices}
        for index, _ in devices:  # warm each device's program cache
            run_stats(a.vbcl, scene, ["--width", "8", "--height", "8", "--device", str(index),
                                      "-o", os.path.join(a.tmp, "drivers.pfm")] + extra)
        for _ in range(a.repeats):  # the devices interleaved, repeat by repeat
            for index, _ in devices:
                opts = ["--width", str(size), "--height", str(size), "--device", str(index),
                        "-o", os.path.join(a.tmp, "drivers.pfm")] + extra
                runs[index].append(run_stats(a.vbcl, scene, opts))
        for index, name in devices:
            rs = sorted(runs[index], key=lambda r: r["total_ms"])
            st = rs[len(rs) // 2]
            rows.append(dict(throughput(st), **{
                "device": f"{index}: {name}", "scene": label,
                "shadow_mrays_s": (f"{st['rays_shadow'] / (st['shading_ms'] * 1e3):.2f}"
                                   if st["shading_ms"] > 0 else ""),
            }))
            print(f"drivers: {rows[-1]}", flush=True)
    note = (f"{size}x{size}, median of {a.repeats} (the devices interleaved), every device "
            "`vbcl --list-devices` shows (Intel's CPU runtime too after `. \"$(scripts/intel-ocl.sh)\"`). primary: camera "
            "rays over the intersect kernel's time; shadow: feelers over the shading kernel's "
            "time (which also shades the first hits); secondary: reflected and transmitted rays "
            "over the ray-tree kernel's time (which also traces their feelers); all: every ray "
            "over all tracing kernels' time.")
    return write_table(out, "drivers", rows,
                       ["device", "scene", "primary_mrays_s", "shadow_mrays_s",
                        "secondary_mrays_s", "all_mrays_s", "kernel_ms"],
                       "Throughput per OpenCL device", note)


# Part 5: scenes traced by vbcl and Embree; each with --grid auto and, where it has one, the
# scene's own grid (label, path).
EMBREE_SCENES = [
    ("A.4 two prisms", A4),
    ("glass_bombed_sphere", "scenes/glass_bombed_sphere.json"),
    ("spheres36", "scenes/bench/spheres36.json"),
]


def part_embree(a, out):
    prog = a.bench_rays or next(
        (p for p in (os.path.join(os.path.dirname(a.vbcl) or ".", "vbcl-bench-rays"),
                     "build/vbcl-bench-rays") if os.path.exists(p)), None)
    title = "Against Embree: Mrays/s per ray kind on the same triangles and rays"
    if not prog:
        text = f"### {title}\n\nskipped: build/vbcl-bench-rays not built (make bench builds it)\n"
        print(text, flush=True)
        return text
    size = a.size or (16 if a.quick else 200)
    reps = a.repeats_given or (1 if a.quick else 5)
    rows, info = [], None
    for label, scene in EMBREE_SCENES:
        with open(scene) as f:
            own = json.load(f).get("render", {}).get("grid")
        grids = ([] if own is None else [None]) + ["auto"]
        for g in grids:
            path = os.path.join(a.tmp, "rays.json")
            cmd = [prog, scene, "--width", str(size), "--height", str(size),
                   "--repeats", str(reps), "--json", path]
            cmd += ["--grid", g] if g else []
            cmd += ["--shadow-samples", "4"] if a.quick else []
            subprocess.run(cmd, check=True)  # fails when the two sides disagree
            with open(path) as f:
                info = json.load(f)
            grid = g or f"{own} (scene)"
            for k in info["kinds"]:
                emb = "embree_mrays_s" in k
                rows.append({
                    "scene": label, "triangles": info["triangles"], "grid": grid,
                    "cells": info["cells"], "kind": k["kind"], "rays": k["rays"],
                    "vbcl_mrays_s": f"{k['vbcl_mrays_s']:.3f}" if k["rays"] else "",
                    "embree_mrays_s": f"{k['embree_mrays_s']:.3f}" if emb else "",
                    "vbcl/embree": f"{k['ratio']:.3f}" if emb else "",
                    "vbcl_any_mrays_s": (f"{k['vbcl_any_mrays_s']:.3f}"
                                         if "vbcl_any_mrays_s" in k and k["rays"] else ""),
                    "agreement": f"{100 * k['agreement']:.3f}%" if emb else "",
                })
    note = (f"{size}x{size} camera rays, the scenes' feelers per point"
            f"{' (4 with --quick)' if a.quick else ''}, median of {reps} interleaved repeats. "
            f"vbcl: OpenCL event time of probe kernels running the renderer's own functions on "
            f"{info['device']}; Embree: {info['embree']}, single-ray API"
            f"{', RTC_SCENE_FLAG_ROBUST' if info['robust'] else ''}, {info['threads']} threads, "
            "wall time, BVH build excluded. Kinds: primary (camera rays, closest hit); shadow "
            "(feelers from opaque primary hits whose feelers meet no dielectric: the renderer's "
            "light_shade_local against rtcOccluded1); shadow_glass (the other opaque primary hits' "
            "feelers: light_shade_local against as many rtcIntersect1 from crossing to crossing as "
            "the renderer's walk makes); secondary (reflected and transmitted rays from primary "
            "hits on dielectrics, closest hit; vbcl as its ray trees trace them, among the objects "
            "each can meet). vbcl_any: the shadow feelers by scene_trace_any "
            "alone. agreement: rays on which both sides agree on hit or miss and the distance "
            "(1e-4 relative).")
    return write_table(out, "embree", rows,
                       ["scene", "triangles", "grid", "cells", "kind", "rays", "vbcl_mrays_s",
                        "embree_mrays_s", "vbcl/embree", "vbcl_any_mrays_s", "agreement"],
                       title, note)


def machine(vbcl):
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            m = re.search(r"^model name\s*:\s*(.*)$", f.read(), re.M)
            cpu = m.group(1) if m else cpu
    except OSError:
        pass
    dev = subprocess.run([vbcl, "--list-devices"], capture_output=True, text=True).stdout
    return f"{cpu}, {os.cpu_count()} logical CPUs; OpenCL devices:\n\n```\n{dev.strip()}\n```\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="tiny sizes: every part runs (CI)")
    ap.add_argument("--parts", default="thesis,grid,error,build,embree,drivers,accel")
    ap.add_argument("--vbcl", default="./vbcl")
    ap.add_argument("--out", default="bench-out")
    ap.add_argument("--size", type=int, default=0, help="image size of parts 1 and 2")
    ap.add_argument("--repeats", type=int, default=None,
                    help="runs per setting, median (default 3; --quick 1)")
    ap.add_argument("--bench-rays", default=None,
                    help="the part embree's program (default: beside --vbcl, else build/)")
    a = ap.parse_args()
    a.repeats_given = a.repeats
    a.repeats = a.repeats or (1 if a.quick else 3)
    os.makedirs(a.out, exist_ok=True)
    parts = {"thesis": part_thesis, "grid": part_grid, "error": part_error, "build": part_build,
             "accel": part_accel,
             "embree": part_embree, "drivers": part_drivers}
    chosen = [p.strip() for p in a.parts.split(",") if p.strip()]
    for p in chosen:
        if p not in parts:
            ap.error(f"--parts: unknown part {p!r} ({', '.join(parts)})")
    report = [f"# vbcl benchmarks{' (--quick)' if a.quick else ''}", "",
              f"Measured {time.strftime('%Y-%m-%d')} on {machine(a.vbcl)}"]
    t_start = time.time()
    with tempfile.TemporaryDirectory() as tmp:
        a.tmp = tmp
        for p in chosen:
            t0 = time.time()
            report.append(parts[p](a, a.out))
            report.append(f"*Part {p}: {time.time() - t0:.0f} s.*\n")
            print(f"bench: part {p} took {time.time() - t0:.0f} s", flush=True)
    report.append(f"*All parts: {time.time() - t_start:.0f} s ({(time.time() - t_start) / 60:.1f} "
                  "minutes).*\n")
    with open(os.path.join(a.out, "bench.md"), "w") as f:
        f.write("\n".join(report))
    print(f"bench: wrote {a.out}/bench.md and the CSV, markdown and PNG files beside it "
          f"({time.time() - t_start:.0f} s)")


if __name__ == "__main__":
    main()
