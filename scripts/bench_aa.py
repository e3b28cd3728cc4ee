#!/usr/bin/env python3
"""bench_aa.py — anti-aliasing: run time against error, adaptive (--aa THRESHOLD) and
uniform (--ssaa N) supersampling, each against a converged --ssaa 16 reference of the
same scene (docs/architecture.md, "Measurements").

usage: scripts/bench_aa.py [--quick] [--vbcl ./vbcl] [--out bench-out] [--repeats N]
                          [--scenes NAME,...] [--path-only] [--path-size N]

Writes OUT/aa_time_error.csv (one row per render) and OUT/aa_time_error.png (RMSE against
render time, one panel per scene). Time is the render's wall time from --stats-json (pass 0,
refinement and read-back; not the program build). Error: RMSE over the RGB channels of the
linear image clamped to [0, 1] (what a display shows), and PSNR = 20 log10(1 / RMSE).
The reference is rendered with another render.seed, so that its shadow-feeler jitter is
independent of the images measured (the adaptive mode's level-4 pixels would otherwise
equal it exactly); its subpixel positions are the same 16x16 grid.
Cost per sample: device time of the tracing kernels per camera ray (us), for adaptive
refinement its own batches (aa.refine_ms / rays.refinement), for uniform all of them
(time_ms.kernels / samples.total); and the same per traced ray, camera rays plus their
shadow feelers and ray-tree rays (for refinement: the rays beyond those of the plain render).
Path cost (OUT/aa_path_cost.csv): the same samples through both paths, so that where
adaptive samples lie (the expensive parts of an image) does not enter the comparison: the
quadtree forced to one level everywhere (--aa 1 --aa-min-level L --aa-max-level L, 4^L
samples in every pixel) against --ssaa 2^L, in interleaved rounds; device time per sample of
refinement's tracing batches (aa.refine_ms over the refinement's samples), of all of
refinement (contrast, tracing, split stores and the nearest-sample resolve), and of uniform
supersampling (all its kernels), with per-round ratios, on images of at least 128x128
(PATH_MIN_SIZE; --path-size N renders N x N). "no shares": the quadtree with
--no-sample-shares, whose ray-tree points take the feelers uniform's do. --path-only runs
the path cost alone (OUT/aa_path_cost.csv; no time against error), --repeats N rounds.
--quick renders tiny images (for CI: well under a minute).
"""
import argparse
import csv
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vbcl_stats import read_stats_json  # noqa: E402  (bench.py imports it from here too)


def need_modules():
    try:
        import numpy  # noqa: F401
        import matplotlib  # noqa: F401
    except ImportError:
        # scripts/install-deps.sh installs Debian's python3-numpy and python3-matplotlib for
        # /usr/bin/python3; another python3 first on PATH gets them from PyPI
        print("bench: installing numpy and matplotlib (pip --user)", file=sys.stderr)
        pip = [sys.executable, "-m", "pip", "install", "--user", "--quiet", "numpy", "matplotlib"]
        if subprocess.call(pip) != 0:  # a Debian python3 refuses --user without this
            subprocess.check_call(pip + ["--break-system-packages"])
        import site
        import importlib
        importlib.invalidate_caches()
        site.addsitedir(site.getusersitepackages())


need_modules()
import numpy as np  # noqa: E402
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# scene, label, size, extra options
# glass_bombed_sphere at 128x128, not 64x64, for the reason PATH_MIN_SIZE gives: at 64x64
# its whole refinement at a threshold is a batch or two, whose fixed costs its few samples
# carry (docs/benchmarks.md, "glass_bombed_sphere at 128 x 128").
FULL = [
    ("tests/scenes/aa_edges.json", "aa_edges (flat colours, hard edges)", 128, []),
    ("scenes/quickstart.json", "quickstart (soft shadows)", 128, []),
    ("scenes/glass_bombed_sphere.json", "glass_bombed_sphere (ray trees)", 128,
     ["--shadow-samples", "4"]),
    ("scenes/thesis/a4_two_prisms.json", "a4_two_prisms (thesis A.4, --grid auto)", 100,
     ["--grid", "auto"]),
]
QUICK = [
    ("tests/scenes/aa_edges.json", "aa_edges", 16, []),
    ("scenes/quickstart.json", "quickstart", 16, ["--shadow-samples", "1"]),
]
THRESHOLDS_FULL = [1.0, 0.4, 0.2, 0.1, 0.07, 0.05, 0.03, 0.02]
THRESHOLDS_QUICK = [1.0, 0.4, 0.1, 0.02]
UNIFORM_FULL = [1, 2, 4, 8]
UNIFORM_QUICK = [1, 2, 4]
# A setting whose first render takes longer than this (ms) is not repeated (bench.py's rule).
LONG_RUN_MS = 3000


def read_exr(path):
    """Pixels of an EXR as a float array (h, w, 3), through oiiotool's C dump."""
    text = subprocess.run(["oiiotool", "--dumpdata:C=img", path], check=True,
                          capture_output=True, text=True).stdout
    m = re.search(r"img\[(\d+)\]\[(\d+)\]\[(\d+)\]", text)
    h, w, c = (int(g) for g in m.groups())
    body = re.sub(r"/\*.*?\*/", " ", text[text.index("=", m.end()):], flags=re.S)
    vals = np.array(re.findall(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|nan|inf", body),
                    dtype=np.float64)
    return vals[: h * w * c].reshape(h, w, c)[:, :, :3]


def read_pfm(path):
    """Pixels of a PFM (as vbcl writes it: "PF", little- or big-endian floats, rows bottom
    to top) as a float array (h, w, 3), read with numpy alone."""
    with open(path, "rb") as f:
        data = f.read()
    head = data.split(b"\n", 3)
    if len(head) < 4 or head[0] != b"PF":
        raise ValueError(f"{path}: not an RGB PFM")
    w, h = (int(v) for v in head[1].split())
    order = "<" if float(head[2]) < 0 else ">"
    vals = np.frombuffer(head[3], dtype=order + "f4", count=w * h * 3)
    return vals.reshape(h, w, 3)[::-1].astype(np.float64)


def reseeded(scene):
    """A copy of scene beside it (relative mesh paths still resolve) with another seed."""
    with open(scene) as f:
        data = json.load(f)
    data.setdefault("render", {})["seed"] = 7919
    path = os.path.join(os.path.dirname(scene) or ".", f".bench_aa_ref_{os.getpid()}.json")
    with open(path, "w") as f:
        json.dump(data, f)
    return path


def render(vbcl, scene, size, extra, opts, out, full=False):
    """Renders scene at size x size into out; returns (render wall ms, samples per pixel),
    or with full the whole --stats-json document."""
    st = read_stats_json(vbcl, scene,
                         ["--width", str(size), "--height", str(size), "-o", out] + extra + opts)
    return st if full else (st["time_ms"]["render"], st["samples"]["per_pixel_mean"])


def traced(st):
    """Rays a render traced: camera rays, shadow feelers and ray-tree rays."""
    r = st["rays"]
    return r["total"]


def cost_per_sample(st, plain):
    """(us per camera ray, us per traced ray) of the tracing kernels: for adaptive
    refinement its own batches against the rays beyond the plain render's, for uniform
    supersampling the whole render."""
    if st["aa"]["mode"] == "adaptive":
        n = st["rays"]["refinement"]
        ms = st["aa"]["refine_ms"]
        rays = traced(st) - traced(plain)
    else:
        n = st["samples"]["total"]
        ms = st["time_ms"]["kernels"]
        rays = traced(st)
    if n <= 0 or rays <= 0:
        return "", ""
    return f"{1000.0 * ms / n:.2f}", f"{1000.0 * ms / rays:.3f}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="tiny images, fewer settings (CI)")
    ap.add_argument("--vbcl", default="./vbcl")
    ap.add_argument("--out", default="bench-out")
    ap.add_argument("--scenes", default="", help="only these scenes (file names without .json)")
    ap.add_argument("--repeats", type=int, default=None,
                    help="renders per setting, median time (default 3; --quick 1; "
                         "one for a setting whose first render takes over 3 s)")
    ap.add_argument("--path-only", action="store_true",
                    help="only the path cost (OUT/aa_path_cost.csv), not time against error")
    ap.add_argument("--path-size", type=int, default=0,
                    help=f"the path cost's image side (default: the scene's, at least "
                         f"{PATH_MIN_SIZE})")
    a = ap.parse_args()
    if a.path_size < 0 or (a.repeats is not None and a.repeats < 1):
        ap.error("--path-size and --repeats take a positive number")
    scenes = QUICK if a.quick else FULL
    if a.scenes:
        scenes = [sc for sc in scenes if os.path.splitext(os.path.basename(sc[0]))[0]
                  in a.scenes.split(",")]
    thresholds = THRESHOLDS_QUICK if a.quick else THRESHOLDS_FULL
    uniform = UNIFORM_QUICK if a.quick else UNIFORM_FULL
    repeats = a.repeats or (1 if a.quick else 3)
    os.makedirs(a.out, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for scene, label, size, extra in [] if a.path_only else scenes:
            rows += bench_scene(a, tmp, scene, label, size, extra, thresholds, uniform, repeats)
        path_rows = []
        for scene, label, size, extra in scenes:
            path_rows += path_cost(a, tmp, scene, size, extra, repeats)
    write_csv(os.path.join(a.out, "aa_path_cost.csv"), path_rows)
    if a.path_only:
        print(f"bench_aa: wrote {os.path.join(a.out, 'aa_path_cost.csv')}")
        return
    csv_path = os.path.join(a.out, "aa_time_error.csv")
    write_csv(csv_path, rows, skip=("label",))
    plot(rows, scenes, os.path.join(a.out, "aa_time_error.png"))
    print(f"bench_aa: wrote {csv_path} and {os.path.join(a.out, 'aa_time_error.png')}")


def write_csv(path, rows, skip=()):
    """rows (dicts) as CSV, the first row's keys less skip as the columns."""
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=[k for k in rows[0] if k not in skip],
                           extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)


PATH_LEVELS_FULL = [1, 2]
PATH_LEVELS_QUICK = [1]
# The path cost's smallest image side (not --quick): per-batch costs (kernel launches, the
# ray trees' rounds) are shared by a batch's samples, and a forced 2x2 refinement counts 3
# of a pixel's 4 samples against uniform's 4, so a small image charges the quadtree up to
# 4/3 of them per sample. glass_bombed_sphere at 64x64 is one batch of 12,288 rays there,
# and uniform's own cost per sample was 1.76x its cost at 128x128 (docs/benchmarks.md).
PATH_MIN_SIZE = 128


def path_cost(a, tmp, scene, size, extra, repeats):
    """Rows of the path-cost comparison for one scene (module docstring): per level, the
    medians over interleaved rounds (at least 5; one warm-up round first)."""
    name = os.path.splitext(os.path.basename(scene))[0]
    size = a.path_size or (size if a.quick else max(size, PATH_MIN_SIZE))
    npix = size * size
    out = os.path.join(tmp, "path.exr")
    rows = []
    for level in PATH_LEVELS_QUICK if a.quick else PATH_LEVELS_FULL:
        forced = ["--aa", "1", "--aa-min-level", str(level), "--aa-max-level", str(level)]
        variants = (("uniform", ["--ssaa", str(1 << level)]), ("quadtree", forced),
                    ("quadtree, no shares", forced + ["--no-sample-shares"]))
        got = {v: [] for v, _ in variants}
        rounds = 1 if a.quick else max(repeats, 5)
        for r in range(rounds + (0 if a.quick else 1)):
            for v, opts in variants:
                st = render(a.vbcl, scene, size, extra, opts, out, full=True)
                n, aa = st["samples"]["total"], st["aa"]
                if v == "uniform":
                    trace = whole = st["time_ms"]["kernels"] / n
                else:
                    refined = n - npix
                    trace = aa["refine_ms"] / refined
                    whole = (aa["contrast_ms"] + aa["refine_ms"] + aa["reconstruct_ms"]) / refined
                if r or a.quick:  # the first round warms the kernels up
                    got[v].append((1000.0 * trace, 1000.0 * whole))
        for v, _ in variants[1:]:
            ratio_t = statistics.median([q[0] / u[0] for q, u in zip(got[v], got["uniform"])])
            ratio_w = statistics.median([q[1] / u[1] for q, u in zip(got[v], got["uniform"])])
            row = {"scene": name, "size": f"{size}x{size}", "samples_per_pixel": 1 << (2 * level),
                   "variant": v, "rounds": len(got[v]),
                   "uniform_us_per_sample": f"{statistics.median([u[0] for u in got['uniform']]):.3f}",
                   "tracing_us_per_sample": f"{statistics.median([q[0] for q in got[v]]):.3f}",
                   "tracing_ratio": f"{ratio_t:.3f}",
                   "refinement_us_per_sample": f"{statistics.median([q[1] for q in got[v]]):.3f}",
                   "refinement_ratio": f"{ratio_w:.3f}"}
            rows.append(row)
            print(f"{name:22s} path cost {1 << level}x{1 << level} {v:20s} tracing "
                  f"{row['tracing_ratio']} x uniform, all of refinement "
                  f"{row['refinement_ratio']} x", flush=True)
    return rows


def bench_scene(a, tmp, scene, label, size, extra, thresholds, uniform, repeats):
    """The rows of one scene: its reference, then every setting (median time of repeats)."""
    name = os.path.splitext(os.path.basename(scene))[0]
    ref_path = os.path.join(tmp, name + "_ref.exr")
    # warm the program cache and PoCL's kernels (compiled at their first launch, once per
    # work-group size, which is fixed), then the reference
    for opts in (["--aa", "0.1"], ["--ssaa", "2"]):
        render(a.vbcl, scene, 8, extra, opts, os.path.join(tmp, "warm.exr"))
    plain = render(a.vbcl, scene, size, extra, ["--aa", "0"], os.path.join(tmp, "warm.exr"),
                   full=True)
    ref_scene = reseeded(scene)
    try:
        ref_ms, _ = render(a.vbcl, ref_scene, size, extra, ["--ssaa", "16"], ref_path)
    finally:
        os.remove(ref_scene)
    ref = np.clip(read_exr(ref_path), 0.0, 1.0)
    settings = [("adaptive", t, ["--aa", str(t)]) for t in thresholds]
    # --ssaa 1 is the plain render; "--aa 0" also for scenes with their own render.aa
    settings += [("uniform", n, ["--ssaa", str(n)] + (["--aa", "0"] if n == 1 else []))
                 for n in uniform]
    rows = []
    for method, param, opts in settings:
        out = os.path.join(tmp, "img.exr")
        runs = [render(a.vbcl, scene, size, extra, opts, out, full=True)]
        if runs[0]["time_ms"]["total"] <= LONG_RUN_MS:  # a long setting runs once
            runs += [render(a.vbcl, scene, size, extra, opts, out, full=True)
                     for _ in range(repeats - 1)]
        st = sorted(runs, key=lambda r: r["time_ms"]["render"])[len(runs) // 2]
        spp = st["samples"]["per_pixel_mean"]
        img = np.clip(read_exr(out), 0.0, 1.0)
        rmse = float(np.sqrt(np.mean((img - ref) ** 2)))
        psnr = 20.0 * np.log10(1.0 / rmse) if rmse > 0 else float("inf")
        us_sample, us_ray = cost_per_sample(st, plain)
        row = {"scene": name, "size": f"{size}x{size}", "method": method,
               "param": param, "render_ms": round(float(st["time_ms"]["render"]), 1),
               "samples_per_pixel": spp, "rmse": f"{rmse:.6g}",
               "psnr_db": f"{psnr:.2f}", "us_per_sample": us_sample, "us_per_ray": us_ray,
               "reference_ms": round(ref_ms, 1), "label": label}
        rows.append(row)
        print(f"{name:22s} {method:8s} {param!s:5s} {row['render_ms']:9.1f} ms "
              f"{spp:7.2f} spp  RMSE {rmse:.5f}  PSNR {psnr:6.2f} dB  "
              f"{us_sample or '-':>6s} us/sample", flush=True)
    return rows


def plot(rows, scenes, path):
    cols = min(len(scenes), 2)
    nrows = (len(scenes) + cols - 1) // cols
    fig, axes = plt.subplots(nrows, cols, figsize=(5.2 * cols, 4.4 * nrows), squeeze=False)
    for ax in axes.flat[len(scenes):]:
        ax.set_visible(False)
    for ax, (scene, label, size, _) in zip(axes.flat, scenes):
        name = os.path.splitext(os.path.basename(scene))[0]
        for method, style, fmt in (("adaptive", "o-", "{:g}"), ("uniform", "s--", "{}x{}")):
            rs = [r for r in rows if r["scene"] == name and r["method"] == method]
            xs = [r["render_ms"] / 1000.0 for r in rs]
            ys = [max(float(r["rmse"]), 1e-7) for r in rs]
            ax.plot(xs, ys, style, label=f"{method} ({'threshold' if method == 'adaptive' else 'N x N'})")
            for r, x, y in zip(rs, xs, ys):
                txt = fmt.format(r["param"], r["param"]) if method == "uniform" else fmt.format(r["param"])
                ax.annotate(txt, (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
        ref_ms = next(r["reference_ms"] for r in rows if r["scene"] == name)
        ref_txt = f"\nreference 16x16: {ref_ms / 1000:.1f} s" if ref_ms else ""
        ax.set_title(f"{label}, {size}x{size}{ref_txt}", fontsize=9)
        ax.set_xscale("log")
        ax.set_yscale("log")
        # a decade or less of time: matplotlib labels the minor ticks, and they overlap
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_xlabel("render time (s)")
        ax.set_ylabel("RMSE vs 16x16")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
