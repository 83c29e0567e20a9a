#!/usr/bin/python3
"""Speed against accuracy for every shipped scene: the charts, tables and commands of docs/figures/charts.md.

  scripts/compare/charts.py [--scenes GLOB_OR_FILE ...] [--only converge,compare,spec] [--resume] [options below]

For each scene (default: every scenes/**/*.gltf, found by glob, so new scenes join on the next run):
  1. a reference: candela on PoCL, --strategy auto, --ref-spp samples with seed --ref-seed (not the ladders'
     seed), and its variance image; cached in build/charts/refs/ under a hash of the scene's files, the kernel
     sources (cl/) and these settings, so reruns reuse it (its spp is in the EXR's candela:spp);
  2. scripts/compare/converge.py against that one reference for each strategy (nee and bsdf always; auto, the default,
     unless the scene sets another default and a test render shows auto is nee there), on PoCL (--pocl-ladder) and rusticl
     (--rusticl-ladder), all with seed --seed; one chart of every series (docs/figures/charts/NAME.png) and one CSV; and on PoCL the
     default strategy with --light-selection power, unless a test render shows it is the light tree's image there;
  3. candela compare NAME --devices pocl,rusticl (build times cold/cached, samples/s, relMSE between the
     devices, z-test verdict); when the verdict is "NOT consistent", where the difference is (largest |z|);
  4. scripts/bench/specialization.sh on this scene alone (specialized against --generic kernels, PoCL).
Writes docs/figures/charts/NAME.{png,csv,json} and regenerates docs/figures/charts.md from every docs/figures/charts/*.json.
Work files: build/charts/NAME/. Needs build/candela (scripts/setup.sh builds it) and Debian's python3-numpy,
python3-openimageio and python3-matplotlib.
"""

import argparse
import csv
import glob
import hashlib
import json
import math
import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import candela_tools as ct  # noqa: E402
import converge  # noqa: E402  (its chart and CSV columns)

ROOT = ct.ROOT
EPSILON = ct.EPSILON
STRATEGY_COLOR = {"nee": "tab:blue", "bsdf": "tab:orange", "auto": "tab:green"}
POWER_COLOR = "tab:purple"  # the default strategy with --light-selection power instead of the light tree
DEVICE_STYLE = {"pocl": "o-", "rusticl": "s--"}
STEPS = ("converge", "compare", "spec")


def log(msg):
    print("[charts %s] %s" % (time.strftime("%H:%M:%S"), msg), file=sys.stderr, flush=True)


def load_average():
    return "%.2f" % ct.load_average()


def rel(path):
    return os.path.relpath(path, ROOT)


def shell_join(cmd):
    out = []
    for c in cmd:
        c = str(c)
        out.append(c if c and all(ch.isalnum() or ch in "-_./=:,+" for ch in c) else "'%s'" % c.replace("'", "'\\''"))
    return " ".join(out)


def run(cmd, env=None, check=True, capture=True):
    p = subprocess.run([str(c) for c in cmd], cwd=ROOT, env=env, text=True,
                       stdout=subprocess.PIPE if capture else None, stderr=subprocess.PIPE if capture else None)
    if check and p.returncode != 0:
        raise RuntimeError("%s failed (exit %d):\n%s%s" % (shell_join(cmd), p.returncode, p.stdout or "",
                                                          (p.stderr or "")[-2000:]))
    return p


# ---- the scene ----

def scene_strings(value):
    if isinstance(value, dict):
        for v in value.values():
            yield from scene_strings(v)
    elif isinstance(value, list):
        for v in value:
            yield from scene_strings(v)
    elif isinstance(value, str):
        yield value


def scene_info(path):
    with open(path) as f:
        gltf = json.load(f)
    scenes = gltf.get("scenes") or [{}]
    scene = scenes[gltf.get("scene", 0)]
    strategy = ((scene.get("extras") or {}).get("candela") or {}).get("strategy") or "auto"
    punctual = sum(1 for n in gltf.get("nodes", []) if "KHR_lights_punctual" in (n.get("extensions") or {}))
    # Files the scene refers to (buffers, images, environment maps, grids): everything that changes its image
    files = [path]
    base = os.path.dirname(path)
    for s in scene_strings(gltf):
        if s and not s.startswith("data:") and len(s) < 400:
            p = os.path.join(base, s)
            if os.path.isfile(p) and p not in files:
                files.append(p)
    return {"default_strategy": strategy, "punctual_lights": punctual, "files": files}


def hash_files(h, paths):
    for p in paths:
        h.update(rel(p).encode() + b"\0")
        with open(p, "rb") as f:
            h.update(hashlib.sha256(f.read()).digest())


def kernel_sources():
    return sorted(glob.glob(os.path.join(ROOT, "cl", "**", "*"), recursive=True))


# ---- images ----

def read_rgb(path):
    return ct.read_rgb(path, "image")


# ---- steps ----

def reference(args, name, scene, info):
    h = hashlib.sha256()
    hash_files(h, info["files"])
    hash_files(h, [p for p in kernel_sources() if os.path.isfile(p)])
    settings = ["--spp", args.ref_spp, "--width", args.width, "--seed", args.ref_seed, "--strategy", "auto",
                "--device", "pocl"] + args.render_args
    h.update(json.dumps([str(s) for s in settings]).encode())
    key = h.hexdigest()[:12]
    refdir = os.path.join(ROOT, "build", "charts", "refs")
    os.makedirs(refdir, exist_ok=True)
    out = os.path.join(refdir, "%s-%s.exr" % (name, key))
    var = os.path.join(refdir, "%s-%s-variance.exr" % (name, key))
    stats = os.path.join(refdir, "%s-%s.json" % (name, key))
    options = ["--variance", var, "-q"] + settings
    if not (os.path.isfile(out) and os.path.isfile(var) and os.path.isfile(stats)):
        log("%s: reference, %s spp (load %s)" % (name, args.ref_spp, load_average()))
        ct.render(scene, out, options, binary=args.candela, stats=stats)
        cached = False
    else:
        cached = True
    st = json.load(open(stats))
    np = ct.numpy_oiio()[0]
    r, meta = read_rgb(out)
    v, _ = read_rgb(var)
    v = np.where(np.isfinite(v), v, 0.0)
    floor = float(np.mean(v / (r * r + EPSILON)))
    return {"path": rel(out), "hash": key, "spp": int(meta.get("spp", args.ref_spp)), "seed": args.ref_seed,
            "strategy": "auto", "device": st.get("device", "pocl"), "seconds": st.get("seconds"),
            "width": r.shape[1], "height": r.shape[0], "noise_floor": floor, "cached": cached,
            "command": "build/candela render " + shell_join([rel(scene), "-o", out, "--variance", var, "--stats", stats,
                                                             "-q"] + settings).replace(ROOT + "/", "")}


def auto_differs(args, name, scene, workdir):
    """Does --strategy auto render differently from nee on this scene? Same seed, small render, on PoCL."""
    imgs = {}
    for s in ("nee", "auto"):
        out = os.path.join(workdir, "auto-check-%s.exr" % s)
        ct.render(scene, out, ["--spp", 4, "--width", 48, "--seed", args.seed, "--strategy", s, "--device",
                                    "pocl", "-q"] + args.render_args, binary=args.candela)
        imgs[s] = read_rgb(out)[0]
    np = ct.numpy_oiio()[0]
    return not np.array_equal(imgs["nee"], imgs["auto"])


def power_differs(args, name, scene, workdir, strategy):
    """Does --light-selection power render differently from the light tree here? Same seed, small render."""
    imgs = {}
    for sel in ("tree", "power"):
        out = os.path.join(workdir, "selection-check-%s.exr" % sel)
        ct.render(scene, out, ["--spp", 4, "--width", 48, "--seed", args.seed, "--strategy", strategy,
                                    "--light-selection", sel, "--device", "pocl", "-q"] + args.render_args,
                  binary=args.candela)
        imgs[sel] = read_rgb(out)[0]
    np = ct.numpy_oiio()[0]
    return not np.array_equal(imgs["tree"], imgs["power"])


def converge_series(args, name, scene, ref, device, strategy, workdir, resume, selection=None):
    ladder = args.pocl_ladder if device == "pocl" else args.rusticl_ladder
    out = os.path.join(workdir, "converge-%s-%s%s.csv" % (device, strategy, "-" + selection if selection else ""))
    cmd = ["scripts/compare/converge.py", rel(scene), "--reference", ref["path"], "--device", device, "--strategy", strategy,
           "--seed", args.seed, "--spp-ladder", ladder, "--csv", out, "--no-blender", "-q"]
    more = args.render_args + (["--light-selection", selection] if selection else [])
    if more:
        cmd += ["--"] + more
    if not (resume and os.path.isfile(out)):
        log("%s: converge %s %s%s, ladder %s (load %s)" % (name, device, strategy,
                                                          ", %s selection" % selection if selection else "",
                                                          ladder, load_average()))
        p = run(cmd)
        slopes = [l for l in p.stdout.splitlines() if "slope" in l]
        if slopes:
            log("  " + slopes[0])
    rows = []
    with open(out) as f:
        for r in csv.DictReader(f):
            for k in ("spp",):
                r[k] = int(r[k])
            for k in ("seconds", "startup_seconds", "rel_mse", "mse", "mae", "efficiency", "samples_per_second"):
                r[k] = float(r[k])
            rows.append(r)
    cmd_text = shell_join(cmd).replace(out, "OUT.csv").replace(ROOT + "/", "")
    return rows, cmd_text


def compare(args, name, scene, workdir, resume):
    js = os.path.join(workdir, "compare.json")
    txt = os.path.join(workdir, "compare.txt")
    keep = os.path.join(workdir, "compare-images")
    cmd = [args.candela, "compare", rel(scene), "--devices", "pocl,rusticl", "--spp", args.compare_spp,
           "--width", args.compare_width, "--json", js, "--keep", keep] + args.render_args
    if not (resume and os.path.isfile(js) and os.path.isfile(txt)):
        log("%s: compare pocl,rusticl (load %s)" % (name, load_average()))
        p = run(cmd, check=False)
        if p.returncode not in (0, 2):
            raise RuntimeError("%s failed (exit %d): %s" % (shell_join(cmd), p.returncode, p.stderr[-2000:]))
        with open(txt, "w") as f:
            f.write(p.stdout)
    with open(js) as f:
        j = json.load(f)
    with open(txt) as f:
        j["text"] = f.read()
    j["command"] = shell_join(["candela"] + cmd[1:]).replace(" --json " + js, "").replace(" --keep " + keep, "")
    if not j["consistent"]:
        j["diagnosis"] = diagnose(keep)
        # Control runs: is it a difference between the devices at all? PoCL against PoCL (seeds 0 and 1, as above),
        # and both devices with the independent sampler (the z-test's variance assumes independent samples)
        j["controls"] = []
        for what, devices, more in (("PoCL against PoCL (seeds 0 and 1)", "pocl,pocl", []),
                                    ("PoCL against rusticl, --sampler independent", "pocl,rusticl",
                                     ["--sampler", "independent"])):
            cjs = os.path.join(workdir, "control-%s%s.json" % (devices.replace(",", "-"), "-".join([""] + more)))
            ccmd = [args.candela, "compare", rel(scene), "--devices", devices, "--spp", args.compare_spp, "--width",
                    args.compare_width, "--no-determinism-check", "-q", "--json", cjs] + more + args.render_args
            if not (resume and os.path.isfile(cjs)):
                log("%s: NOT consistent: control run, %s (load %s)" % (name, what, load_average()))
                p = run(ccmd, check=False)
                if p.returncode not in (0, 2):
                    raise RuntimeError("%s failed: %s" % (shell_join(ccmd), p.stderr[-2000:]))
            with open(cjs) as f:
                cj = json.load(f)
            zt = cj["devices"][1]["against_first"]["z_test"]
            j["controls"].append({"what": what, "consistent": cj["consistent"], "mean_z2": zt["mean_z2"],
                                  "count_abs_z_over_4": zt["count_abs_z_over_4"], "values": zt["values"],
                                  "rel_mse": cj["devices"][1]["against_first"]["rel_mse"],
                                  "command": shell_join(["candela"] + ccmd[1:]).replace(" --json " + cjs, "")})
    return j


def diagnose(keep):
    """Where two devices differ: the largest |z| pixels and the image means, from compare's kept images."""
    np = ct.numpy_oiio()[0]
    exrs = sorted(glob.glob(os.path.join(keep, "**", "*.exr"), recursive=True))
    found = {}
    for p in exrs:
        found[os.path.relpath(p, keep)] = p
    out = {"files": sorted(found)}
    mains = [p for p in sorted(found) if p.endswith("main.exr")]
    variances = [p for p in sorted(found) if "var" in os.path.basename(p) and "main" in os.path.basename(p)]
    if len(mains) < 2 or len(variances) < 2:
        out["note"] = "kept images not found in the expected layout"
        return out
    a, _ = read_rgb(found[mains[0]])
    b, _ = read_rgb(found[mains[1]])
    va, _ = read_rgb(found[variances[0]])
    vb, _ = read_rgb(found[variances[1]])
    s = va + vb
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.where(s > 0, (b - a) / np.sqrt(s), 0.0)
    z = np.where(np.isfinite(z), z, 0.0)
    # Largest |z| per pixel, leaving out values whose variance is at float-rounding level (see below)
    tiny = (s > 0) & (np.sqrt(s) < 1e-6 * np.maximum(np.abs(a), np.abs(b)))
    az = np.where(tiny, 0.0, np.abs(z)).max(axis=2)
    order = np.argsort(az, axis=None)[::-1][:8]
    pix = []
    for idx in order:
        y, x = np.unravel_index(idx, az.shape)
        pix.append({"x": int(x), "y": int(y), "max_abs_z": float(az[y, x]), "a": a[y, x].tolist(),
                    "b": b[y, x].tolist(), "sd_a": np.sqrt(va[y, x]).tolist(), "sd_b": np.sqrt(vb[y, x]).tolist()})
    n = a.shape[0] * a.shape[1]
    # Values whose variance estimate is at the level of float rounding (sd below 1e-6 of the value): a pixel whose
    # samples are all equal up to rounding (a white furnace) has M2 of rounding noise, not zero
    rest = (s > 0) & ~tiny
    out["rounding_variance"] = {"values": int(tiny.sum()), "abs_z_over_4": int((np.abs(z[tiny]) > 4).sum()),
                                "max_abs_diff": float(np.abs(b - a)[tiny].max()) if tiny.any() else 0.0}
    out["other_values"] = {"values": int(rest.sum()), "abs_z_over_4": int((np.abs(z[rest]) > 4).sum()),
                           "mean_z2": float(np.mean(z[rest] ** 2)) if rest.any() else float("nan")}
    out.update({"largest_z": pix, "count_pixels_abs_z_over_4": int((np.abs(z).max(axis=2) > 4).sum()),
                "pixels": int(n),
                "mean_a": a.reshape(-1, 3).mean(axis=0).tolist(), "mean_b": b.reshape(-1, 3).mean(axis=0).tolist(),
                "se_mean_diff": (np.sqrt(s.reshape(-1, 3).sum(axis=0)) / n).tolist()})
    return out


def specialization(args, name, scene, workdir, resume):
    txt = os.path.join(workdir, "specialization.txt")
    cmd = ["scripts/bench/specialization.sh", "pocl", args.spec_rounds, args.spec_width, args.spec_spp]
    if not (resume and os.path.isfile(txt)):
        log("%s: specialization (load %s)" % (name, load_average()))
        env = dict(os.environ, CANDELA_BENCH_SCENES=rel(scene), CANDELA_SKIP_BUILD="1")
        p = run(cmd, env=env)
        with open(txt, "w") as f:
            f.write(p.stdout)
    rows = {}
    ratio = None
    for line in open(txt):
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 6 and cells[1] in ("specialized", "generic"):
            rows[cells[1]] = {"build_cold": float(cells[2]), "first_run_wall": float(cells[3]),
                              "build_cached": float(cells[4]), "msamples_per_cpu_s": float(cells[5])}
        elif len(cells) == 4 and cells[0] == name and cells[1][0].isdigit():
            ratio = {"cold_build_generic_over_specialized": float(cells[1]),
                     "first_run_wall_generic_over_specialized": float(cells[2]),
                     "speed_specialized_over_generic": float(cells[3])}
    return {"kernels": rows, "ratios": ratio, "rounds": args.spec_rounds, "width": args.spec_width,
            "spp": args.spec_spp,
            "command": "CANDELA_BENCH_SCENES=%s %s" % (rel(scene), shell_join(cmd))}


# ---- one scene ----

def series_label(device, strategy, biased, selection=None):
    return "%s %s%s%s" % (device, strategy, ", %s selection" % selection if selection else "",
                          " (biased: delta lights unseen)" if biased else "")


def strategy_text(se):
    return se["strategy"] + (", `--light-selection %s`" % se["selection"] if se.get("selection") else "")


def do_scene(args, scene, name):
    info = scene_info(scene)
    # Work files of these settings (--resume reuses them): build/charts/NAME/KEY/
    key = hashlib.sha256(json.dumps([str(v) for k, v in sorted(vars(args).items())
                                     if k not in ("scenes", "only", "resume", "markdown_only")]).encode()).hexdigest()
    workdir = os.path.join(ROOT, "build", "charts", name, key[:10])
    os.makedirs(workdir, exist_ok=True)
    outdir = os.path.join(ROOT, args.out)
    os.makedirs(outdir, exist_ok=True)
    summary_path = os.path.join(outdir, name + ".json")
    old = json.load(open(summary_path)) if os.path.isfile(summary_path) else {}
    started = time.time()
    summary = {"scene": rel(scene), "name": name, "default_strategy": info["default_strategy"],
               "punctual_lights": info["punctual_lights"], "load_start": load_average(),
               "date": time.strftime("%Y-%m-%d %H:%M")}
    steps = dict(old.get("step_seconds") or {})
    t = time.time()
    ref = reference(args, name, scene, info)
    summary["reference"] = ref
    if not ref["cached"]:
        steps["reference"] = time.time() - t
    if "converge" in args.only:
        t = time.time()
        if info["default_strategy"] == "auto":
            strategies, auto_note = ["auto", "nee", "bsdf"], "auto is the default"
        elif auto_differs(args, name, scene, workdir):
            strategies, auto_note = ["nee", "bsdf", "auto"], "auto differs from nee here (test render, same seed)"
        else:
            strategies, auto_note = ["nee", "bsdf"], ("auto left out: it renders bit-identically to nee here "
                                                      "(48 px, 4 spp, same seed)")
        summary["auto"] = auto_note
        rows, series = [], []
        for device in ("pocl", "rusticl"):
            for strategy in strategies:
                biased = strategy == "bsdf" and info["punctual_lights"] > 0
                pts, cmd = converge_series(args, name, scene, ref, device, strategy, workdir, args.resume)
                label = series_label(device, strategy, biased)
                for r in pts:
                    r.update({"label": label, "selector": device, "color": STRATEGY_COLOR[strategy],
                              "style": DEVICE_STYLE[device], "biased": int(biased)})
                rows += pts
                slope_spp = ct.fit_slope([r["spp"] for r in pts], [r["rel_mse"] for r in pts])
                slope_s = ct.fit_slope([r["seconds"] for r in pts], [r["rel_mse"] for r in pts])
                series.append({"device": device, "strategy": strategy, "biased": biased, "command": cmd,
                               "slope_spp": slope_spp, "slope_seconds": slope_s, "last": pts[-1],
                               "device_name": pts[-1]["device"]})
            if device == "pocl":
                # The light tree (the default selection) against power alone, for the scene's default strategy,
                # where the two render differently (PoCL only: one more ladder)
                default = info["default_strategy"]
                if power_differs(args, name, scene, workdir, default):
                    summary["power"] = ("purple: `--strategy %s --light-selection power` (selection by power alone "
                                        "instead of the light tree)" % default)
                    pts, cmd = converge_series(args, name, scene, ref, device, default, workdir, args.resume,
                                               selection="power")
                    biased = default == "bsdf" and info["punctual_lights"] > 0
                    for r in pts:
                        r.update({"label": series_label(device, default, biased, "power"), "selector": device,
                                  "color": POWER_COLOR, "style": DEVICE_STYLE[device], "biased": int(biased)})
                    rows += pts
                    series.append({"device": device, "strategy": default, "selection": "power", "biased": biased,
                                   "command": cmd, "last": pts[-1], "device_name": pts[-1]["device"],
                                   "slope_spp": ct.fit_slope([r["spp"] for r in pts],
                                                                   [r["rel_mse"] for r in pts]),
                                   "slope_seconds": ct.fit_slope([r["seconds"] for r in pts],
                                                                       [r["rel_mse"] for r in pts])})
                else:
                    summary["power"] = ("`--light-selection power` left out: it renders bit-identically to the "
                                        "light tree here (48 px, 4 spp, same seed)")
        csv_path = os.path.join(outdir, name + ".csv")
        cols = ["selector"] + converge.COLUMNS + ["biased"]
        with open(csv_path, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=cols, extrasaction="ignore")
            w.writeheader()
            for r in rows:
                w.writerow(r)
        title = "%s, %dx%d, against a %d-spp reference (auto, seed %d)" % (
            os.path.basename(scene), ref["width"], ref["height"], ref["spp"], ref["seed"])
        converge.draw_chart(rows, os.path.join(outdir, name + ".png"), title)
        summary["series"] = series
        steps["converge"] = time.time() - t
    elif "series" in old:
        summary["series"], summary["auto"], summary["power"] = old["series"], old.get("auto"), old.get("power")
    if "compare" in args.only:
        t = time.time()
        summary["compare"] = compare(args, name, scene, workdir, args.resume)
        steps["compare"] = time.time() - t if not args.resume else max(time.time() - t, steps.get("compare", 0))
    elif "compare" in old:
        summary["compare"] = old["compare"]
    if "spec" in args.only:
        t = time.time()
        summary["specialization"] = specialization(args, name, scene, workdir, args.resume)
        steps["spec"] = time.time() - t if not args.resume else max(time.time() - t, steps.get("spec", 0))
    elif "specialization" in old:
        summary["specialization"] = old["specialization"]
    summary["step_seconds"] = steps
    summary["load_end"] = load_average()
    summary["wall_seconds"] = time.time() - started
    with open(summary_path, "w") as f:
        json.dump(summary, f, indent=1, sort_keys=True)
    log("%s: done in %.0f s (load %s)" % (name, summary["wall_seconds"], summary["load_end"]))


# ---- Markdown ----

def fmt_g(v, digits=3):
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "-"
    return "%.*g" % (digits, v)


def scene_markdown(s):
    out = []
    name = s["name"]
    out.append("### %s\n" % name)
    ref = s["reference"]
    out.append("`%s`: default strategy `%s`%s. Reference: %d spp, `--strategy auto`, seed %d, PoCL, %dx%d "
               "(its own noise adds about %s to every relMSE below, from its variance image)." % (
                   s["scene"], s["default_strategy"],
                   ", %d punctual (delta) light%s" % (s["punctual_lights"], "s" if s["punctual_lights"] != 1 else "")
                   if s["punctual_lights"] else "", ref["spp"], ref["seed"], ref["width"], ref["height"],
                   fmt_g(ref["noise_floor"], 2)))
    if s.get("series"):
        out[-1] += (" [CSV](charts/%s.csv). %s.%s Efficiency = 1 / (relMSE × seconds) at the last ladder step; "
                   "slope = log–log slope of relMSE against spp over the ladder (−1 for an unbiased estimator)." %
                   (name, s["auto"][0].upper() + s["auto"][1:],
                    " %s%s." % (s["power"][0].upper(), s["power"][1:]) if s.get("power") else ""))
    out.append("")
    if s.get("series"):
        out.append("![%s: relMSE against seconds](charts/%s.png)\n" % (name, name))
        out.append("| device | strategy | spp | render s | relMSE | efficiency | slope | note |")
        out.append("|---|---|---|---|---|---|---|---|")
        best = {}
        for se in s["series"]:
            if not se["biased"]:
                best[se["device"]] = max(best.get(se["device"], 0), se["last"]["efficiency"])
        for se in s["series"]:
            last = se["last"]
            if se["biased"]:
                note = ("**biased**: BSDF sampling never finds the %d punctual light%s ([integrator.md, Strategies](../integrator.md#strategies)); "
                        "converges to another image" % (s["punctual_lights"], "s" if s["punctual_lights"] != 1 else ""))
            elif last["rel_mse"] < 2 * ref["noise_floor"]:
                note = ("within 2× of the reference's own noise (%s): the reference, not this series, limits the "
                        "measurement" % fmt_g(ref["noise_floor"], 2))
                if last["efficiency"] == best.get(se["device"]):
                    note += "; best on %s" % se["device"]
            elif last["efficiency"] == best.get(se["device"]):
                note = "best on %s" % se["device"]
            else:
                note = "%.2g× the best" % (last["efficiency"] / best[se["device"]]) if best.get(se["device"]) else ""
            out.append("| %s | %s | %d | %.3f | %s | %s | %.2f | %s |" % (
                se["device"], strategy_text(se), last["spp"], last["seconds"], fmt_g(last["rel_mse"]),
                fmt_g(last["efficiency"]), se["slope_spp"], note))
        out.append("")
    para = []
    c = s.get("compare")
    if c:
        d0, d1 = c["devices"][0], c["devices"][1]
        zt = d1["against_first"]["z_test"]
        verdict = "statistically consistent" if zt["consistent"] else "**NOT consistent**: " + "; ".join(
            r.replace("|", "\\|") for r in zt["reasons"])
        dev = lambda d: "%s %.3f Msamples/s (build %.2f s cold, %.3f s cached)" % (
            d["selector"], d["samples_per_second"] * 1e-6, d["kernel_build_cold_seconds"],
            d["kernel_build_cached_seconds"])
        para.append("Devices (`candela compare`, %dx%d, %d spp, seeds %d and %d): %s against %s: relMSE %s, mean z² "
                    "%.3f, %.3f%% of values with |z| > 4: %s." % (
                        c["width"], c["height"], c["spp"], d0["seed"], d1["seed"], dev(d1), dev(d0),
                        fmt_g(d1["against_first"]["rel_mse"]), zt["mean_z2"], 100 * zt["frac_abs_z_over_4"], verdict))
        dg = c.get("diagnosis")
        if dg and "rounding_variance" in dg:
            rv, ov = dg["rounding_variance"], dg["other_values"]
            para.append("Where the devices differ (values = pixel-channels, from the kept images): %d of %d pixels have "
                       "a channel with |z| > 4; image means %s (PoCL) and %s (rusticl), standard error of their "
                       "difference %s. %d values have a variance estimate at float-rounding level (sd < 10⁻⁶ of the "
                       "value): %d of them have |z| > 4, with |a − b| at most %s. The other %d values: mean z² %.3f, "
                       "%d with |z| > 4. Largest |z| among those: %s." % (
                           dg["count_pixels_abs_z_over_4"], dg["pixels"], fmt_g(dg["mean_a"][0], 4),
                           fmt_g(dg["mean_b"][0], 4), fmt_g(dg["se_mean_diff"][0], 2), rv["values"],
                           rv["abs_z_over_4"], fmt_g(rv["max_abs_diff"], 2), ov["values"], ov["mean_z2"],
                           ov["abs_z_over_4"], "; ".join("(%d, %d) z %.1f: %s against %s ± %s" % (
                               p["x"], p["y"], p["max_abs_z"], fmt_g(p["a"][0], 3), fmt_g(p["b"][0], 3),
                               fmt_g(math.sqrt(p["sd_a"][0] ** 2 + p["sd_b"][0] ** 2), 2))
                               for p in dg["largest_z"][:3])))
        for ctl in c.get("controls", []):
            para.append("Control, %s: %s (mean z² %.3f, %d of %d values with |z| > 4, relMSE %s): `%s`" % (
                ctl["what"], "statistically consistent" if ctl["consistent"] else "**NOT consistent**",
                ctl["mean_z2"], ctl["count_abs_z_over_4"], ctl["values"], fmt_g(ctl["rel_mse"]), ctl["command"]))
        if "same_seed" in d1:
            ss = d1["same_seed"]
            para.append("Same seed on both: max |a − b| %s, %.1f%% of values bit-identical." % (
                fmt_g(ss["max_abs_diff"], 2), 100 * ss["identical_fraction"]))
    sp = s.get("specialization")
    if sp and sp.get("ratios"):
        k, r = sp["kernels"], sp["ratios"]
        para.append("Specialization (PoCL, `scripts/bench/specialization.sh`, median of %d rounds): cold build %.2f s "
                   "specialized vs %.2f s generic (×%.2f), cached %.3f vs %.3f s; speed %.3f vs %.3f M samples per "
                   "CPU-second: specialized/generic = **%.2f**." % (
                       sp["rounds"], k["specialized"]["build_cold"], k["generic"]["build_cold"],
                       r["cold_build_generic_over_specialized"], k["specialized"]["build_cached"],
                       k["generic"]["build_cached"], k["specialized"]["msamples_per_cpu_s"],
                       k["generic"]["msamples_per_cpu_s"], r["speed_specialized_over_generic"]))
    para.append("Reproduce this scene: `scripts/compare/charts.py --scenes %s` (reference cached in `build/charts/refs/`; "
               "its JSON beside the chart keeps every step's command). Measured %s, load average %s to %s."
                % (s["scene"], s["date"], s["load_start"], s["load_end"]))
    out.append(" ".join(para) + "\n")
    return "\n".join(out)


def overview(summaries):
    out = ["| scene | best on PoCL (efficiency) | best on rusticl | biased series | rusticl / PoCL samples/s | "
           "devices | specialized / generic speed |", "|---|---|---|---|---|---|---|"]
    for s in summaries:
        best = {}
        for se in s.get("series", []):
            if se["biased"]:
                continue
            e = se["last"]["efficiency"]
            if e > best.get(se["device"], ("", 0))[1]:
                best[se["device"]] = (strategy_text(se), e)
        biased = ", ".join("%s %s" % (se["device"], strategy_text(se)) for se in s.get("series", []) if se["biased"])
        c = s.get("compare")
        if c:
            d0, d1 = c["devices"][0], c["devices"][1]
            speed = "%.3f" % (d1["samples_per_second"] / d0["samples_per_second"])
            verdict = "consistent" if c["consistent"] else "**NOT consistent**"
            notes = []
            dg = c.get("diagnosis") or {}
            if dg.get("other_values", {}).get("abs_z_over_4") == 0 and dg.get("rounding_variance", {}).get("values"):
                notes.append("every \\|z\\| > 4 at rounding-level variance")
            for ctl in c.get("controls", []):
                notes.append("%s: %s, relMSE %s" % (
                    "PoCL vs PoCL" if "PoCL against PoCL" in ctl["what"] else "independent sampler",
                    "consistent" if ctl["consistent"] else "not", fmt_g(ctl["rel_mse"], 2)))
            if notes:
                verdict += " (relMSE %s; %s)" % (fmt_g(d1["against_first"]["rel_mse"], 2), "; ".join(notes))
        else:
            speed = verdict = "-"
        sp = (s.get("specialization") or {}).get("ratios")
        out.append("| [%s](#%s) | %s | %s | %s | %s | %s | %s |" % (
            s["name"], s["name"], "%s (%s)" % (best["pocl"][0], fmt_g(best["pocl"][1])) if "pocl" in best else "-",
            "%s (%s)" % (best["rusticl"][0], fmt_g(best["rusticl"][1])) if "rusticl" in best else "-",
            biased or "none", speed, verdict, "%.2f" % sp["speed_specialized_over_generic"] if sp else "-"))
    return "\n".join(out)


def write_markdown(args):
    outdir = os.path.join(ROOT, args.out)
    summaries = []
    for p in sorted(glob.glob(os.path.join(outdir, "*.json"))):
        with open(p) as f:
            s = json.load(f)
        if os.path.isfile(os.path.join(ROOT, s["scene"])):
            summaries.append(s)
    summaries.sort(key=lambda s: s["scene"])
    md = [MD_HEAD % {"pocl": args.pocl_ladder, "rusticl": args.rusticl_ladder}, overview(summaries), ""]
    for s in summaries:
        md.append(scene_markdown(s))
    path = os.path.join(ROOT, args.markdown)
    with open(path, "w") as f:
        f.write("\n".join(md))
    log("wrote %s (%d scenes)" % (rel(path), len(summaries)))


MD_HEAD = """# Speed against accuracy, per scene

Generated by `scripts/compare/charts.py` (do not edit by hand: rerun it). For every shipped scene: relMSE against render
seconds for each strategy on PoCL and rusticl (one chart, all series against one reference), the device comparison
of `candela compare`, and the gain of the specialized kernel over `--generic`.

How the numbers are made ([accuracy.md](../accuracy.md) explains each tool):
- **Reference**: `candela render --strategy auto --seed 1000` on PoCL at high spp, cached in `build/charts/refs/`
  under a hash of the scene's files, `cl/` and the settings. Every series of a scene is measured against this one
  reference. Its own noise (the mean of its variance image over r² + 0.01) is given per scene: it adds to every
  relMSE, so curves flatten when they approach it.
- **Series**: `scripts/compare/converge.py`, seed 0 for every strategy and device (independent of the reference's seed), ladder
  %(pocl)s spp on PoCL and %(rusticl)s on rusticl (about 10–14× slower). Seconds are `candela render`'s render time
  without the kernel build. Colour = strategy (blue `nee`, orange `bsdf`, green `auto`), solid = PoCL, dashed =
  rusticl. `auto` (the default: a choice per vertex and per light) is drawn on every scene that does not set
  another default, else where it renders differently from `nee`. Every series picks its lights through the light
  tree (the default `--light-selection tree`); purple is the scene's default strategy with `--light-selection
  power` (PoCL), drawn where that renders differently from the tree.
- **Biased series** are drawn and listed, not hidden: under `--strategy bsdf` a punctual (delta) light is never
  found by a sampled ray ([integrator.md, Strategies](../integrator.md#strategies)), so on scenes with point, spot or directional lights `bsdf`
  converges to a darker image and its relMSE levels off.
- **Efficiency** = 1 / (relMSE × seconds) at the last step of the ladder: a single ladder of a heavy-tailed
  estimator is noisy ([integrator.md, Strategies](../integrator.md#strategies)), so read factors, not digits.
- **Devices**: `candela compare SCENE --devices pocl,rusticl` (seed 0 on PoCL, 1 on rusticl, z-test per pixel;
  "build cold" has every cache empty).
- **Specialization**: `scripts/bench/specialization.sh` on that scene alone (PoCL, samples per CPU-second, which cancels
  most of the other load on the shared 2-core machine).

[accuracy.md, Per-scene charts](../accuracy.md#per-scene-charts-scriptscomparechartspy) says what the runs show (a device
difference is a bug until shown otherwise). All timings come from the shared
2-core development machine, often while other work ran: the load average is given per scene. Reproduce everything with `scripts/compare/charts.py`, one scene with
`scripts/compare/charts.py --scenes scenes/lights/veach.gltf`.

## Overview
"""


def main():
    ap = argparse.ArgumentParser(prog="scripts/compare/charts.py", description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", nargs="+", default=["scenes/**/*.gltf"], help="scene files or globs")
    ap.add_argument("--only", default=",".join(STEPS), help="steps to run: converge,compare,spec (others keep "
                    "their last results from docs/figures/charts/NAME.json)")
    ap.add_argument("--resume", action="store_true", help="reuse each step's output in build/charts/NAME/ if present")
    ap.add_argument("--markdown-only", action="store_true", help="only regenerate docs/figures/charts.md")
    ap.add_argument("--width", type=int, default=96, help="image width of references and ladders (default 96)")
    ap.add_argument("--ref-spp", type=int, default=1024, help="reference spp (default 1024)")
    ap.add_argument("--ref-seed", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=0, help="seed of every ladder (default 0)")
    ap.add_argument("--pocl-ladder", default="1,2,4,8,16,32,64")
    ap.add_argument("--rusticl-ladder", default="1,2,4,8")
    ap.add_argument("--compare-spp", type=int, default=64)
    ap.add_argument("--compare-width", type=int, default=48)
    ap.add_argument("--spec-rounds", type=int, default=2)
    ap.add_argument("--spec-width", type=int, default=96)
    ap.add_argument("--spec-spp", type=int, default=32)
    ap.add_argument("--out", default="docs/figures/charts")
    ap.add_argument("--markdown", default="docs/figures/charts.md")
    ap.add_argument("--candela", default=os.path.join(ROOT, "build", "candela"))
    ap.add_argument("--render-args", default="", help="more options for every render, e.g. '--max-depth 8'")
    args = ap.parse_args()
    args.render_args = args.render_args.split()
    args.only = [s for s in args.only.split(",") if s]
    for s in args.only:
        if s not in STEPS:
            ap.error("--only takes converge, compare and spec, not '%s'" % s)
    os.environ.setdefault("RUSTICL_ENABLE", "llvmpipe")
    if not args.markdown_only:
        if not os.path.isfile(args.candela):
            sys.exit("candela: error: %s not found: build it first (scripts/setup.sh, or cmake)" % args.candela)
        scenes = []
        for pattern in args.scenes:
            matches = sorted(glob.glob(os.path.join(ROOT, pattern), recursive=True)) if any(
                ch in pattern for ch in "*?[") else [os.path.join(ROOT, pattern)]
            for m in matches:
                if not os.path.isfile(m):
                    sys.exit("candela: error: scene not found: " + pattern)
                if m not in scenes:
                    scenes.append(m)
        names = {}
        for s in scenes:
            n = os.path.basename(s)[:-len(".gltf")]
            if n in names:
                n = os.path.basename(os.path.dirname(s)) + "-" + n
            names[n] = s
        t0 = time.time()
        log("%d scenes, load %s" % (len(names), load_average()))
        for n, s in names.items():
            try:
                do_scene(args, s, n)
            except ct.UserError as e:
                ct.fail("%s: %s" % (n, e))
        log("all scenes in %.0f s" % (time.time() - t0))
    write_markdown(args)


if __name__ == "__main__":
    main()
