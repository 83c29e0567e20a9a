#!/usr/bin/python3
"""Time to a clean image: the wall time each renderer and mode needs to reach a stated relMSE.

  scripts/compare/time_to_clean.py SCENE [SCENE ...] [--size 128] [--ref-spp 4096] [--ladder 4,16,64,256]
                     [--adaptive-k 0.8] [--targets 1e-2,1e-3] [--max-depth 16] [--device pocl]
                     [--no-mitsuba] [--no-cycles] [--variant llvm_ad_rgb] [--out DIR] [--chart PATH]
                     [--candela PATH] [--blender PATH]

For each SCENE (image SIZE wide, the height from the camera's aspect ratio, as scripts/compare/vs_mitsuba.py):
candela's uniform reference (--ref-spp, seed 1000, cached in DIR), then each rung N of the ladder (seed 0):
  candela uniform            --spp N (the EXR's noisy.R/G/B of a --denoise render: the same samples)
  candela uniform+denoise    that render's denoised RGB; seconds = its --stats seconds + the denoise time
                             candela prints ("denoised in ...")
  candela adaptive           --spp N --noise-threshold E_N, E_N = K / sqrt(N) (K = --adaptive-k: 0.2 at 16
                             spp, 0.05 at 256), the noisy half of a --denoise render again
  candela adaptive+denoise   its denoised RGB, seconds likewise
  Mitsuba 3                  llvm_ad_rgb path tracer (MIS), independent sampler, the scene converted by
                             scripts/candela_tools/mitsuba.py; seconds of mi.render after a warm-up
  Cycles                     Debian's Blender (scripts/candela_tools/cycles.py's settings; its seconds inside
                             bpy.ops.render.render, scene sync included; no denoiser in Blender 3.4's build)
candela's seconds exclude the kernel build (an untimed warm-up per kernel fills the caches). relMSE
(scripts/compare/relmse.py's, epsilon 0.01): candela's modes against candela's reference; Mitsuba and Cycles
against candela's reference (their bias included) and against their own reference (--ref-spp, seed 1000:
variance only). The reference's own noise, about relMSE(1 spp) / ref-spp, is a floor no render goes under.

The figure of merit: the seconds to reach each of --targets, interpolated log-log between the two rungs that
straddle it ("≤ t" when the first rung is already below it, "not reached" beyond the ladder). A renderer that
cannot load a scene gets a row saying so.

Writes DIR/runs.csv (every render), DIR/table.md (the markdown table, also printed) and the chart (--chart,
default DIR/time-to-clean.png: relMSE against seconds, log-log, one panel per scene, one line per renderer
and mode). Runs with Debian's python3 (numpy, OpenImageIO, matplotlib; Mitsuba installed as vs_mitsuba.py's
docstring says).
"""

import argparse
import csv
import math
import os
import shutil
import sys
import tempfile
import types

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import candela_tools as ct  # noqa: E402
from candela_tools import UserError, cycles, mitsuba as mitsuba_scene  # noqa: E402
import denoise  # noqa: E402  (denoise_seconds: the time candela prints)
import vs_mitsuba  # noqa: E402  (image_size, REF_SEED)

ROOT = ct.ROOT
REF_SEED = vs_mitsuba.REF_SEED
COLUMNS = ["scene", "series", "spp", "mean_spp", "threshold", "seconds", "render_seconds", "denoise_seconds",
           "rel_mse", "reference", "loadavg1"]
SERIES = ["candela uniform", "candela adaptive", "candela uniform+denoise", "candela adaptive+denoise",
          "Mitsuba 3", "Mitsuba 3 (own ref)", "Cycles", "Cycles (own ref)"]
STYLE = {"candela uniform": ("tab:blue", "o-"), "candela adaptive": ("tab:green", "o-"),
         "candela uniform+denoise": ("tab:blue", "^--"), "candela adaptive+denoise": ("tab:green", "^--"),
         "Mitsuba 3": ("tab:orange", "s-"), "Mitsuba 3 (own ref)": ("tab:orange", "s:"),
         "Cycles": ("tab:red", "D-"), "Cycles (own ref)": ("tab:red", "D:")}


def main():
    ap = argparse.ArgumentParser(prog="scripts/compare/time_to_clean.py", description=__doc__.split("\n")[0])
    ap.add_argument("scenes", nargs="+", metavar="SCENE")
    ap.add_argument("--size", type=int, default=128, help="image width (default 128)")
    ap.add_argument("--ref-spp", type=int, default=4096, help="spp of the references (default 4096)")
    ap.add_argument("--ladder", default="4,16,64,256", help="sample counts (default 4,16,64,256)")
    ap.add_argument("--adaptive-k", type=float, default=0.8,
                    help="the adaptive rung N gets --noise-threshold K/sqrt(N) (default 0.8)")
    ap.add_argument("--targets", default="1e-2,1e-3", help="relMSE targets (default 1e-2,1e-3)")
    ap.add_argument("--max-depth", type=int, default=16, help="candela's --max-depth (default 16)")
    ap.add_argument("--device", default="pocl")
    ap.add_argument("--no-mitsuba", action="store_true")
    ap.add_argument("--no-cycles", action="store_true")
    ap.add_argument("--variant", default="llvm_ad_rgb", help="Mitsuba variant (default llvm_ad_rgb)")
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "time-to-clean"))
    ap.add_argument("--chart", help="the chart's path (default DIR/time-to-clean.png)")
    ap.add_argument("--candela", default=os.path.join(ROOT, "build", "candela"))
    ap.add_argument("--blender", default=shutil.which("blender") or "")
    args = ap.parse_args()
    try:
        return run(args)
    except UserError as e:
        ct.fail(str(e))


def candela_render(args, scene, tmp, name, spp, seed, width, height, extra=()):
    """(the EXR's path, --stats seconds, the denoise seconds candela printed or 0)"""
    out, stats = os.path.join(tmp, name + ".exr"), os.path.join(tmp, name + ".json")
    opts = ["--spp", spp, "--seed", seed, "--width", width, "--height", height, "--max-depth", args.max_depth,
            "--device", args.device] + list(extra)
    r = ct.render(scene, out, opts, binary=args.candela, stats=stats)
    den = denoise.denoise_seconds(r.stderr) if "--denoise" in extra else 0.0
    return out, r.stats["seconds"], den


def time_to(points, target):
    """Seconds to reach relMSE TARGET along the ladder's (seconds, relMSE) points: log-log interpolation
    between the first straddling pair; (seconds, "≤") when the first point is already below, None beyond."""
    if not points:
        return None
    if points[0][1] <= target:
        return points[0][0], "≤"
    for (s0, e0), (s1, e1) in zip(points, points[1:]):
        if e0 > target >= e1:
            f = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(s0) + f * (math.log(s1) - math.log(s0))), ""
    return None


def run(args):
    ladder = ct.parse_ladder(args.ladder, "--ladder")
    targets = sorted((float(t) for t in args.targets.split(",") if t), reverse=True)
    if not os.path.isfile(args.candela):
        raise UserError("candela not found at %s (build it, or pass --candela PATH)" % args.candela)
    os.makedirs(args.out, exist_ok=True)
    mi = None
    if not args.no_mitsuba:
        try:
            mi = mitsuba_scene.import_mitsuba(args.variant)
        except UserError as e:
            print("note: no Mitsuba: %s" % e, file=sys.stderr)
    blender = None if args.no_cycles else args.blender
    rows, failures, hosts = [], {}, {}
    for scene in args.scenes:
        scene_rows(args, scene, ladder, mi, blender, rows, failures, hosts)
        write_csv(args, rows)  # after each scene: a later failure keeps the earlier ones
    table = report(args, rows, failures, targets, ladder, mi, hosts)
    with open(os.path.join(args.out, "table.md"), "w") as f:
        f.write(table)
    print(table)
    chart(args, rows, targets)
    return 0


def scene_rows(args, scene, ladder, mi, blender, rows, failures, hosts):
    stem = os.path.splitext(os.path.basename(scene))[0]
    try:  # the camera's aspect ratio, read by the Mitsuba converter (glTF JSON only)
        width, height = vs_mitsuba.image_size(types.SimpleNamespace(size=args.size, height=None, scene=scene))
    except (ValueError, UnicodeDecodeError):
        width, height = args.size, args.size
    tag = "%s-%dx%d-d%d-%dspp" % (stem, width, height, args.max_depth, args.ref_spp)

    def add(series, spp, seconds, rel, reference, render_seconds=None, den=0.0, mean_spp=None, threshold=""):
        row = {"scene": stem, "series": series, "spp": spp, "mean_spp": mean_spp if mean_spp else spp,
               "threshold": threshold, "seconds": seconds, "render_seconds": render_seconds or seconds,
               "denoise_seconds": den, "rel_mse": rel, "reference": reference, "loadavg1": ct.load_average()}
        rows.append(row)
        print("%-14s %-26s %5d spp (mean %7.1f)  %8.3f s  relMSE %.4g" % (stem, series, spp, row["mean_spp"],
                                                                          seconds, rel), file=sys.stderr, flush=True)

    with tempfile.TemporaryDirectory(prefix="candela-ttc-") as tmp:
        # candela: warm-ups (both kernels, the denoiser's library), then the reference
        candela_render(args, scene, tmp, "warm", 1, 0, width, height, ["--denoise"])
        candela_render(args, scene, tmp, "warm", 1, 0, width, height,
                       ["--denoise", "--noise-threshold", 0.1, "--aov", "spp"])
        cref_path = os.path.join(args.out, "candela-ref-%s.exr" % tag)
        if not os.path.isfile(cref_path):
            path, seconds, _ = candela_render(args, scene, tmp, "ref", args.ref_spp, REF_SEED, width, height)
            os.replace(path, cref_path)
            print("candela reference: %d spp in %.1f s -> %s" % (args.ref_spp, seconds, cref_path), file=sys.stderr)
        cref, _ = ct.read_rgb(cref_path, "candela reference")
        hosts["candela"] = args.device

        # Mitsuba: converted scene, warm-up, its own reference
        mts = mref = None
        if mi is not None and scene.lower().endswith(".glb"):
            failures[(stem, "Mitsuba 3")] = "scripts/candela_tools/mitsuba.py converts .gltf (JSON), not .glb"
        elif mi is not None:
            try:
                mts = mitsuba_scene.Mitsuba(mi, scene, width, height, args.max_depth, "independent", tmp)
                mts.render(ladder[0], 999)  # Dr.Jit compiles the kernel (the independent sampler reuses it)
                mref_path = os.path.join(args.out, "mitsuba-ref-%s-%s.exr" % (tag, mi.variant()))
                if not os.path.isfile(mref_path):
                    image, seconds = mts.render(args.ref_spp, REF_SEED)
                    mts.write(image, mref_path)
                    print("Mitsuba reference: %d spp in %.1f s" % (args.ref_spp, seconds), file=sys.stderr)
                mref, _ = ct.read_rgb(mref_path, "Mitsuba reference")
                for note in mts.notes:
                    print("Mitsuba scene conversion (%s): %s" % (stem, note), file=sys.stderr)
            except Exception as e:  # the conversion or Mitsuba's loader refused the scene
                failures[(stem, "Mitsuba 3")] = str(e).strip().splitlines()[-1][:160] if str(e).strip() else repr(e)
                mts = None

        for spp in ladder:
            threshold = round(args.adaptive_k / math.sqrt(spp), 4)
            for mode, extra in (("uniform", []), ("adaptive", ["--noise-threshold", threshold, "--aov", "spp"])):
                path, seconds, den = candela_render(args, scene, tmp, "%s-%d" % (mode, spp), spp, 0, width, height,
                                                    ["--denoise"] + extra)
                noisy = ct.read_channels(path, ["noisy.R", "noisy.G", "noisy.B"])
                clean = ct.read_channels(path, "RGB")
                mean_spp = float(ct.read_channels(path, ["spp.Y"]).mean()) if mode == "adaptive" else spp
                th = threshold if mode == "adaptive" else ""
                add("candela " + mode, spp, seconds, ct.rel_mse(noisy, cref), "candela", mean_spp=mean_spp,
                    threshold=th)
                add("candela %s+denoise" % mode, spp, seconds + den, ct.rel_mse(clean, cref), "candela",
                    render_seconds=seconds, den=den, mean_spp=mean_spp, threshold=th)
            if mts is not None:
                image, seconds = mts.render(spp, 0)
                add("Mitsuba 3", spp, seconds, ct.rel_mse(image, cref), "candela")
                add("Mitsuba 3 (own ref)", spp, seconds, ct.rel_mse(image, mref), "own")
        if mts is not None:
            hosts["mitsuba"] = "Mitsuba %s %s" % (mi.__version__, mi.variant())

        if blender:
            try:
                cyref_path = os.path.join(args.out, "cycles-ref-%s.exr" % tag)
                if not os.path.isfile(cyref_path):
                    renders, _ = cycles.run_ladder(blender, scene, [args.ref_spp], width, height, args.max_depth,
                                                   REF_SEED, tmp, tag="cycles-ref")
                    shutil.copy(renders[0][1], cyref_path)
                    print("Cycles reference: %d spp in %.1f s" % (args.ref_spp, renders[0][2]), file=sys.stderr)
                cyref, _ = ct.read_rgb(cyref_path, "Cycles reference")
                renders, info = cycles.run_ladder(blender, scene, ladder, width, height, args.max_depth, 0, tmp)
                hosts["cycles"] = "Blender %s" % info["blender"]
                for spp, path, seconds in renders:
                    image, _ = ct.read_rgb(path, "Cycles render")
                    add("Cycles", spp, seconds, ct.rel_mse(image, cref), "candela")
                    add("Cycles (own ref)", spp, seconds, ct.rel_mse(image, cyref), "own")
            except UserError as e:
                lines = str(e).strip().splitlines()
                errs = [l for l in lines if l.startswith("Error:")]  # Blender's own reason, e.g. no camera
                failures[(stem, "Cycles")] = (errs or lines)[0 if errs else -1][:160]


def write_csv(args, rows):
    with open(os.path.join(args.out, "runs.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS)
        w.writeheader()
        w.writerows(rows)


def curve(rows, scene, series):
    """(seconds, relMSE) of the series' rungs, in ladder order"""
    pts = sorted((r["spp"], r["seconds"], r["rel_mse"]) for r in rows if r["scene"] == scene and r["series"] == series)
    return [(s, e) for _, s, e in pts]


def report(args, rows, failures, targets, ladder, mi, hosts):
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    head = ["scene", "renderer, mode"] + ["s to relMSE %g" % t for t in targets] + \
        ["relMSE at %d spp (s)" % ladder[-1]]
    lines = ["%s; %d px wide, ladder %s spp, max depth %d, references %d spp; %s" % (
        ct.cpu_description(), args.size, ",".join(map(str, ladder)), args.max_depth, args.ref_spp,
        ", ".join(hosts[k] for k in ("candela", "mitsuba", "cycles") if k in hosts)), "",
        "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for scene in scenes:
        for series in SERIES:
            pts = curve(rows, scene, series)
            base = series.split(" (")[0]
            if not pts:
                why = failures.get((scene, base))
                if why and series == base:
                    lines.append("| %s | %s | cannot load: %s |" % (scene, series, why.replace("|", "/")) +
                                 " |" * len(targets))
                continue
            cells = []
            for t in targets:
                hit = time_to(pts, t)
                cells.append("not reached" if hit is None else "%s%.2f" % (hit[1], hit[0]))
            top = [r for r in rows if r["scene"] == scene and r["series"] == series and r["spp"] == ladder[-1]]
            last = "%.3g (%.2f s)" % (top[0]["rel_mse"], top[0]["seconds"]) if top else ""
            lines.append("| %s | %s | %s | %s |" % (scene, series, " | ".join(cells), last))
    return "\n".join(lines) + "\n"


def chart(args, rows, targets):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("note: no matplotlib: no chart", file=sys.stderr)
        return
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    fig, axes = plt.subplots(1, len(scenes), figsize=(3.3 * len(scenes), 3.3), dpi=80, squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        for series in SERIES:
            pts = curve(rows, scene, series)
            if pts:
                color, style = STYLE[series]
                ax.loglog([p[0] for p in pts], [p[1] for p in pts], style, color=color, markersize=3, linewidth=1,
                          label=series)
        for t in targets:
            ax.axhline(t, color="gray", linewidth=0.6, alpha=0.5)
        ax.set_title(scene, fontsize=8)
        ax.set_xlabel("seconds", fontsize=7)
        ax.tick_params(labelsize=6)
        ax.grid(True, which="both", alpha=0.2)
    axes[0][0].set_ylabel("relMSE vs candela's reference", fontsize=7)
    found = {}
    for ax in axes[0]:
        for h, l in zip(*ax.get_legend_handles_labels()):
            found.setdefault(l, h)
    labels = [s for s in SERIES if s in found]
    handles = [found[s] for s in labels]
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=6, frameon=False)
    fig.tight_layout(rect=(0, 0.12, 1, 1))
    path = args.chart or os.path.join(args.out, "time-to-clean.png")
    fig.savefig(path)
    plt.close(fig)
    print("wrote %s, %s" % (os.path.join(args.out, "runs.csv"), path), file=sys.stderr)


if __name__ == "__main__":
    sys.exit(main())
