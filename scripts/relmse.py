#!/usr/bin/env python3
"""Relative mean squared error of images against a reference.

    scripts/relmse.py REFERENCE.exr IMAGE.exr [IMAGE.exr ...] [--epsilon 0.01]

relMSE = mean over pixels and RGB channels of (x - r)^2 / (r^2 + epsilon), r the
reference. Prints one line per image: its relMSE, then its candela:spp metadata when it
has some. Pixels are read through `oiiotool --dumpdata` (openimageio-tools), so nothing
beyond Python's standard library is needed.
"""
import argparse
import re
import subprocess
import sys

PIXEL = re.compile(r"^\s*Pixel \((\d+), (\d+)\):((?:\s+\S+)+)\s*$")


def read_image(path):
    """(width, height, pixels): pixels as a list of RGB tuples in row-major order"""
    out = subprocess.run(["oiiotool", "--dumpdata", path], check=True, capture_output=True, text=True).stdout
    pixels = {}
    for line in out.splitlines():
        m = PIXEL.match(line)
        if m:
            pixels[(int(m.group(2)), int(m.group(1)))] = tuple(float(v) for v in m.group(3).split()[:3])
    if not pixels:
        sys.exit(f"relmse: no pixels read from {path}")
    height = 1 + max(y for y, _ in pixels)
    width = 1 + max(x for _, x in pixels)
    return width, height, [pixels[(y, x)] for y in range(height) for x in range(width)]


def spp_of(path):
    out = subprocess.run(["oiiotool", "--info", "-v", path], check=True, capture_output=True, text=True).stdout
    m = re.search(r'candela:spp: "(\d+)"', out)
    return m.group(1) if m else None


def rel_mse(reference, image, epsilon):
    total = 0.0
    for r, x in zip(reference, image):
        total += sum((xc - rc) ** 2 / (rc * rc + epsilon) for rc, xc in zip(r, x))
    return total / (3 * len(reference))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("reference")
    ap.add_argument("images", nargs="+")
    ap.add_argument("--epsilon", type=float, default=0.01)
    args = ap.parse_args()
    rw, rh, ref = read_image(args.reference)
    for path in args.images:
        w, h, img = read_image(path)
        if (w, h) != (rw, rh):
            sys.exit(f"relmse: {path} is {w}x{h}, the reference {rw}x{rh}")
        spp = spp_of(path)
        print(f"{rel_mse(ref, img, args.epsilon):.6e}  {path}" + (f"  ({spp} spp)" if spp else ""))


if __name__ == "__main__":
    main()
