#!/usr/bin/env python3
"""drivers_check.py — `make test-drivers`: the same scenes on two OpenCL drivers, compared.

usage: scripts/drivers_check.py [--vbcl build/vbcl] [--a Portable] [--b Intel] [--only REGEX]
       scripts/drivers_check.py --save DIR --b NVIDIA    (on a machine with device B)
       scripts/drivers_check.py --against DIR [--a Portable]    (here, on device A)

Renders each scene of SCENES as PFM (linear float) on device A and device B (--device by
name, both visible in this process's environment: `make test-drivers` sources the file
scripts/intel-ocl.sh writes) and compares the images with the scene's tolerance. Where
device B is on another machine (a GPU node without PoCL), --save renders B's images
there into DIR (needs only vbcl, its OpenCL driver, python3 and numpy), and --against
renders A here and compares with them; the mixed-driver frame is then left out:

  tight   values within 1e-6 + REL * max(|a|, |b|) (REL 1e-4 for opaque scenes, 1e-3
          for dielectrics: ray trees compound the few ulps OpenCL allows exp, pow, sqrt and
          division), except at most 0.5% of them, and RMS difference <= 1e-4. The exception
          is for samples that graze an edge: a shadow feeler or an anti-aliasing subpixel
          ray passing within rounding of a silhouette lands on either side, and moves its
          pixel by that one sample's share (penumbra: one of 256 feelers, 1.2e-3);
  chaotic paths that reach the high-index glass of the thesis's figure A.4 go through
          dozens of interfaces, where a last-bit difference flips a total internal
          reflection or a grid-cell boundary; such a pixel is a different but equally valid
          sample of the same light paths. Bound: at most FRAC of the values beyond the tight
          tolerance, and the mean of every channel over the image within 4 standard errors
          of the per-pixel differences (|mean(a-b)| <= 4 std(a-b) / sqrt(n)): two
          renders of the same paths can disagree pixel by pixel, not in their sum.

One more render shares a frame between both drivers (--device A,B: pass 0's tiles go to
whichever is free) and is held to the opaque bound against A alone.

Prints one line per scene and exits 1 if any scene fails (docs/testing.md, "Two OpenCL
drivers").
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_aa import np, read_pfm  # noqa: E402

SMALL = ["--width", "64", "--height", "64"]
# name, scene, options, kind ("opaque", "glass" or "chaotic"), FRAC for chaotic scenes
SCENES = [
    ("tiny", "tests/scenes/tiny.json", [], "opaque", 0),
    ("penumbra", "tests/scenes/penumbra.json", [], "opaque", 0),
    ("tiny_aa", "tests/scenes/tiny_aa.json", [], "opaque", 0),
    ("aa_edges --aa 0.1", "tests/scenes/aa_edges.json", ["--aa", "0.1"], "opaque", 0),
    ("quickstart 64x64", "scenes/quickstart.json", SMALL, "opaque", 0),
    ("surface_patterns 64x48", "scenes/surface_patterns.json",
     ["--width", "64", "--height", "48"], "opaque", 0),
    ("tiny_glass", "tests/scenes/tiny_glass.json", [], "glass", 0),
    ("tiny_dispersion", "tests/scenes/tiny_dispersion.json", [], "glass", 0),
    ("glass_bombed_sphere 64x64", "scenes/glass_bombed_sphere.json",
     SMALL + ["--shadow-samples", "4"], "glass", 0),
    ("prism_dispersion 96x64", "scenes/prism_dispersion.json",
     ["--width", "96", "--height", "64"], "glass", 0),
    ("high_index 64x64", "scenes/high_index.json", SMALL + ["--shadow-samples", "4"], "glass", 0),
    ("environment_glass 64x64", "scenes/environment_glass.json",
     SMALL + ["--shadow-samples", "4"], "glass", 0),
    # one frame shared by both drivers (--device A,B): a mixture of their pixels
    ("quickstart 64x64 on both at once", "scenes/quickstart.json", SMALL + ["MIXED"], "opaque",
     0),
    ("a4_two_prisms 64x64", "scenes/thesis/a4_two_prisms.json",
     SMALL + ["--shadow-samples", "4"], "chaotic", 0.10),
]
REL = {"opaque": 1e-4, "glass": 1e-3, "chaotic": 1e-3}
RMS_MAX = 1e-4
EDGE_FRAC = 0.005


def render(vbcl, device, scene, opts, out):
    cmd = [vbcl, scene, "-q", "--device", device, "-o", out] + opts
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {r.returncode}: {r.stderr.strip()}")
    return read_pfm(out)


def compare(a, b, kind, frac_max):
    """Returns (ok, one-line summary) for images a and b of the given kind."""
    d = a - b
    tol = 1e-6 + REL[kind] * np.maximum(np.abs(a), np.abs(b))
    beyond = np.abs(d) > tol
    frac = float(beyond.mean())
    rms = float(np.sqrt(np.mean(d * d)))
    worst = float(np.abs(d).max())
    n = d.shape[0] * d.shape[1]
    mean = d.reshape(n, -1).mean(axis=0)
    se = d.reshape(n, -1).std(axis=0) / np.sqrt(n)
    text = (f"RMS {rms:.2e}, worst {worst:.2e}, {100 * frac:.2f}% of values beyond "
            f"1e-6 + {REL[kind]:g} rel, channel means differ by "
            f"{', '.join(f'{m:+.1e}' for m in mean)} (4 s.e. {', '.join(f'{4 * s:.1e}' for s in se)})")
    if kind == "chaotic":
        ok = frac <= frac_max and bool(np.all(np.abs(mean) <= 4 * se + 1e-7))
        return ok, text + f"; bound: <= {100 * frac_max:.0f}% beyond, means within 4 s.e."
    ok = frac <= EDGE_FRAC and rms <= RMS_MAX
    return ok, text + f"; bound: <= {100 * EDGE_FRAC:g}% beyond, RMS <= {RMS_MAX:g}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vbcl", default="build/vbcl")
    ap.add_argument("--a", default="Portable", help="first device (--device spec)")
    ap.add_argument("--b", default="Intel", help="second device (--device spec)")
    ap.add_argument("--only", default="",
                    help="only scenes whose name this regular expression matches (re.search)")
    ap.add_argument("--save", metavar="DIR",
                    help="render on device B alone into DIR, for --against on another machine")
    ap.add_argument("--against", metavar="DIR",
                    help="device B's images are in DIR (made by --save): render A, compare")
    a = ap.parse_args()
    if a.save and a.against:
        ap.error("--save and --against exclude each other")
    remote = a.save or a.against
    scenes = [(i, *sc) for i, sc in enumerate(SCENES)
              if (not a.only or re.search(a.only, sc[0])) and not (remote and "MIXED" in sc[2])]
    if a.save:
        os.makedirs(a.save, exist_ok=True)
    failed = 0
    with tempfile.TemporaryDirectory(prefix="vbcl-drivers-") as tmp:
        for i, name, scene, opts, kind, frac in scenes:
            saved = os.path.join(remote, f"scene{i:02d}.pfm") if remote else None
            try:
                dev_b = f"{a.a},{a.b}" if "MIXED" in opts else a.b
                opts = [o for o in opts if o != "MIXED"]
                if a.save:
                    render(a.vbcl, dev_b, scene, opts, saved)
                    print(f"drivers: {name}: rendered on {a.b} into {saved}", flush=True)
                    continue
                img_a = render(a.vbcl, a.a, scene, opts, os.path.join(tmp, "a.pfm"))
                if a.against:
                    if not os.path.exists(saved):
                        raise RuntimeError(f"{saved} is missing (no --save render of it)")
                    img_b = read_pfm(saved)
                else:
                    img_b = render(a.vbcl, dev_b, scene, opts, os.path.join(tmp, "b.pfm"))
            except RuntimeError as e:
                print(f"drivers: {name}: FAILED: {e}", flush=True)
                failed += 1
                continue
            ok, text = compare(img_a, img_b, kind, frac)
            print(f"drivers: {name} ({kind}): {'ok' if ok else 'FAILED'}: {text}", flush=True)
            failed += not ok
    total = len(scenes)
    if a.save:
        print(f"drivers: {total - failed} of {total} scenes rendered on {a.b} into {a.save}")
    else:
        other = f"the images in {a.against}" if a.against else a.b
        print(f"drivers: {a.a} against {other}: {total - failed} of {total} scenes agree")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
