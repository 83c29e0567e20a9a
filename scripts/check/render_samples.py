#!/usr/bin/python3
"""Renders glTF assets with candela's default command and checks what a user would see.

    scripts/render-samples [DIR_OR_FILE ...] [--out DIR] [--width 256] [--spp 16]
                           [--device SEL] [--binary PATH] [--sheet OUT.png] [--check]
                           [--timeout SECONDS (per render, default 1800)]
                           [-- more render options]

Without arguments it renders every .gltf/.glb under ../shared/gltf-samples (the Khronos
sample assets beside the checkout). Each asset is rendered as a new user would:
`candela render ASSET -o NAME.png --width W --spp N` (plus NAME.exr and --stats), then once
more at --max-depth 0 under a white background to find where the camera sees the asset rather
than the background. One JSON line per asset goes to OUT/samples.jsonl and a row to OUT/samples.csv:
seconds, triangles, dropped samples, mean / median / 99th-percentile luminance of the linear
image, the fraction of black and of clipped-white 8-bit pixels, the asset's coverage of the
frame, the warnings, and the verdict of the checks below. A contact sheet (--sheet, default
OUT/contact-sheet.png) shows each render beside the asset's own screenshot when
../shared/gltf-samples/_screenshots has one.

Checks (--check makes any failure the exit status): the render succeeds, no sample is
dropped, the asset is not black (median luminance of its pixels > 0.02 or their mean
> 0.05, and at most 70 % of the frame black unless the scene's own lights light it), not a white wall (< 30 % of pixels clipped), and the asset is in view (covers at
least 3 % of the frame, unless its name says it is an empty scene). An empty scene passes when it is
refused with the "no triangles" message: a file with nothing to draw gets a clear error, not a blank image.

Runs with Debian's python3 (python3-numpy, python3-openimageio, python3-pil).
"""

import argparse
import csv
import json
import os
import re
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import candela_tools as ct  # noqa: E402

ROOT = ct.ROOT
samples_folder = ct.samples_folder
SAMPLES = samples_folder()
COLUMNS = ["asset", "ok", "failures", "seconds", "triangles", "dropped_samples", "mean", "median", "p99",
           "black_fraction", "clipped_fraction", "coverage", "warnings", "error"]


fail = ct.fail


def find_assets(paths):
    assets = []
    for p in paths:
        if os.path.isfile(p):
            assets.append(p)
            continue
        if not os.path.isdir(p):
            fail("no such file or folder: " + p)
        for d, dirs, files in os.walk(p):
            dirs[:] = sorted(x for x in dirs if not x.startswith("_"))
            assets += [os.path.join(d, f) for f in sorted(files) if f.lower().endswith((".gltf", ".glb"))]
    return assets


def asset_name(path, base):
    rel = os.path.relpath(path, base) if base and path.startswith(base) else os.path.basename(path)
    return os.path.splitext(os.path.basename(rel))[0]


def luminance(rgb):
    return 0.2126 * rgb[..., 0] + 0.7152 * rgb[..., 1] + 0.0722 * rgb[..., 2]


def read_image(path):
    try:
        return ct.read_image(path)[0][..., :3]
    except ct.UserError:
        return None


def render(binary, asset, outputs, options, timeout):
    """(exit status, stderr, wall seconds) of `candela render ASSET -o OUTPUT... OPTIONS`"""
    start = time.time()
    try:
        r = ct.render(asset, outputs, options, binary=binary, timeout=timeout)
    except ct.RenderError as e:
        return e.returncode, e.stderr, time.time() - start
    return 0, r.stderr, time.time() - start


def measure(asset, name, out, opts, np):
    base = os.path.join(out, name)
    row = {"asset": name, "ok": False, "failures": [], "warnings": []}
    options = ["--width", str(opts.width), "--spp", str(opts.spp), "--stats", base + ".json"] + \
        (["--device", opts.device] if opts.device else []) + opts.extra
    rc, err, seconds = render(opts.binary, asset, [base + ".png", base + ".exr"], options, opts.timeout)
    row["seconds"] = round(seconds, 2)
    row["warnings"] = [l[len("warning: "):] for l in err.splitlines() if l.startswith("warning: ")]
    empty = re.search(r"empty|no_?nodes|no_?scenes?", name, re.I)
    if rc != 0:
        row["error"] = " ".join(l for l in err.splitlines() if "error" in l)[:300] or "exit status %d" % rc
        # A file with nothing to draw is refused with a clear message: what an empty scene should get
        if empty and "no triangles" in err:
            row["ok"] = True
            return row
        row["failures"].append("render failed")
        return row
    with open(base + ".json") as f:
        stats = json.load(f)
    row["triangles"] = stats.get("triangles")
    row["dropped_samples"] = stats.get("dropped_samples", 0)
    img = read_image(base + ".exr")
    png = read_image(base + ".png")
    lum = luminance(img)
    # Where the asset is: at depth 0 under a white background, escaped rays are exactly 1
    # and hits show only emission
    probe = os.path.join(out, name + ".depth0.exr")
    rc0, _, _ = render(opts.binary, asset, probe, ["--width", str(opts.width), "--spp", "4", "--max-depth", "0",
                                                    "--background", "1,1,1", "-q"] +
                       (["--device", opts.device] if opts.device else []) + opts.extra, opts.timeout)
    covered = None
    if rc0 == 0:
        covered = np.abs(read_image(probe) - 1.0).max(axis=-1) > 1e-3
        os.remove(probe)
    row["coverage"] = round(float(covered.mean()), 4) if covered is not None else None
    inside = lum[covered] if covered is not None and covered.any() else lum.ravel()
    row["mean"] = round(float(inside.mean()), 4)
    row["median"] = round(float(np.median(inside)), 4)
    row["p99"] = round(float(np.percentile(inside, 99)), 4)
    row["black_fraction"] = round(float((png.max(axis=-1) < 2.0 / 255).mean()), 4)
    row["clipped_fraction"] = round(float((png.min(axis=-1) > 253.0 / 255).mean()), 4)
    if row["dropped_samples"]:
        row["failures"].append("%d dropped samples" % row["dropped_samples"])
    # A frame mostly black is a failure unless the scene's own lights are meant to light it
    # (then its background is the scene's: black unless it sets one)
    own_lights = "the scene's own lights light it" in err
    if not (row["median"] > 0.02 or row["mean"] > 0.05) or (row["black_fraction"] > 0.7 and not own_lights):
        row["failures"].append("black")
    if row["clipped_fraction"] > 0.3:
        row["failures"].append("white wall")
    if row["coverage"] is not None and row["coverage"] < 0.03 and not empty:
        row["failures"].append("not in view")
    row["ok"] = not row["failures"]
    return row


def norm(s):
    return re.sub(r"[^a-z0-9]", "", s.lower()).replace("khrmaterials", "")


def screenshot_for(name, shots):
    if not os.path.isdir(shots):
        return None
    n = norm(name)
    for f in sorted(os.listdir(shots)):
        s = norm(os.path.splitext(f)[0])
        if s and (s == n or s in n or n in s):
            return os.path.join(shots, f)
    return None


def contact_sheet(rows, out, sheet, shots):
    from PIL import Image, ImageDraw
    cell, label, cols = 200, 14, 3
    n = len(rows)
    width, height = cols * (2 * cell + 8), ((n + cols - 1) // cols) * (cell + label + 4)
    img = Image.new("RGB", (width, max(height, 1)), "white")
    draw = ImageDraw.Draw(img)
    for i, row in enumerate(rows):
        x, y = (i % cols) * (2 * cell + 8), (i // cols) * (cell + label + 4)
        draw.text((x + 2, y), row["asset"] + ("" if row["ok"] else "  [" + ", ".join(row["failures"]) + "]"),
                  fill="black" if row["ok"] else "red")
        for k, path in enumerate([os.path.join(out, row["asset"] + ".png"), screenshot_for(row["asset"], shots)]):
            if path and os.path.exists(path):
                im = Image.open(path).convert("RGB")
                im.thumbnail((cell, cell))
                img.paste(im, (x + k * cell, y + label))
    img.save(sheet)


def main():
    argv = sys.argv[1:]
    extra = []
    if "--" in argv:
        extra = argv[argv.index("--") + 1:]
        argv = argv[:argv.index("--")]
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("paths", nargs="*")
    ap.add_argument("--out", default=None)
    ap.add_argument("--width", type=int, default=256)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--device", default="")
    ap.add_argument("--binary", default=os.path.join(ROOT, "build", "candela"))
    ap.add_argument("--sheet", default=None)
    ap.add_argument("--timeout", type=int, default=1800)  # a cold rusticl kernel build takes up to ~10 min
    ap.add_argument("--check", action="store_true")
    opts = ap.parse_args(argv)
    opts.extra = extra
    try:
        np, _ = ct.numpy_oiio()
    except ct.UserError as e:
        fail(str(e))
    if not os.access(opts.binary, os.X_OK):
        fail("no candela binary at %s (build it, or pass --binary)" % opts.binary)
    paths = opts.paths or [SAMPLES]
    assets = find_assets(paths)
    if not assets:
        fail("no .gltf or .glb files under " + " ".join(paths))
    out = opts.out or tempfile.mkdtemp(prefix="candela-samples-")
    os.makedirs(out, exist_ok=True)
    base = os.path.commonpath([os.path.abspath(p) for p in paths]) if paths else None
    rows = []
    with open(os.path.join(out, "samples.jsonl"), "w") as jl:
        for i, asset in enumerate(assets):
            name = asset_name(os.path.abspath(asset), base)
            if any(r["asset"] == name for r in rows):
                name = os.path.basename(os.path.dirname(asset)) + "-" + name
            row = measure(asset, name, out, opts, np)
            rows.append(row)
            jl.write(json.dumps(row) + "\n")
            print("[%d/%d] %-36s %s %5.1fs %s" % (i + 1, len(assets), name, "ok  " if row["ok"] else "FAIL",
                                                  row["seconds"], ", ".join(row["failures"])), flush=True)
    with open(os.path.join(out, "samples.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS)
        w.writeheader()
        for r in rows:
            w.writerow({k: ("; ".join(r[k]) if isinstance(r.get(k), list) else r.get(k)) for k in COLUMNS})
    sheet = opts.sheet or os.path.join(out, "contact-sheet.png")
    try:
        contact_sheet(rows, out, sheet, os.path.join(SAMPLES, "_screenshots"))
        print("contact sheet: " + sheet)
    except ImportError:
        print("no contact sheet: python3-pil is not installed", file=sys.stderr)
    failed = [r["asset"] for r in rows if not r["ok"]]
    print("%d of %d assets pass; results in %s" % (len(rows) - len(failed), len(rows), out))
    return 1 if failed and opts.check else 0


if __name__ == "__main__":
    sys.exit(main())
