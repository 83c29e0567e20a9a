#!/usr/bin/python3
"""relMSE of the three strategies (nee, bsdf, auto) on glTF assets, against a reference.

    /usr/bin/python3 scripts/compare/strategy_assets.py [ASSET ...]

ASSET: a folder name under ../shared/gltf-samples (its glTF/, glTF-Binary/ or own
.gltf/.glb) or a path to a .gltf/.glb. Without assets, the set docs/integrator.md
("Measured") reports. Each is rendered at --size px wide (default 128) with --spp
samples (16) for seeds 1..--seeds (2) per strategy, and once with --ref-spp (1024) of
`auto` at seed 999 as the reference (kept in --out and reused: delete it after a
change that could bias it). Prints per asset and strategy the
relMSE, mean of (x - r)^2 / (r^2 + 0.01) over pixels and channels, averaged over seeds.
Needs Debian's python3-openimageio and numpy; --binary (default build/candela).
"""
import argparse
import glob
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import candela_tools as ct  # noqa: E402

ROOT = ct.ROOT
SAMPLES = ct.samples_folder()
DEFAULT = ["Cameras", "Avocado", "BoxTextured", "Fox", "NormalTangentTest", "SpecularTest", "AnisotropyBarnLamp",
           "AnisotropyDiscTest", "DamagedHelmet", "ClearCoatTest_glb", "TransmissionRoughnessTest",
           os.path.join(ROOT, "scenes/furnace/closed-sphere.gltf"), os.path.join(ROOT, "scenes/lights/environment.gltf")]


def scene_file(asset):
    if os.path.isfile(asset):
        return asset
    for pattern in ("glTF/*.gltf", "glTF-Binary/*.glb", "*.gltf", "*.glb"):
        found = sorted(glob.glob(os.path.join(SAMPLES, asset, pattern)))
        if found:
            return found[0]
    sys.exit(f"strategy-assets: no glTF for {asset} (looked in {SAMPLES})")


def render(args, scene, strategy, spp, seed, out, cached=False):
    if not (cached and os.path.exists(out)):
        ct.render(scene, out, ["--width", args.size, "--spp", spp, "--seed", seed, "--strategy", strategy,
                               "--device", args.device, "-q"], binary=args.binary)
    return ct.read_rgb(out)[0]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("assets", nargs="*")
    ap.add_argument("--binary", default=os.path.join(ROOT, "build", "candela"))
    ap.add_argument("--device", default="pocl")
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "strategy-assets"))
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--seeds", type=int, default=2)
    args = ap.parse_args()
    try:
        run(args)
    except ct.UserError as e:
        ct.fail(str(e))


def run(args):
    os.makedirs(args.out, exist_ok=True)
    print(f"{'scene':28s} {'nee':>10s} {'bsdf':>10s} {'auto':>10s}")
    for asset in args.assets or DEFAULT:
        scene = scene_file(asset)
        name = os.path.splitext(os.path.basename(scene))[0]
        tag = f"{args.out}/{name}-{args.size}"
        ref = render(args, scene, "auto", args.ref_spp, 999, f"{tag}-ref{args.ref_spp}.exr", cached=True)
        errors = []
        for strategy in ("nee", "bsdf", "auto"):
            e = []
            for seed in range(1, args.seeds + 1):
                img = render(args, scene, strategy, args.spp, seed, f"{tag}-{strategy}{args.spp}-s{seed}.exr")
                e.append(ct.rel_mse(img, ref))
            errors.append(sum(e) / len(e))
        print(f"{name:28s} {errors[0]:10.5f} {errors[1]:10.5f} {errors[2]:10.5f}", flush=True)


if __name__ == "__main__":
    main()
