#!/usr/bin/python3
"""What `render --denoise` costs and gains (docs/cli.md, Denoising).

    scripts/compare/denoise.py SCENE --reference REF.exr [--size 512] [--spp 16] [--against 256]
                               [--mp-size 1024] [--binary build/candela] [--out DIR]

Time: a 1-spp render of SCENE at MP_SIZE² with --denoise at each quality; the denoise time
candela prints (the two guides' prefilters and the beauty's filter, with the copies) per
megapixel. Error: SCENE at SIZE² with SPP samples denoised at each quality, and AGAINST samples
undenoised, each as relMSE against REF.exr (a render at SIZE² with many more samples and another
--seed). Runs with Debian's python3 (python3-numpy, python3-openimageio).
"""
import argparse
import os
import re
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import candela_tools as ct  # noqa: E402

QUALITIES = ("fast", "balanced", "high")


def denoise_seconds(stderr):
    m = re.search(r"denoised in ([0-9.]+)s", stderr)
    if not m:
        raise ct.UserError("candela printed no denoise time: " + stderr.strip()[-300:])
    return float(m.group(1))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("--reference", required=True)
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--against", type=int, default=256)
    ap.add_argument("--mp-size", type=int, default=1024)
    ap.add_argument("--binary")
    ap.add_argument("--out")
    args = ap.parse_args()
    out = args.out or tempfile.mkdtemp(prefix="candela-denoise-")
    try:
        ref, _ = ct.read_rgb(args.reference, "reference")
        common = ["-q", "--seed", "1"]
        megapixels = args.mp_size * args.mp_size / 1e6
        for q in QUALITIES:
            r = ct.render(args.scene, os.path.join(out, "mp-%s.exr" % q),
                          ["--spp", 1, "--width", args.mp_size, "--height", args.mp_size, "--denoise=" + q] + common[1:],
                          binary=args.binary)
            print("time %-8s %.2f s per megapixel" % (q, denoise_seconds(r.stderr) / megapixels))
        size = ["--width", args.size, "--height", args.size]
        plain = os.path.join(out, "plain-%d.exr" % args.against)
        ct.render(args.scene, plain, ["--spp", args.against] + size + common, binary=args.binary)
        noisy = None
        for q in QUALITIES:
            path = os.path.join(out, "denoised-%d-%s.exr" % (args.spp, q))
            ct.render(args.scene, path, ["--spp", args.spp, "--denoise=" + q] + size + common, binary=args.binary)
            den = ct.read_channels(path, "RGB")
            noisy = ct.read_channels(path, ["noisy.R", "noisy.G", "noisy.B"])
            print("relMSE %d spp denoised (%s): %.3g" % (args.spp, q, ct.rel_mse(den, ref)))
        print("relMSE %d spp undenoised: %.3g" % (args.spp, ct.rel_mse(noisy, ref)))
        print("relMSE %d spp undenoised: %.3g" % (args.against, ct.rel_mse(ct.read_rgb(plain)[0], ref)))
    except (ct.UserError, ct.RenderError) as e:
        ct.fail(str(e))


if __name__ == "__main__":
    main()
