#!/usr/bin/python3
"""Adaptive sampling (--noise-threshold) measured: its bias, and its error against uniform sampling at equal time.

  scripts/compare/adaptive.py bias SCENE [--threshold E] [--spp N] [--seeds K] [--ref-spp M] [--width W]
  scripts/compare/adaptive.py time SCENE [--threshold E] [--time S] [--seeds K] [--ref-spp M] [--width W]

Both render a uniform reference (M spp, seed 1000) into --out DIR (kept: a second run reuses it); time takes
--reference REF.exr instead, an image k times as wide (averaged over k x k blocks: the same pixels under the
box filter).
bias: K seeds of the adaptive render (at most N spp) and, as a control, K uniform renders at the adaptive
renders' mean spp. Prints the ratio of the image means to the reference's with its standard error (over the
seeds, and the reference's own from its variance image), and the median over pixels of the pixel ratio
(the seeds' mean over the reference, pixels above 1 % of the image's mean), for both.
time: K pairs of renders, uniform and adaptive, each with --time S, interleaved; prints each relMSE against
the reference (epsilon 0.01), the medians and their ratio uniform / adaptive.
"""
import argparse
import os
import statistics
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import candela_tools as ct  # noqa: E402


def reference(args):
    if args.reference:  # an image k times as wide: averaged over k x k blocks (exact under the box filter)
        rgb, _ = ct.read_rgb(args.reference)
        k = rgb.shape[1] // args.width
        h, w = rgb.shape[0] // k, rgb.shape[1] // k
        return rgb[:h * k, :w * k].reshape(h, k, w, k, 3).mean(axis=(1, 3)), None
    ref = os.path.join(args.out, "ref-%s-%d-%d.exr" % (os.path.basename(args.scene), args.width, args.ref_spp))
    var = ref[:-4] + "-var.exr"
    if not os.path.exists(ref) or not os.path.exists(var):
        ct.render(args.scene, ref, ["--spp", args.ref_spp, "--seed", 1000, "--variance", var] + args.common)
    rgb, _ = ct.read_rgb(ref)
    v, _ = ct.read_rgb(var)
    return rgb, v


def bias(args):
    np, _ = ct.numpy_oiio()
    ref, ref_var = reference(args)
    rows = {}
    for kind in ("adaptive", "uniform"):
        images, spps = [], []
        for seed in range(args.seeds):
            path = os.path.join(args.out, "bias-%s-%d.exr" % (kind, seed))
            opts = ["--seed", seed, "--aov", "spp"] + args.common
            if kind == "adaptive":
                opts += ["--spp", args.spp, "--noise-threshold", args.threshold]
            else:
                opts += ["--spp", max(1, round(statistics.mean(rows["adaptive"][1])))]
            ct.render(args.scene, path, opts)
            images.append(ct.read_rgb(path)[0])
            spps.append(float(ct.read_channels(path, ["spp.Y"]).mean()))
        rows[kind] = (images, spps)
    ref_mean = ref.mean()
    ref_se = np.sqrt(np.nan_to_num(ref_var, posinf=0.0).sum()) / ref.size
    print("%s, %d px, reference %d spp: image mean %.5g ± %.2g" % (args.scene, args.width, args.ref_spp, ref_mean,
                                                                  ref_se))
    for kind, (images, spps) in rows.items():
        means = [im.mean() / ref_mean for im in images]
        se = math_hypot(statistics.stdev(means) / len(means) ** 0.5, ref_se / ref_mean)
        pooled = sum(images) / len(images)
        keep = ref > 0.01 * ref_mean
        median = float(np.median(pooled[keep] / ref[keep]))
        print("  %-8s mean spp %7.1f  mean ratio %.5f ± %.5f  median pixel ratio %.4f" %
              (kind, statistics.mean(spps), statistics.mean(means), se, median))


def math_hypot(a, b):
    return (a * a + b * b) ** 0.5


def equal_time(args):
    ref, _ = reference(args)
    errs = {"uniform": [], "adaptive": []}
    for extra in ([], ["--noise-threshold", args.threshold]):  # warm-ups: the kernels built and cached
        ct.render(args.scene, os.path.join(args.out, "warm-up.exr"), ["--spp", 1] + args.common + extra)
    for seed in range(args.seeds):
        for kind in (("uniform", "adaptive") if seed % 2 == 0 else ("adaptive", "uniform")):
            path = os.path.join(args.out, "time-%s-%d.exr" % (kind, seed))
            opts = ["--seed", seed, "--time", args.time, "--aov", "spp"] + args.common
            if kind == "adaptive":
                opts += ["--noise-threshold", args.threshold]
            r = ct.render(args.scene, path, opts, stats=path[:-4] + ".json")
            e = ct.rel_mse(ct.read_rgb(path)[0], ref)
            spp = float(ct.read_channels(path, ["spp.Y"]).mean())
            errs[kind].append(e)
            print("  %-8s seed %d: relMSE %.4g in %.2f s, mean spp %.1f" % (kind, seed, e, r.stats["seconds"], spp))
    u, a = statistics.median(errs["uniform"]), statistics.median(errs["adaptive"])
    print("%s, %d px, %g s: median relMSE uniform %.4g, adaptive (E %g) %.4g: uniform / adaptive %.2f" %
          (args.scene, args.width, args.time, u, args.threshold, a, u / a))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mode", choices=["bias", "time"])
    ap.add_argument("scene")
    ap.add_argument("--threshold", type=float, default=0.02)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--time", type=float, default=4.0)
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--width", type=int, default=128)
    ap.add_argument("--reference", help="time: a reference k times as wide, rendered with the box filter")
    ap.add_argument("--device", default="pocl")
    ap.add_argument("--out", default="adaptive-out")
    ap.add_argument("--candela", help="the candela binary (default: build/candela)")
    args = ap.parse_args()
    if args.candela:
        ct.BINARY = args.candela
    os.makedirs(args.out, exist_ok=True)
    args.common = ["--width", args.width, "--device", args.device, "-q"]
    try:
        bias(args) if args.mode == "bias" else equal_time(args)
    except (ct.UserError, ct.RenderError) as e:
        ct.fail(str(e))


if __name__ == "__main__":
    main()
