#!/usr/bin/python3
"""Where rusticl (Mesa llvmpipe) loses against PoCL: the same scene rendered on both
devices by the shipped kernel and by cut-down copies of it, in alternating rounds.

  scripts/bench/rusticl_breakdown.py [--scene GLTF] [--size N] [--seconds S] [--rounds N] [--binary PATH]
                            [--variants A,B,...]

Each render runs for S seconds (`candela render --time S`, default 2) whatever its speed, so
that launch overheads weigh the same on fast and slow variants.

Variants (each a copy of cl/ with one source edit, passed by CANDELA_KERNEL_DIR):
  full           the shipped kernel, --max-depth 8
  depth-0        the shipped kernel, --max-depth 0 (camera rays: one closest hit, emission)
  closest-hit    render_paths traces the camera ray's closest hit and nothing else
  no-shadow-rays the shipped kernel with every shadow ray unoccluded, --max-depth 8
  generic        the shipped kernel with every feature compiled in (--generic), --max-depth 8

It prints Msamples/s per device and variant (the median over rounds) and rusticl / PoCL.
A source edit that no longer matches cl/ is an error: update the patterns below.
"""

import argparse
import os
import shutil
import statistics
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import candela_tools as ct  # noqa: E402

ROOT = ct.ROOT

# variant: (file, old text, new text, extra render options)
VARIANTS = {
    "full": (None, None, None, ["--max-depth", "8"]),
    "depth-0": (None, None, None, ["--max-depth", "0"]),
    "closest-hit": ("integrator_path.cl", "    float3 l = path_trace(&sc, ray, &rng);",
                    "    Hit hh = scene_intersect(&sc, ray, INFINITY);\n"
                    "    float3 l = (float3)(hh.t, hh.b1, (float)hh.prim);", ["--max-depth", "8"]),
    "no-shadow-rays": ("scene_data.cl", "  return bvh_occluded(sc, sc->bvh_nodes, sc->bvh_tris, ray, tmax);",
                       "  return false;", ["--max-depth", "8"]),
    "generic": (None, None, None, ["--max-depth", "8", "--generic"]),
}


fail = ct.fail


def make_kernel_dir(tmp, name, variant):
    path, old, new, _ = variant
    if path is None:
        return os.path.join(ROOT, "cl")
    d = os.path.join(tmp, name)
    shutil.copytree(os.path.join(ROOT, "cl"), d)
    f = os.path.join(d, path)
    with open(f) as h:
        text = h.read()
    if old not in text:
        fail("variant %s: cl/%s no longer contains %r (update scripts/bench/rusticl_breakdown.py)" % (name, path, old))
    with open(f, "w") as h:
        h.write(text.replace(old, new))
    return d


def render(args, kernel_dir, device, extra, budget, size):
    env = dict(os.environ, CANDELA_KERNEL_DIR=kernel_dir, RUSTICL_ENABLE="llvmpipe")
    try:
        r = ct.render(args.scene, os.path.join(args.tmp, "out.exr"),
                      budget + ["--width", size, "--height", size, "--device", device, "-q"] + extra,
                      binary=args.binary, stats=os.path.join(args.tmp, "s.json"), env=env)
    except ct.UserError as e:
        fail("variant with kernels %s on %s: %s" % (kernel_dir, device, e))
    return r.stats["samples_per_second"] / 1e6


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scene", default=os.path.join(ROOT, "scenes/cornell-box/cornell-box.gltf"))
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--seconds", type=float, default=2.0)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--binary", default=os.path.join(ROOT, "build/candela"))
    parser.add_argument("--variants", default=",".join(VARIANTS), help="comma-separated subset of " + ", ".join(VARIANTS))
    args = parser.parse_args()
    if not os.access(args.binary, os.X_OK):
        fail("no candela binary at %s (build it, or pass --binary)" % args.binary)
    names = [v for v in args.variants.split(",") if v]
    for v in names:
        if v not in VARIANTS:
            fail("unknown variant %s (known: %s)" % (v, ", ".join(VARIANTS)))
    with tempfile.TemporaryDirectory() as tmp:
        args.tmp = tmp
        dirs = {v: make_kernel_dir(tmp, v, VARIANTS[v]) for v in names}
        rates = {(v, d): [] for v in names for d in ("pocl", "rusticl")}
        for v in names:  # warm-up: kernel builds and PoCL's lazily built work-group code
            for d in ("pocl", "rusticl"):
                render(args, dirs[v], d, VARIANTS[v][3], ["--spp", "1"], 32)
        for r in range(args.rounds):
            for v in (names if r % 2 == 0 else names[::-1]):
                for d in (("pocl", "rusticl") if r % 2 == 0 else ("rusticl", "pocl")):
                    budget = ["--time", str(args.seconds)]
                    rates[(v, d)].append(render(args, dirs[v], d, VARIANTS[v][3], budget, args.size))
        load = os.getloadavg()[0]
    print("| variant | PoCL Msamples/s | rusticl Msamples/s | rusticl / PoCL |")
    print("|---|---|---|---|")
    for v in names:
        p, q = statistics.median(rates[(v, "pocl")]), statistics.median(rates[(v, "rusticl")])
        print("| %s | %.3f | %.3f | %.3f |" % (v, p, q, q / p))
    print("(%s, %d^2, medians of %d rounds; load average %.1f at the end)" % (os.path.relpath(args.scene, ROOT),
                                                                             args.size, args.rounds, load))


if __name__ == "__main__":
    main()
