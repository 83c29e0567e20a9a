#!/usr/bin/python3
"""Relative mean squared error of images against a reference.

    scripts/compare/relmse.py REFERENCE.exr IMAGE.exr [IMAGE.exr ...] [--epsilon 0.01]

relMSE = mean over pixels and RGB channels of (x - r)^2 / (r^2 + epsilon), r the
reference. Prints one line per image: its relMSE, then its candela:spp metadata when it
has some. Runs with Debian's python3 (python3-numpy, python3-openimageio).
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import candela_tools as ct  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("reference")
    ap.add_argument("images", nargs="+")
    ap.add_argument("--epsilon", type=float, default=ct.EPSILON)
    args = ap.parse_args()
    try:
        ref, _ = ct.read_rgb(args.reference, "reference")
        for path in args.images:
            img, meta = ct.read_rgb(path)
            if img.shape != ref.shape:
                ct.fail("%s is %dx%d, the reference %dx%d" % (path, img.shape[1], img.shape[0], ref.shape[1],
                                                              ref.shape[0]))
            spp = meta.get("spp")
            print(f"{ct.rel_mse(img, ref, args.epsilon):.6e}  {path}" + (f"  ({spp} spp)" if spp else ""))
    except ct.UserError as e:
        ct.fail(str(e))


if __name__ == "__main__":
    main()
