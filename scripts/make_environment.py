#!/usr/bin/env python3
"""make_environment.py — the example environment scenes/images/sky.exr, made procedurally:
a latitude-longitude image (docs/scene-format.md, "image.environment": row 0 the zenith,
u = 0 the direction -z, u = 1/4 the direction +x) of a blue sky with soft clouds and a sun,
a ring of hills along the horizon and a warm ground below it.

usage: scripts/make_environment.py [-o scenes/images/sky.exr] [--width 256] [--height 128]
           [--sun AZIMUTH ELEVATION]
AZIMUTH is in degrees from -z toward +x (the direction (sin az, 0, -cos az)), ELEVATION
in degrees above the horizon. The image is written as a Portable Float Map and turned into a
half-float, zip-compressed EXR by oiiotool (openimageio-tools); the sun is bright (about 20
times the sky) so that glass shows it in its reflections. Needs numpy.
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np


def directions(w, h, sub=(0.0, 0.0)):
    """The unit direction of each texel centre (h, w, 3) as vbcl and Mitsuba 3 map them:
    u = (i + 1/2) / w around the up axis from -z toward +x, v = j / (h - 1) from the zenith;
    sub moves them by that part of a texel (a supersample)."""
    u = (np.arange(w) + 0.5 + sub[0]) / w
    v = np.clip((np.arange(h) + sub[1]) / (h - 1), 0, 1)
    phi, theta = np.meshgrid(2 * np.pi * u, np.pi * v)
    return np.stack([np.sin(phi) * np.sin(theta), np.cos(theta),
                     -np.cos(phi) * np.sin(theta)], axis=-1), phi


def sky(w, h, sun_az, sun_el, n=4):
    """The image, each texel the mean of n x n samples across it (soft edges)."""
    img = np.zeros((h, w, 3))
    for a in range(n):
        for b in range(n):
            img += sky_at(w, h, sun_az, sun_el, ((a + 0.5) / n - 0.5, (b + 0.5) / n - 0.5))
    return (img / (n * n)).astype(np.float32)


def sky_at(w, h, sun_az, sun_el, sub):
    d, phi = directions(w, h, sub)
    y = d[..., 1]
    img = np.zeros((h, w, 3))
    # sky: deep blue at the zenith to pale at the horizon
    t = np.clip(y, 0, 1) ** 0.45
    zenith, horizon = np.array([0.10, 0.22, 0.62]), np.array([0.78, 0.84, 0.92])
    img[:] = horizon + (zenith - horizon) * t[..., None]
    # clouds: a few sums of sines in the sky's own angles, soft-thresholded
    c = (np.sin(3 * phi + 2.0 * y * 5) + 0.6 * np.sin(7 * phi - 3.1 + 9 * y) +
         0.35 * np.sin(13 * phi + 1.7 - 14 * y))
    cloud = np.clip((c - 0.7) / 0.9, 0, 1) * np.clip(y * 4, 0, 1) * np.clip((1 - y) * 2, 0, 1)
    img = img * (1 - 0.8 * cloud[..., None]) + 0.95 * 0.8 * cloud[..., None]
    # the sun: a disc of 2.5 degrees and a glow around it
    az, el = np.radians(sun_az), np.radians(sun_el)
    s = np.array([np.sin(az) * np.cos(el), np.sin(el), -np.cos(az) * np.cos(el)])
    cosang = np.clip(d @ s, -1, 1)
    ang = np.degrees(np.arccos(cosang))
    img += np.array([1.0, 0.93, 0.8]) * (20.0 * (ang < 2.5) + 1.5 * np.exp(-ang / 6.0))[..., None]
    # hills: a silhouette of a few sines, a little above the horizon
    top = 0.09 + 0.05 * np.sin(2 * phi + 0.4) + 0.03 * np.sin(5 * phi + 1.3) + \
        0.015 * np.sin(11 * phi + 0.2)
    hill = (y > -0.02) & (y < top)
    shade = (0.5 + 0.5 * np.clip((top - y) / 0.1, 0, 1)) * (0.8 + 0.2 * np.sin(3 * phi + 2.0))
    img[hill] = (np.array([0.16, 0.26, 0.15]) * shade[hill][:, None])
    # ground: warm earth, darker toward the nadir, with a faint ring pattern
    g = y <= -0.02
    ring = 0.85 + 0.15 * np.sin(40 * np.arccos(np.clip(-y, -1, 1)))
    img[g] = (np.array([0.36, 0.30, 0.22]) * (0.45 + 0.55 * np.clip(1 + y, 0, 1))[g][:, None]
              * ring[g][:, None])
    return img


def write_pfm(path, img):
    h, w, _ = img.shape
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        f.write(np.ascontiguousarray(img[::-1]).astype("<f4").tobytes())  # bottom row first


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("-o", "--output", default="scenes/images/sky.exr")
    ap.add_argument("--width", type=int, default=256)
    ap.add_argument("--height", type=int, default=128)
    ap.add_argument("--sun", type=float, nargs=2, default=(225.0, 45.0),
                    metavar=("AZIMUTH", "ELEVATION"))
    a = ap.parse_args()
    img = sky(a.width, a.height, *a.sun)
    with tempfile.TemporaryDirectory() as tmp:
        pfm = os.path.join(tmp, "sky.pfm")
        write_pfm(pfm, img)
        rc = subprocess.call(["oiiotool", pfm, "-d", "half", "--compression", "zip",
                              "-o", a.output])
    if rc:
        sys.exit("oiiotool failed (openimageio-tools installed?)")
    print("%s: %d x %d, radiance %.3g .. %.3g" % (a.output, a.width, a.height, img.min(),
                                                   img.max()))


if __name__ == "__main__":
    main()
