#!/usr/bin/env python3
"""gallery.py — `make gallery`: the thesis's appendix figures A.1 … A.8 rendered at their
own settings (scenes/thesis/*.json: 400x400, grid 20, the figure's feelers, depth,
anti-aliasing and dispersion), with each render's measured time, samples per pixel and
rays, into PNG files and a markdown table that the README's gallery is made from.

usage: scripts/gallery.py [--vbcl ./vbcl] [--out docs/images/thesis] [--readme README.md]
                          [--size N] [--scenes a1,a4,...]
Writes OUT/<scene>.png (A.6: OUT/a6_eta_animation.png, its 8 frames as a 4x2 mosaic at
half size), OUT/gallery.json (the numbers) and
OUT/gallery.md (the table). With --readme, the table replaces the part of that file between
the lines "<!-- gallery begin -->" and "<!-- gallery end -->". --size N renders at NxN
instead of the scenes' own size (a quick check that the script runs; not for the README).
Every figure is rendered alone, one after another, so the times are the machine's whole;
each is first rendered with one shadow feeler per point so that its time does not include
building its program.
"""
import argparse
import json
import os
import platform
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vbcl_stats import read_stats_json  # noqa: E402

# The appendix, in the thesis's order: scene file, figure, caption (the thesis's own
# words, shortened where it repeats itself), and what the thesis says of its time.
FIGURES = [
    ("a1_deformed_texture", "A.1", "A texture generated with deformed projection (one circle, "
     "2,500 triangles)", ""),
    ("a2_marble", "A.2", "A marble: the previous texture mapped onto a sphere of index 1.501, "
     "volume based rendered", ""),
    ("a3_wood", "A.3", "A wood textured object: deformed projection with 15 embedded circles",
     ""),
    ("a4_two_prisms", "A.4", "Two prisms: the front one transparent (1.501) and texture mapped "
     "with 30 bombed spheres, the other (3.227) non-transparent; anti-aliasing threshold 0.1, "
     "no dispersion", "thesis: 112.5 s total (section 4.1.5, threshold 0.1)"),
    ("a5_dispersion", "A.5", "The same scene with dispersion, and a dimmer light to show it "
     "better", ""),
    ("a6_eta_animation", "A.6", "The role of refractive index in dielectrics (animation): a "
     "bombed textured sphere whose index falls from 3.7 (solid) to 1.501 (glass)", ""),
    ("a7_antialiasing", "A.7", "The effectiveness of the adaptive supersampling anti-aliasing "
     "method: 3 objects, 224 triangles, threshold 0.02", "thesis: 52 minutes"),
    ("a8_no_antialiasing", "A.8", "The effect of aliasing in point sampled ray tracing: the "
     "same without anti-aliasing", "thesis: 17 minutes"),
]
BEGIN, END = "<!-- gallery begin -->", "<!-- gallery end -->"


def cpu_name():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def render(vbcl, scene, out_png, size, extra=()):
    """Renders one figure; returns its --stats-json document (an animation's: the frames)."""
    opts = ["-o", out_png] + list(extra)
    if size:
        opts += ["--width", str(size), "--height", str(size)]
    return read_stats_json(vbcl, scene, opts)


def summarise(doc):
    """The numbers of one figure: times (s), samples per pixel, rays, frames, device."""
    frames = doc["frames"] if "frames" in doc else [doc]
    pixels = [f["scene"]["width"] * f["scene"]["height"] for f in frames]
    samples = [f["samples"]["per_pixel_mean"] * p for f, p in zip(frames, pixels)]
    return {
        "frames": len(frames),
        "width": frames[0]["scene"]["width"], "height": frames[0]["scene"]["height"],
        "triangles": max(f["scene"]["triangles"] for f in frames),
        "render_s": sum(f["time_ms"]["render"] for f in frames) / 1000,
        "total_s": sum(f["time_ms"]["total"] for f in frames) / 1000,
        "spp": sum(samples) / sum(pixels),
        "spp_max": max(f["samples"]["per_pixel_max"] for f in frames),
        "rays": sum(f["rays"]["total"] for f in frames),
        "device": frames[0]["device"]["name"], "driver": frames[0]["device"]["driver"],
    }


def mosaic(frames, out):
    """The animation's frames as one image: 4 across, at half size (oiiotool)."""
    cols = 4
    rows = (len(frames) + cols - 1) // cols
    cmd = ["oiiotool"]
    for f in frames:
        cmd += [f, "--resize", "50%"]
    cmd += ["--mosaic", f"{cols}x{rows}", "-o", out]
    subprocess.run(cmd, check=True)


def rays_text(n):
    return f"{n / 1e6:.1f} M" if n >= 1e5 else f"{n:,}"


def table(rows, machine):
    lines = [f"Rendered by `make gallery` (`scripts/gallery.py`) on {machine}, one figure at a "
             "time; each scene's own settings (`scenes/thesis/`). Time: the whole run "
             "(scene, grid, kernels, render, write; program and generated textures from their "
             "caches, as on any run after the first); spp: camera samples per pixel (mean); "
             "rays: every ray traced (camera, shadow feelers, ray trees, dispersion).", "",
             "| figure | image | thesis caption | time | spp | rays |", "|---|---|---|---|---|---|"]
    for r in rows:
        img = f"docs/images/thesis/{r['name']}.png"
        frames = f" ({r['frames']} frames)" if r["frames"] > 1 else ""
        note = f"<br>({r['thesis']})" if r["thesis"] else ""
        lines.append(
            f"| {r['figure']} | <a href=\"{img}\"><img src=\"{img}\" width=\"200\"></a> | "
            f"{r['caption']}{frames} | {r['total_s']:.1f} s{note} | {r['spp']:.2f} | "
            f"{rays_text(r['rays'])} |")
    return "\n".join(lines) + "\n"


def update_readme(path, text):
    with open(path) as f:
        old = f.read()
    pat = re.compile(re.escape(BEGIN) + r".*?" + re.escape(END), re.S)
    if not pat.search(old):
        sys.exit(f"gallery: {path}: no '{BEGIN}' ... '{END}' section to replace")
    new = pat.sub(lambda _: BEGIN + "\n" + text + END, old)
    fd, tmp = tempfile.mkstemp(dir=os.path.dirname(os.path.abspath(path)))
    with os.fdopen(fd, "w") as f:
        f.write(new)
    os.replace(tmp, path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vbcl", default="./vbcl")
    ap.add_argument("--out", default="docs/images/thesis")
    ap.add_argument("--readme", default="")
    ap.add_argument("--size", type=int, default=0)
    ap.add_argument("--scenes", default="", help="a comma list of prefixes (a1,a4,...)")
    a = ap.parse_args()
    if a.readme and a.size:
        ap.error("--readme takes the scenes' own size: leave out --size")
    want = [s for s in a.scenes.split(",") if s]
    os.makedirs(a.out, exist_ok=True)
    rows = []
    for name, figure, caption, thesis in FIGURES:
        if want and not any(name.startswith(w) for w in want):
            continue
        scene = os.path.join("scenes", "thesis", name + ".json")
        with open(scene) as f:
            animated = "animation" in json.load(f)
        print(f"gallery: {figure} {scene}", flush=True)
        # warm: build the scene's program and let PoCL compile its kernels (at their first
        # launch, for the work-group sizes of this image size) with one feeler per point, so
        # that the time measured is a render's, not a first build's
        with tempfile.TemporaryDirectory() as tmp:
            render(a.vbcl, scene, os.path.join(tmp, "warm_##.png"), a.size,
                   ["--shadow-samples", "1"])
        if animated:  # the frames into a scratch folder, the mosaic into OUT
            with tempfile.TemporaryDirectory() as tmp:
                st = summarise(render(a.vbcl, scene, os.path.join(tmp, "f_##.png"), a.size))
                mosaic([os.path.join(tmp, f"f_{k:02d}.png") for k in range(st["frames"])],
                       os.path.join(a.out, name + ".png"))
        else:
            st = summarise(render(a.vbcl, scene, os.path.join(a.out, name + ".png"), a.size))
        rows.append(dict(st, name=name, figure=figure, caption=caption, thesis=thesis))
        print(f"gallery: {figure}: {st['total_s']:.1f} s, {st['spp']:.2f} spp, "
              f"{rays_text(st['rays'])} rays", flush=True)
    machine = (f"a {os.cpu_count()}-core {cpu_name()}, OpenCL device "
               f"{rows[0]['device']} (driver {rows[0]['driver']})") if rows else ""
    with open(os.path.join(a.out, "gallery.json"), "w") as f:
        json.dump({"machine": machine, "figures": rows}, f, indent=1)
    text = table(rows, machine)
    with open(os.path.join(a.out, "gallery.md"), "w") as f:
        f.write(text)
    print(text)
    if a.readme:
        update_readme(a.readme, text)
        print(f"gallery: {a.readme} updated")


if __name__ == "__main__":
    main()
