#!/usr/bin/python3
"""Equal-time error of candela against Mitsuba 3's MIS path tracer: relMSE of each renderer against its own
high-spp reference, and the efficiency 1/(relMSE x seconds) of each.

  scripts/compare/vs_mitsuba.py SCENE [--ladder 16,32,64,128,256] [--ref-spp 4096] [--max-depth 16] [--size 128]
                     [--height H] [--repeats 3] [--repeat-rungs 1] [--strategy auto]
                     [--samplers sobol,independent] [--mitsuba-sampler independent] [--device pocl]
                     [--variant llvm_ad_rgb] [--out DIR] [--candela PATH] [--record]

The method is scripts/compare/equal_time.py's (whose helpers it uses): a ladder of sample counts rendered by candela with
each of --samplers and by Mitsuba with --mitsuba-sampler, in turn (the order rotating), the top --repeat-rungs
rungs --repeats times with seeds 0, 1, 2, ...; relMSE = mean (x - r)^2 / (r^2 + 0.01) over pixels and channels
(scripts/compare/relmse.py), r the renderer's OWN reference (seed 1000, --ref-spp, rendered once and cached in --out;
candela's with the first of --samplers), so that the bias between the two renderers' images does not enter;
the load average of each render is recorded. The reference's own noise adds the same fraction (about
spp/ref-spp) to both renderers' relMSE, so it leaves the ratio of efficiencies unchanged. candela's seconds are
its --stats `seconds` (kernel build excluded; an untimed 1-spp warm-up fills the kernel caches first); Mitsuba's
are the time of mi.render() until the image is on the host, after an untimed warm-up render that JIT-compiles
its kernel at each spp of the ladder (with the independent sampler later renders of any spp reuse one kernel;
stratified samplers compile one per sample count). The scene is converted by scripts/candela_tools/mitsuba.py (its
docstring says what is approximated); Mitsuba's path integrator gets max_depth = --max-depth + 1 (it counts path
vertices, candela scattering events) and rr_depth 3.

How well the two renderers agree: the ratio of the references' means (candela / Mitsuba) over the frame, per
channel, and its range over a 4 x 4 grid of tiles (those not darker than 1 % of the frame), and the relMSE of
Mitsuba's reference against candela's.

Mitsuba is not a dependency of candela's build or tests. Install it for Debian's python3 (which has numpy and
OpenImageIO):  /usr/bin/python3 -m pip install --user --break-system-packages mitsuba
The `llvm_ad_rgb` variant (Dr.Jit's LLVM backend, SIMD over all cores) needs libLLVM: DRJIT_LIBLLVM_PATH
(default /usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 when that file exists); without it the script falls back to
`scalar_rgb` (one path per thread, no SIMD) and says so.

Writes DIR/runs-mitsuba-SAMPLER.csv (every render) and the references, and prints a markdown table.
"""

import argparse
import csv
import os
import statistics
import sys
import tempfile
import types

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import candela_tools as ct  # noqa: E402
from candela_tools import UserError, mitsuba as mitsuba_scene  # noqa: E402
import converge  # noqa: E402  (its ladder rung: converge.run_candela)
import equal_time  # noqa: E402  (its table formatting)

ROOT = ct.ROOT
REF_SEED = 1000

RUN_COLUMNS = ["series", "renderer", "sampler", "spp", "repeat", "seed", "seconds", "rel_mse_own_ref",
               "efficiency_own_ref", "loadavg1"]


def main():
    ap = argparse.ArgumentParser(prog="scripts/compare/vs_mitsuba.py", description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--ladder", default="16,32,64,128,256")
    ap.add_argument("--ref-spp", type=int, default=4096, help="spp of each renderer's reference (default 4096)")
    ap.add_argument("--max-depth", type=int, default=16, help="candela's --max-depth (default 16); Mitsuba gets +1")
    ap.add_argument("--size", type=int, default=128, help="image width (default 128)")
    ap.add_argument("--height", type=int, help="image height (default: the width over the camera's aspectRatio)")
    ap.add_argument("--repeats", type=int, default=3, help="renders of each of the top rungs (default 3)")
    ap.add_argument("--repeat-rungs", type=int, default=1, help="how many top rungs are repeated (default 1)")
    ap.add_argument("--strategy", default="auto", help="candela's --strategy (default auto)")
    ap.add_argument("--samplers", default="sobol,independent", help="candela --sampler values (default both)")
    ap.add_argument("--mitsuba-sampler", default="independent",
                    help="Mitsuba's sampler plugin (default independent; also stratified, multijitter, ldsampler)")
    ap.add_argument("--device", default="pocl")
    ap.add_argument("--variant", default="llvm_ad_rgb", help="Mitsuba variant (default llvm_ad_rgb)")
    ap.add_argument("--out", help="folder of the runs CSV and the cached references (default build/vs-mitsuba/SCENE)")
    ap.add_argument("--candela", default=os.path.join(ROOT, "build", "candela"))
    ap.add_argument("--record", action="store_true",
                    help="set this scene's figure against Mitsuba in docs/figures/results.json (samples per second "
                    "and efficiency at the top rung, the first of --samplers)")
    args = ap.parse_args()
    try:
        return run(args)
    except UserError as e:
        ct.fail(str(e))


def image_size(args):
    if args.height:
        return args.size, args.height
    doc, _, _ = mitsuba_scene.load_gltf(args.scene)
    aspect = None
    for node_index, _ in mitsuba_scene.walk(doc, doc.get("scene", 0)):
        node = doc["nodes"][node_index]
        if "camera" in node:
            aspect = doc["cameras"][node["camera"]].get("perspective", {}).get("aspectRatio")
            break
    return args.size, max(1, int(round(args.size / aspect))) if aspect else args.size


def agreement(cref, mref, np):
    """candela/Mitsuba ratio of the references' means per channel, its range over the 4 x 4 tiles whose mean is at
    least 1 % of the frame's (channels averaged), and relMSE of Mitsuba's reference against candela's"""
    frame = cref.mean(axis=(0, 1)) / np.maximum(mref.mean(axis=(0, 1)), 1e-30)
    h, w = cref.shape[:2]
    tiles = []
    for i in range(4):
        for j in range(4):
            c = cref[i * h // 4:(i + 1) * h // 4, j * w // 4:(j + 1) * w // 4].mean()
            m = mref[i * h // 4:(i + 1) * h // 4, j * w // 4:(j + 1) * w // 4].mean()
            if m > 0.01 * mref.mean():  # tiles of at least 1 % of the frame mean
                tiles.append(c / m)
    return frame, min(tiles), max(tiles), ct.errors(mref, cref)["rel_mse"]


def run(args):
    ladder = ct.parse_ladder(args.ladder, "--ladder")
    np, _ = ct.numpy_oiio()
    if not os.path.isfile(args.candela):
        raise UserError("candela not found at %s (build it, or pass --candela PATH)" % args.candela)
    mi = mitsuba_scene.import_mitsuba(args.variant)
    width, height = image_size(args)
    stem = os.path.splitext(os.path.basename(args.scene))[0]
    out = args.out or os.path.join(ROOT, "build", "vs-mitsuba", stem)
    os.makedirs(out, exist_ok=True)
    tag = "%dx%d-d%d-%dspp" % (width, height, args.max_depth, args.ref_spp)
    samplers = [s for s in args.samplers.split(",") if s]
    if not samplers:
        raise UserError("--samplers needs at least one candela sampler")
    cref_path = os.path.join(out, "candela-ref-%s-%s-%s.exr" % (tag, args.strategy, samplers[0]))
    mref_path = os.path.join(out, "mitsuba-ref-%s-%s.exr" % (tag, mi.variant()))

    devices = {}

    def candela(tmp, spp, seed, sampler):
        cargs = types.SimpleNamespace(candela=args.candela, scene=args.scene, seed=seed, strategy=args.strategy,
                                      device=args.device, max_depth=args.max_depth)
        path, stats = converge.run_candela(cargs, ["--sampler", sampler], tmp, spp, width, height)
        devices["candela"] = stats.get("device", args.device)
        image, _ = ct.read_rgb(path, "candela render")
        return image, stats["seconds"], path

    with tempfile.TemporaryDirectory(prefix="candela-vs-mitsuba-") as tmp:
        mts = mitsuba_scene.Mitsuba(mi, args.scene, width, height, args.max_depth, args.mitsuba_sampler, tmp)
        for note in mts.notes:
            print("scene conversion: " + note, file=sys.stderr)
        for sampler in samplers:
            candela(tmp, 1, 0, sampler)  # warm-up: kernel build and caches
        for spp in ladder:  # warm-up: Dr.Jit compiles the kernel (samplers other than independent: one per spp)
            mts.render(spp, 999)
        if not os.path.isfile(cref_path):
            image, seconds, path = candela(tmp, args.ref_spp, REF_SEED, samplers[0])
            os.replace(path, cref_path)
            print("candela reference: %d spp in %.1f s -> %s" % (args.ref_spp, seconds, cref_path), file=sys.stderr)
        if not os.path.isfile(mref_path):
            image, seconds = mts.render(args.ref_spp, REF_SEED)
            mts.write(image, mref_path)
            print("Mitsuba reference: %d spp in %.1f s -> %s" % (args.ref_spp, seconds, mref_path), file=sys.stderr)
        cref, _ = ct.read_rgb(cref_path, "candela reference")
        mref, _ = ct.read_rgb(mref_path, "Mitsuba reference")
        if cref.shape != mref.shape or cref.shape[:2] != (height, width):
            raise UserError("cached references differ in size: remove %s and %s" % (cref_path, mref_path))

        jobs = []
        for i, spp in enumerate(ladder):
            reps = args.repeats if i >= len(ladder) - args.repeat_rungs else 1
            jobs += [(spp, r) for r in range(reps)]
        rows = []
        series = ["candela-" + s for s in samplers] + ["mitsuba"]
        for n, (spp, rep) in enumerate(jobs):
            for who in series[n % len(series):] + series[:n % len(series)]:
                load = ct.load_average()
                if who == "mitsuba":
                    image, seconds = mts.render(spp, rep)
                    ref, sampler = mref, args.mitsuba_sampler
                else:
                    sampler = who[len("candela-"):]
                    image, seconds, _ = candela(tmp, spp, rep, sampler)
                    ref = cref
                rel = ct.errors(image, ref)["rel_mse"]
                rows.append({"series": who, "renderer": who.split("-")[0], "sampler": sampler, "spp": spp,
                             "repeat": rep, "seed": rep, "seconds": seconds,
                             "rel_mse_own_ref": rel, "efficiency_own_ref": equal_time.eff(rel, seconds),
                             "loadavg1": load})
                print("%-20s %5d spp rep %d  %8.3f s  relMSE %.4g  load %.2f" % (who, spp, rep, seconds, rel, load),
                      file=sys.stderr, flush=True)

    runs = os.path.join(out, "runs-mitsuba-%s.csv" % args.mitsuba_sampler)
    with open(runs, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=RUN_COLUMNS)
        w.writeheader()
        w.writerows(rows)
    report(args, rows, series, ladder, width, height, mi, agreement(cref, mref, np))
    print("wrote " + runs, file=sys.stderr)
    if args.record:
        record(args, rows, series, ladder, width, height, mi, devices)
    return 0


def report(args, rows, series, ladder, width, height, mi, agree):
    frame, tile_lo, tile_hi, floor = agree
    fmt = equal_time.fmt
    print("\n%s, %dx%d, candela --max-depth %d --strategy %s; Mitsuba %s %s, path max_depth %d, rr_depth 3, "
          "sampler %s; references %d spp, seed %d\n" % (
              os.path.basename(args.scene), width, height, args.max_depth, args.strategy, mi.__version__,
              mi.variant(), args.max_depth + 1, args.mitsuba_sampler, args.ref_spp, REF_SEED))
    print("| renderer (sampler) | spp | seconds | relMSE vs own ref | efficiency 1/(relMSE·s) | "
          "efficiency / Mitsuba's | load |")
    print("|---|---|---|---|---|---|---|")
    for spp in ladder:
        mts = {r["repeat"]: r for r in rows if r["series"] == "mitsuba" and r["spp"] == spp}
        for who in series:
            pts = [r for r in rows if r["series"] == who and r["spp"] == spp]
            col = {k: [r[k] for r in pts] for k in ("seconds", "rel_mse_own_ref", "efficiency_own_ref", "loadavg1")}
            cells = [fmt(statistics.median(col[k]), min(col[k]), max(col[k]), f) for k, f in
                     (("seconds", "%.3f"), ("rel_mse_own_ref", "%.4g"), ("efficiency_own_ref", "%.1f"),
                      ("loadavg1", "%.2f"))]
            ratio = ""
            if who != "mitsuba":  # paired by repeat (seed)
                rs = [r["efficiency_own_ref"] / mts[r["repeat"]]["efficiency_own_ref"] for r in pts
                      if r["repeat"] in mts]
                ratio = "**" + fmt(statistics.median(rs), min(rs), max(rs), "%.2f") + "**" if rs else ""
            name = "Mitsuba (%s)" % pts[0]["sampler"] if who == "mitsuba" else "candela (%s)" % pts[0]["sampler"]
            print("| %s | %d | %s | %s | %s | %s | %s |" % (name, spp, cells[0], cells[1], cells[2], ratio, cells[3]))
    print("\nSlopes (log-log least squares over the ladder's medians):")
    for who in series:
        pts = []
        for spp in ladder:
            sel = [r for r in rows if r["series"] == who and r["spp"] == spp]
            pts.append((spp, statistics.median([r["rel_mse_own_ref"] for r in sel]),
                        statistics.median([r["seconds"] for r in sel])))
        if len(pts) > 1:
            print("  %-20s relMSE ~ spp^%.3f; %.4g s per spp at %d spp" % (
                who, ct.fit_slope([p[0] for p in pts], [p[1] for p in pts]), pts[-1][2] / pts[-1][0],
                pts[-1][0]))
    print("\nAgreement of the references: mean candela / Mitsuba over the frame %s (RGB), %.3f–%.3f over 4×4 tiles; "
          "relMSE of Mitsuba's reference against candela's %.4g" % (
              ", ".join("%.4f" % v for v in frame), tile_lo, tile_hi, floor))


def record(args, rows, series, ladder, width, height, mi, devices):
    """--record: at the top rung, candela's samples per second over Mitsuba's (median seconds) and its efficiency
    over Mitsuba's (paired by seed), with the first of --samplers."""
    top, who = ladder[-1], series[0]
    mine = [r for r in rows if r["series"] == who and r["spp"] == top]
    theirs = {r["repeat"]: r for r in rows if r["series"] == "mitsuba" and r["spp"] == top}
    sps = lambda pts: top * width * height / statistics.median([r["seconds"] for r in pts]) * 1e-6  # noqa: E731
    ratios = [r["efficiency_own_ref"] / theirs[r["repeat"]]["efficiency_own_ref"] for r in mine if r["repeat"] in theirs]
    if not mine or not ratios:
        print("note: nothing to record: no paired renders at the top rung", file=sys.stderr)
        return
    a, b = sps(mine), sps(list(theirs.values()))
    figure = "%.2f× (%.2f vs %.2f Msamples/s); %s× Mitsuba's efficiency (%s sampler, %d spp, %dx%d, max depth %d)" % (
        a / b, a, b, equal_time.fmt(statistics.median(ratios), min(ratios), max(ratios), "%.2f"), mine[0]["sampler"],
        top, width, height, args.max_depth)
    host = ", ".join([ct.cpu_description(), devices.get("candela", args.device),
                      "Mitsuba %s %s" % (mi.__version__, mi.variant())])
    ct.record_result(ct.result_key(args.scene, "vs-mitsuba"), figure, ct.command_line(), host)


if __name__ == "__main__":
    sys.exit(main())
