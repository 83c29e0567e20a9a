#!/usr/bin/python3
"""Equal-time error of candela against Blender Cycles: relMSE of each renderer at equal time, and the
efficiency 1/(relMSE x seconds) of each.

  scripts/compare/equal_time.py SCENE --reference REF.exr --cycles-reference CREF.exr [--cycles-reference-spp N]
                     [--ladder 16,32,64,128,256]
                     [--repeats 3] [--repeat-rungs 2] [--max-depth 64] [--device pocl]
                     [--samplers sobol,independent] [--out DIR] [--candela PATH] [--blender PATH] [--record]

REF.exr is candela's high-spp reference (render it with a seed other than the ladder's 0, 1, 2), CREF.exr a
high-spp Cycles render with the same settings (scripts/candela_tools/cycles.py's run_ladder;
--cycles-reference-spp N renders it, seed 1000, when the file is missing). Cycles 3.4 converges to a slightly different image than
candela (emitters emit from both faces, ...), so its error against REF.exr has a bias floor; its error against
CREF.exr is its variance only, the fair efficiency comparison. Both are reported, for both renderers.

The ladder's renders are interleaved (for each rung: each candela sampler and Cycles, the order rotating), the
top --repeat-rungs rungs --repeats times with seeds 0, 1, 2, ... (the machine may be shared: the spread over the
repeats and the load average of each render are recorded). candela's seconds are its --stats `seconds` (kernel
build excluded: an untimed 1-spp warm-up per sampler fills the caches); Cycles' are the time inside
bpy.ops.render.render, including its per-render setup (scene sync, BVH build; setup_seconds, measured by a
1-spp probe in the same process after a warm-up render).

Repeated rungs also give a reference-free error: half the mean over pairs of seeds of (x_i - x_j)^2 / (r^2 + 0.01),
r the renderer's own reference (rel_var_pairs): the variance part of relMSE, without bias or reference noise.

Writes DIR/runs.csv (every render), DIR/summary.csv (median and range per renderer and rung), DIR/chart.png and
prints a markdown table; --record sets the scene's equal-time figure in docs/figures/results.json.
"""

import argparse
import csv
import os
import shutil
import statistics
import sys
import tempfile
import types

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import candela_tools as ct  # noqa: E402
from candela_tools import UserError, cycles  # noqa: E402
import converge  # noqa: E402  (its ladder rung: converge.run_candela)

ROOT = ct.ROOT

RUN_COLUMNS = ["series", "renderer", "sampler", "spp", "repeat", "seed", "seconds", "setup_seconds",
               "startup_seconds", "rel_mse_candela_ref", "rel_mse_own_ref", "efficiency_candela_ref",
               "efficiency_own_ref", "loadavg1"]


loadavg = ct.load_average


def eff(rel, sec):
    return 1.0 / (rel * sec) if rel > 0 and sec > 0 else float("inf")


def main():
    ap = argparse.ArgumentParser(prog="scripts/compare/equal_time.py", description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--reference", required=True, help="candela's high-spp reference (.exr)")
    ap.add_argument("--cycles-reference", required=True, help="Cycles' high-spp reference (.exr), same settings")
    ap.add_argument("--cycles-reference-spp", type=int, metavar="N",
                    help="render --cycles-reference first (N spp, seed 1000, the size of --reference) when it is "
                    "missing")
    ap.add_argument("--ladder", default="16,32,64,128,256")
    ap.add_argument("--repeats", type=int, default=3, help="renders of each of the top rungs (default 3)")
    ap.add_argument("--repeat-rungs", type=int, default=2, help="how many top rungs are repeated (default 2)")
    ap.add_argument("--max-depth", type=int, default=64)
    ap.add_argument("--device", default="pocl")
    ap.add_argument("--samplers", default="sobol,independent", help="candela --sampler values (default both)")
    ap.add_argument("--threads", type=int, help="Cycles' threads (default nproc)")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "figures", "equal-time"))
    ap.add_argument("--candela", default=os.path.join(ROOT, "build", "candela"))
    ap.add_argument("--blender", default=shutil.which("blender") or "")
    ap.add_argument("--record", action="store_true",
                    help="set this scene's equal-time figure in docs/figures/results.json (candela's efficiency over "
                    "Cycles' at the top rung, each against its own reference)")
    args = ap.parse_args()
    try:
        return run(args)
    except UserError as e:
        ct.fail(str(e))


def run(args):
    ladder = ct.parse_ladder(args.ladder, "--ladder")
    if not args.blender:
        raise UserError("Blender is not installed (or pass --blender PATH)")
    ref, _ = ct.read_rgb(args.reference, "reference")
    if args.cycles_reference_spp and not os.path.isfile(args.cycles_reference):
        with tempfile.TemporaryDirectory(prefix="candela-equal-time-") as tmp:
            renders, info = cycles.run_ladder(args.blender, args.scene, [args.cycles_reference_spp], ref.shape[1],
                                              ref.shape[0], args.max_depth, 1000, tmp, args.threads, "reference")
            shutil.copy(renders[0][1], args.cycles_reference)
        print("Cycles reference: %d spp in %.1f s -> %s" % (args.cycles_reference_spp, renders[0][2],
                                                          args.cycles_reference), file=sys.stderr)
    cref, _ = ct.read_rgb(args.cycles_reference, "Cycles reference")
    height, width = ref.shape[0], ref.shape[1]
    if cref.shape != ref.shape:
        raise UserError("the two references differ in size")
    samplers = [s for s in args.samplers.split(",") if s]
    os.makedirs(args.out, exist_ok=True)
    floor = ct.errors(cref, ref)["rel_mse"]
    print("Cycles' reference against candela's: relMSE %.4g (the floor of Cycles' error against candela's "
          "reference)" % floor, file=sys.stderr)

    # (rung, repeat) pairs, each rung's repeats together, low rungs first
    jobs = []
    for i, spp in enumerate(ladder):
        reps = args.repeats if i >= len(ladder) - args.repeat_rungs else 1
        jobs += [(spp, r) for r in range(reps)]
    series = ["candela-" + s for s in samplers] + ["cycles"]
    rows = []
    images = {}  # (series, spp) -> the repeats' images, for the reference-free variance estimate
    hosts = {}  # renderer -> its device or version, for --record
    with tempfile.TemporaryDirectory(prefix="candela-equal-time-") as tmp:
        for k, sampler in enumerate(samplers):  # warm-ups: kernel caches, PoCL's work-group code
            cargs = types.SimpleNamespace(candela=args.candela, scene=args.scene, seed=0, strategy="nee",
                                          device=args.device, max_depth=args.max_depth)
            converge.run_candela(cargs, ["--sampler", sampler], tmp, 1, width, height)
        for n, (spp, rep) in enumerate(jobs):
            order = series[n % len(series):] + series[:n % len(series)]
            for who in order:
                load = loadavg()
                if who == "cycles":
                    renders, info = cycles.run_ladder(args.blender, args.scene, [spp], width, height,
                                                      args.max_depth, rep, tmp, args.threads)
                    _, path, seconds = renders[0]
                    setup = cycles.setup_seconds(info["probe_seconds"], renders)
                    hosts["cycles"] = "Blender %s" % info["blender"]
                    startup = info["startup_seconds"]
                    image, _ = ct.read_rgb(path, "Cycles render")
                    own = ct.errors(image, cref)["rel_mse"]
                    sampler = info["pattern"]
                else:
                    sampler = who[len("candela-"):]
                    cargs = types.SimpleNamespace(candela=args.candela, scene=args.scene, seed=rep, strategy="nee",
                                                  device=args.device, max_depth=args.max_depth)
                    path, stats = converge.run_candela(cargs, ["--sampler", sampler], tmp, spp, width, height)
                    seconds, setup, startup = stats["seconds"], float("nan"), stats["kernel_build_seconds"]
                    hosts["candela"] = stats.get("device", args.device)
                    image, _ = ct.read_rgb(path, "render")
                    own = None
                images.setdefault((who, spp), []).append(image)
                vs_candela = ct.errors(image, ref)["rel_mse"]
                own = vs_candela if own is None else own
                row = {"series": who, "renderer": who.split("-")[0], "sampler": sampler, "spp": spp, "repeat": rep,
                       "seed": rep, "seconds": seconds, "setup_seconds": setup, "startup_seconds": startup,
                       "rel_mse_candela_ref": vs_candela, "rel_mse_own_ref": own,
                       "efficiency_candela_ref": eff(vs_candela, seconds), "efficiency_own_ref": eff(own, seconds),
                       "loadavg1": load}
                rows.append(row)
                print("%-20s %4d spp rep %d  %8.3f s  relMSE %.4g (own ref %.4g)  load %.2f" %
                      (who, spp, rep, seconds, vs_candela, own, load), file=sys.stderr, flush=True)

    with open(os.path.join(args.out, "runs.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=RUN_COLUMNS)
        w.writeheader()
        w.writerows(rows)
    summary = summarize(rows, series, ladder)
    # Reference-free: for renders x_i, x_j of independent seeds, E (x_i - x_j)^2 = 2 Var, so half the mean over the
    # pairs of (x_i - x_j)^2 / (r^2 + epsilon), r the renderer's own reference, is its relMSE without bias and
    # without the reference's noise
    for o in summary:
        imgs = images.get((o["series"], o["spp"]), [])
        r = cref if o["series"] == "cycles" else ref
        pairs = [(a, b) for i, a in enumerate(imgs) for b in imgs[i + 1:]]
        if pairs:
            v = statistics.mean(float(((a - b) ** 2 / (r * r + ct.EPSILON)).mean()) / 2 for a, b in pairs)
            o["rel_var_pairs"], o["efficiency_var_pairs"] = v, eff(v, o["seconds"])
        else:
            o["rel_var_pairs"] = o["efficiency_var_pairs"] = float("nan")
    keys = list(summary[0].keys())
    with open(os.path.join(args.out, "summary.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(summary)
    ratios = report(rows, summary, series, ladder, floor)
    if args.record:
        record(args, ratios, series, ladder, width, height, hosts)
    chart(summary, series, os.path.join(args.out, "chart.png"), "%s, %dx%d, max depth %d" %
          (os.path.basename(args.scene), width, height, args.max_depth), floor)
    print("wrote %s/runs.csv, summary.csv, chart.png" % args.out, file=sys.stderr)
    return 0


def summarize(rows, series, ladder):
    out = []
    for s in series:
        for spp in ladder:
            pts = [r for r in rows if r["series"] == s and r["spp"] == spp]
            if not pts:
                continue
            o = {"series": s, "spp": spp, "renders": len(pts)}
            for key in ("seconds", "setup_seconds", "rel_mse_candela_ref", "rel_mse_own_ref",
                        "efficiency_candela_ref", "efficiency_own_ref", "loadavg1"):
                vals = [r[key] for r in pts]
                o[key] = statistics.median(vals)
                o[key + "_min"] = min(vals)
                o[key + "_max"] = max(vals)
            out.append(o)
    return out


def fmt(med, lo, hi, f="%.4g"):
    if lo == hi:
        return f % med
    return (f + " (" + f + "–" + f + ")") % (med, lo, hi)


def report(rows, summary, series, ladder, floor):
    top = ladder[-1]
    print("\nSlopes (log-log least squares over the ladder's medians):")
    for s in series:
        pts = [o for o in summary if o["series"] == s]
        for ref in ("candela_ref", "own_ref"):
            ys = [o["rel_mse_" + ref] for o in pts]
            print("  %-20s vs %-11s relMSE ~ spp^%.3f, ~ seconds^%.3f" % (
                s, ref, ct.fit_slope([o["spp"] for o in pts], ys),
                ct.fit_slope([o["seconds"] for o in pts], ys)))
    print("\nAt %d spp (median (min–max) over the repeats); Cycles' reference vs candela's: relMSE %.4g\n" %
          (top, floor))
    print("| renderer (sampler) | seconds | Cycles setup s | relMSE vs candela ref | relMSE vs own ref | "
          "relMSE from seed pairs | efficiency vs candela ref | efficiency vs own ref | efficiency from seed pairs "
          "| load |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for o in summary:
        if o["spp"] != top:
            continue
        setup = "–" if o["setup_seconds"] != o["setup_seconds"] else fmt(o["setup_seconds"], o["setup_seconds_min"],
                                                                         o["setup_seconds_max"], "%.3f")
        print("| %s | %s | %s | %s | %s | %.4g | %s | %s | %.1f | %s |" % (
            o["series"], fmt(o["seconds"], o["seconds_min"], o["seconds_max"], "%.3f"), setup,
            fmt(o["rel_mse_candela_ref"], o["rel_mse_candela_ref_min"], o["rel_mse_candela_ref_max"]),
            fmt(o["rel_mse_own_ref"], o["rel_mse_own_ref_min"], o["rel_mse_own_ref_max"]), o["rel_var_pairs"],
            fmt(o["efficiency_candela_ref"], o["efficiency_candela_ref_min"], o["efficiency_candela_ref_max"], "%.1f"),
            fmt(o["efficiency_own_ref"], o["efficiency_own_ref_min"], o["efficiency_own_ref_max"], "%.1f"),
            o["efficiency_var_pairs"], fmt(o["loadavg1"], o["loadavg1_min"], o["loadavg1_max"], "%.2f")))
    print("\nEfficiency ratio candela / Cycles at %d spp, paired by repeat (median (min–max)):" % top)
    cyc = {r["repeat"]: r for r in rows if r["series"] == "cycles" and r["spp"] == top}
    found = {}
    for s in series[:-1]:
        for ref in ("candela_ref", "own_ref"):
            ratios = [r["efficiency_" + ref] / cyc[r["repeat"]]["efficiency_" + ref] for r in rows
                      if r["series"] == s and r["spp"] == top and r["repeat"] in cyc]
            found[(s, ref)] = ratios
            if ratios:
                print("  %-20s vs %-11s %s" % (s, ref, fmt(statistics.median(ratios), min(ratios), max(ratios),
                                                           "%.2f")))
        mine = [o for o in summary if o["series"] == s and o["spp"] == top]
        theirs = [o for o in summary if o["series"] == "cycles" and o["spp"] == top]
        if mine and theirs:
            print("  %-20s from seed pairs %.2f (median seconds)" % (
                s, mine[0]["efficiency_var_pairs"] / theirs[0]["efficiency_var_pairs"]))
    return found


def record(args, ratios, series, ladder, width, height, hosts):
    """--record: candela's efficiency over Cycles' at the top rung, each renderer against its own reference, per
    candela sampler (the first sampler's range leads)."""
    parts = []
    for s in series[:-1]:
        r = ratios.get((s, "own_ref")) or []
        if r:
            parts.append("%s× Cycles' efficiency (%s sampler)" % (
                fmt(statistics.median(r), min(r), max(r), "%.2f"), s[len("candela-"):]))
    if not parts:
        print("note: nothing to record: no paired renders at the top rung", file=sys.stderr)
        return
    figure = "%s; %dx%d, %d spp, max depth %d, each against its own reference" % (
        "; ".join(parts), width, height, ladder[-1], args.max_depth)
    host = ", ".join([ct.cpu_description()] + [hosts[k] for k in ("candela", "cycles") if k in hosts])
    ct.record_result(ct.result_key(args.scene, "equal-time"), figure, ct.command_line(), host)


def chart(summary, series, path, title, floor):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("note: no matplotlib: no chart", file=sys.stderr)
        return
    fig, ax = plt.subplots(figsize=(6.4, 4.4), dpi=90)
    colors = {"candela-sobol": "tab:blue", "candela-independent": "tab:green", "cycles": "tab:red"}
    for s in series:
        pts = [o for o in summary if o["series"] == s]
        xs = [o["seconds"] for o in pts]
        c = colors.get(s)
        ax.loglog(xs, [o["rel_mse_candela_ref"] for o in pts], "o-", color=c, markersize=4,
                  label=s + " vs candela ref")
        if s == "cycles":
            ax.loglog(xs, [o["rel_mse_own_ref"] for o in pts], "s--", color=c, markersize=4,
                      label="cycles vs its own 4096-spp ref")
        for o in (pts[0], pts[-1]):
            ax.annotate(str(o["spp"]), (o["seconds"], o["rel_mse_candela_ref"]), textcoords="offset points",
                        xytext=(4, 4), fontsize=7, color=c)
    ax.axhline(floor, color="tab:red", alpha=0.4, linewidth=1, linestyle=":",
               label="Cycles ref vs candela ref (bias floor)")
    ax.set_xlabel("render seconds (median; candela: kernel build excluded; Cycles: setup included)")
    ax.set_ylabel("relMSE (epsilon 0.01)")
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())
