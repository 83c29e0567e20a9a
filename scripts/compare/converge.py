#!/usr/bin/python3
"""Convergence of candela (and Cycles, when Blender is installed) against a reference.

Renders SCENE at each sample count of a ladder with `candela render --stats`, measures
the error of each image against REF.exr and the render time (kernel build excluded, and
reported apart), and writes a CSV and a log-log chart of error against seconds.

  scripts/compare/converge.py SCENE --reference REF.exr [--spp-ladder 1,2,4,...] [--strategy S]
                   [--device SEL] [--seed S] [--max-depth D] [--csv OUT.csv] [--chart OUT.png|OUT.svg]
                   [--blender PATH | --no-blender] [--threads N] [-- more render options]

The image size is the reference's. Errors, over all pixels and channels (x the render,
r the reference):
  rel_mse = mean (x - r)^2 / (r^2 + 0.01)     (the main metric)
  mse     = mean (x - r)^2
  mae     = mean |x - r|
  efficiency = 1 / (rel_mse * seconds)
With Blender installed, Cycles renders the same ladder (one Blender process: an untimed 1-spp
warm-up, a 1-spp probe of the setup every render repeats, then each rung) with the settings of
scripts/candela_tools/cycles.py, the ones scripts/compare/vs_cycles.py uses: CPU, --threads (default nproc) fixed,
adaptive sampling, denoising and clamping off, every bounce limit = --max-depth (default
candela's, 16; a --max-depth among the options after -- counts too), filter glossy 0, caustics on,
a 1 px box filter, persistent data off, seed --seed, Standard view, a black world unless the
glTF's extras.candela set a background or environment. Cycles' seconds are the time inside
bpy.ops.render.render: its samples plus its scene sync and BVH build (printed as "setup");
startup_seconds is the process's start, the glTF import and the warm-up.
CSV columns: see COLUMNS. Runs with Debian's python3 (python3-numpy, python3-openimageio,
and python3-matplotlib for --chart; scripts/setup.sh installs them).
"""

import argparse
import csv
import os
import shutil
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import candela_tools as ct  # noqa: E402
from candela_tools import UserError, cycles  # noqa: E402

COLUMNS = ["renderer", "device", "strategy", "spp", "seconds", "startup_seconds", "rel_mse", "mse", "mae",
           "efficiency", "samples_per_second"]
EPSILON = ct.EPSILON
CANDELA_DEFAULT_MAX_DEPTH = 16  # candela render's --max-depth default (host/app/render_command.hpp): Cycles' bounces without --max-depth
ROOT = ct.ROOT


def run_candela(args, extra, tmp, spp, width, height):
    """One rung: `candela render` of args.scene at SPP with args' seed, strategy, device and max depth, then EXTRA;
    returns (the image's path, its --stats)."""
    out = os.path.join(tmp, "candela-%d.exr" % spp)
    stats = os.path.join(tmp, "candela-%d.json" % spp)
    if args.max_depth is not None:
        extra = ["--max-depth", str(args.max_depth)] + list(extra)
    options = ["--spp", spp, "--width", width, "--height", height, "--seed", args.seed, "--strategy", args.strategy,
               "-q"]
    if args.device:
        options += ["--device", args.device]
    r = ct.render(args.scene, out, options + list(extra), binary=args.candela, stats=stats)
    return out, r.stats


def series_of(rows):
    """The rows grouped into series, in order of appearance: by row["label"] when the rows have one (scripts/compare/charts.py
    draws several devices and strategies on one chart), else by renderer."""
    groups = {}
    for r in rows:
        groups.setdefault(r.get("label") or r["renderer"], []).append(r)
    return list(groups.items())


def draw_chart(rows, path, title):
    """relMSE against seconds, log-log, one curve per series with a dotted slope -1 line through its middle point.
    Rows may carry "label", "color" and "style" (a matplotlib format such as "o-")."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise UserError("--chart needs matplotlib (Debian: python3-matplotlib; run with /usr/bin/python3)")
    fig, ax = plt.subplots(figsize=(6.4, 4.4), dpi=100)
    groups = series_of(rows)
    several = len(groups) > 2
    for key, pts in groups:
        first = pts[0]
        style = first.get("style") or ("s-" if first["renderer"] == "cycles" else "o-")
        xs = [r["seconds"] for r in pts]
        ys = [r["rel_mse"] for r in pts]
        if first.get("label"):
            label = first["label"]
        else:
            label = "%s (%s, %s)" % (first["renderer"], first["device"], first["strategy"])
        if first["renderer"] == "cycles":
            label += ", start-up %.1f s not shown" % first["startup_seconds"]
        kw = {"color": first["color"]} if first.get("color") else {}
        ax.loglog(xs, ys, style, label=label, markersize=4 if several else 6, **kw)
        color = ax.lines[-1].get_color()
        # spp next to the points (only the first and last of each curve when there are several curves)
        for r in (pts if not several else [pts[0], pts[-1]]):
            ax.annotate(str(r["spp"]), (r["seconds"], r["rel_mse"]), textcoords="offset points", xytext=(4, 4),
                        fontsize=7, color=color if several else "black")
        # Reference line of slope -1 (error proportional to 1 / time) through the middle point
        # (not for a series marked biased, which levels off by design)
        if first.get("biased") in (1, "1", True):
            continue
        mid = pts[len(pts) // 2]
        lo, hi = min(xs), max(xs)
        ax.loglog([lo, hi], [mid["rel_mse"] * mid["seconds"] / lo, mid["rel_mse"] * mid["seconds"] / hi], ":",
                  color=color, alpha=0.6, linewidth=1,
                  label=None if several else "slope -1 (relMSE ~ 1/time)")
    if several:
        ax.plot([], [], ":", color="gray", label="dotted: slope -1 (relMSE ~ 1/time)")
    ax.set_xlabel("render seconds (kernel build excluded)")
    ax.set_ylabel("relMSE (epsilon = %g)" % EPSILON)
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(
        prog="scripts/compare/converge.py",
        description="Error against a reference at increasing sample counts: CSV and log-log chart.",
        epilog="Options after -- go to every candela render (e.g. -- --filter tent); of them only --max-depth reaches "
               "Cycles too. Cycles' settings: scripts/candela_tools/cycles.py.")
    parser.add_argument("scene")
    parser.add_argument("--reference", required=True, help="reference image (.exr); sets the image size")
    parser.add_argument("--spp-ladder", default="1,2,4,8,16,32,64", help="sample counts (default 1,2,...,64)")
    parser.add_argument("--strategy", default="auto", help="candela --strategy (default auto)")
    parser.add_argument("--device", default="", help="candela --device selector")
    parser.add_argument("--seed", type=int, default=0, help="seed of the ladder's renders, candela's and Cycles' "
                        "(default 0)")
    parser.add_argument("--max-depth", type=int, metavar="D",
                        help="candela --max-depth, and Cycles' bounce limits (default: candela's default, %d; "
                        "a --max-depth after -- is passed to Cycles too)" % CANDELA_DEFAULT_MAX_DEPTH)
    parser.add_argument("--threads", type=int, help="Cycles' threads (default nproc)")
    parser.add_argument("--width", type=int, help="image width: must be the reference's (the default)")
    parser.add_argument("--height", type=int, help="image height: must be the reference's (the default)")
    parser.add_argument("--csv", help="write the table here")
    parser.add_argument("--chart", help="write a log-log chart (.png or .svg) here")
    parser.add_argument("--candela", default=os.path.join(ROOT, "build", "candela"), help="candela executable")
    parser.add_argument("--blender", default=shutil.which("blender") or "",
                        help="Blender executable for the Cycles curve (default: blender on PATH)")
    parser.add_argument("--no-blender", action="store_true", help="leave Cycles out even when Blender is installed")
    parser.add_argument("-q", "--quiet", action="store_true", help="no progress lines")
    argv = sys.argv[1:]
    extra = []
    if "--" in argv:
        extra = argv[argv.index("--") + 1:]
        argv = argv[:argv.index("--")]
    args = parser.parse_args(argv)
    try:
        return converge(args, extra)
    except UserError as e:
        ct.fail(str(e))


def converge(args, extra):
    ladder = ct.parse_ladder(args.spp_ladder)
    if not os.path.isfile(args.scene):
        raise UserError("scene file not found: " + args.scene)
    if not os.path.isfile(args.candela):
        raise UserError("candela executable not found: %s (build it, or pass --candela)" % args.candela)
    if args.chart and os.path.splitext(args.chart)[1].lower() not in (".png", ".svg"):
        raise UserError("--chart must end in .png or .svg: " + args.chart)
    reference, ref_meta = ct.read_rgb(args.reference, "reference")
    height, width = reference.shape[0], reference.shape[1]
    if (args.width or width) != width or (args.height or height) != height:
        raise UserError("size mismatch: the render would be %dx%d but the reference %s is %dx%d" %
                        (args.width or width, args.height or height, args.reference, width, height))
    if ref_meta.get("seed") == str(args.seed) and os.path.abspath(ref_meta.get("scene", "")) == os.path.abspath(args.scene):
        print("warning: the reference was rendered with the ladder's seed %d: its samples include the ladder's, "
              "which hides their error; render it with another --seed" % args.seed, file=sys.stderr)
    for o in ("--width", "--height", "--spp", "--seed", "--strategy", "--device", "-o", "--stats", "--time"):
        if any(e == o or e.startswith(o + "=") for e in extra):
            raise UserError("%s is set by scripts/compare/converge.py; pass it as its own option (the size is the reference's)" % o)

    max_depth = resolve_max_depth(args.max_depth, extra)
    rows = []
    with tempfile.TemporaryDirectory(prefix="candela-converge-") as tmp:
        # Warm-up: the first build (and any compilation a driver defers to its first launch)
        # is not timed with the ladder; its kernel build is reported apart
        _, warm = run_candela(args, extra, tmp, 1, width, height)
        device = warm.get("device", args.device)
        if not args.quiet:
            print("candela on %s: kernel build %.2f s%s (excluded from the render seconds)" %
                  (device, warm["kernel_build_seconds"], " (cached)" if warm.get("kernel_from_cache") else ""),
                  file=sys.stderr)
        for spp in ladder:
            out, stats = run_candela(args, extra, tmp, spp, width, height)
            image, _ = ct.read_rgb(out, "render")
            e = ct.errors(image, reference)
            rows.append(row("candela", device, args.strategy, spp, stats["seconds"], stats["kernel_build_seconds"],
                            e, stats["samples_per_second"]))
            if not args.quiet:
                print("candela %6d spp %9.3f s  relMSE %.4g" % (spp, stats["seconds"], e["rel_mse"]), file=sys.stderr)
        if args.blender and not args.no_blender:
            renders, info = cycles.run_ladder(args.blender, args.scene, ladder, width, height, max_depth, args.seed,
                                              tmp, args.threads)
            setup = cycles.setup_seconds(info["probe_seconds"], renders)
            if not args.quiet:
                print("cycles (Blender %s, pattern %s, max depth %d): start-up %.2f s, setup %.3f s of every render "
                      "(scene sync and BVH build: included in its seconds)" %
                      (info["blender"], info["pattern"], max_depth, info["startup_seconds"], setup), file=sys.stderr)
            for spp, out, seconds in renders:
                image, _ = ct.read_rgb(out, "Cycles render")
                e = ct.errors(image, reference)
                rows.append(row("cycles", "blender", "cycles", spp, seconds, info["startup_seconds"], e,
                                spp * width * height / max(seconds, 1e-9)))
                if not args.quiet:
                    print("cycles  %6d spp %9.3f s  relMSE %.4g" % (spp, seconds, e["rel_mse"]), file=sys.stderr)
        elif not args.no_blender:
            print("note: blender is not installed: no Cycles curve (install Blender or pass --blender PATH)",
                  file=sys.stderr)

    for renderer in ("candela", "cycles"):
        pts = [r for r in rows if r["renderer"] == renderer]
        if len(pts) >= 2:
            s_spp = ct.fit_slope([r["spp"] for r in pts], [r["rel_mse"] for r in pts])
            s_time = ct.fit_slope([r["seconds"] for r in pts], [r["rel_mse"] for r in pts])
            print("%s: relMSE slope %.3f against spp, %.3f against seconds (log-log; -1 is the Monte Carlo rate)" %
                  (renderer, s_spp, s_time))
    print("%-8s %7s %10s %10s %11s %11s %11s %11s" % ("renderer", "spp", "seconds", "startup", "relMSE", "MSE", "MAE",
                                                      "efficiency"))
    for r in rows:
        print("%-8s %7d %10.4f %10.3f %11.4g %11.4g %11.4g %11.4g" % (r["renderer"], r["spp"], r["seconds"],
                                                                      r["startup_seconds"], r["rel_mse"], r["mse"],
                                                                      r["mae"], r["efficiency"]))
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=COLUMNS)
            w.writeheader()
            for r in rows:
                w.writerow(r)
        print("wrote " + args.csv)
    if args.chart:
        title = "%s, %dx%d, against %s" % (os.path.basename(args.scene), width, height,
                                           os.path.basename(args.reference))
        draw_chart(rows, args.chart, title)
        print("wrote " + args.chart)
    return 0


def resolve_max_depth(option, extra):
    """The max depth Cycles gets: --max-depth, else a --max-depth among the candela options after --, else
    candela's default."""
    passed = None
    for i, e in enumerate(extra):
        if e == "--max-depth" and i + 1 < len(extra):
            passed = extra[i + 1]
        elif e.startswith("--max-depth="):
            passed = e[len("--max-depth="):]
    if passed is not None:
        if option is not None:
            raise UserError("--max-depth is given twice (as an option and after --): give it once")
        try:
            return int(passed)
        except ValueError:
            raise UserError("--max-depth expects a whole number; got '%s'" % passed)
    if option is not None and option < 0:
        raise UserError("--max-depth must be at least 0; got %d" % option)
    return CANDELA_DEFAULT_MAX_DEPTH if option is None else option


def row(renderer, device, strategy, spp, seconds, startup, e, sps):
    return {"renderer": renderer, "device": device, "strategy": strategy, "spp": spp, "seconds": seconds,
            "startup_seconds": startup, "rel_mse": e["rel_mse"], "mse": e["mse"], "mae": e["mae"],
            "efficiency": 1.0 / (e["rel_mse"] * seconds) if e["rel_mse"] > 0 and seconds > 0 else float("inf"),
            "samples_per_second": sps}


if __name__ == "__main__":
    sys.exit(main())
