#!/usr/bin/python3
"""candela against Blender Cycles (CPU), side by side, in one run.

For each glTF scene and each round (the renderers alternate within a round):
  Cycles   one Blender process (blender -b --factory-startup) imports the glTF, sets the
           settings below, renders once at 1 spp untimed (Cycles' first render also initializes
           it, ~0.1 s, which would otherwise inflate the low render) and renders twice, at --cycles-spp-low and --spp samples, timing
           each bpy.ops.render.render; camera samples/s = (spp - spp_low) x pixels /
           (t(spp) - t(spp_low)), so that Blender's start-up, the import, Cycles' scene sync
           and BVH build (done again by every render) cancel out. They are reported apart:
           startup_seconds (process start to the first timed render, warm-up included) and setup_seconds (what the
           first render took beyond its samples).
  candela  for each device: an untimed 1-spp warm-up at the same size (fills the kernel
           caches, and PoCL's lazily built machine code), then `candela render --stats` at the same size, spp
           and depth; samples/s from its `seconds` (kernel build and BVH build excluded, both
           reported: kernel_build_seconds, bvh_build_seconds), with peak_rss_bytes and
           device bytes per triangle.
Output: a table (default), --json (JSON lines, one per render), --csv, or --markdown (the
README's table: median and range over the rounds and the ratios candela / Cycles).

  scripts/compare/vs_cycles.py [--scenes "A B ..."] [--assets "A B ..."] [--size N (512)] [--spp N (16)] [--cycles-spp-low N (4)]
                    [--max-depth D (8)] [--rounds N (3)] [--devices "pocl rusticl"]
                    [--device-spp DEV=N ...] [--json|--csv|--markdown] [--out FILE]
                    [--blender PATH] [--binary PATH] [--threads N] [--images DIR]
  scripts/compare/vs_cycles.py --from FILE.jsonl      (the --markdown table of a saved --out file)

Default scenes: every scenes/**/*.gltf and the million-triangle mesh (build/bench/
suzanne-1m.gltf, written by scripts/scenes/make_blender_mesh.py through Blender; without Blender,
build/bench/mesh-1m.gltf from scripts/scenes/make_bench_mesh.py), then the sample assets.
Sample assets (--assets; default without --scenes: DamagedHelmet, 2CylinderEngine and Fox
from ../shared/gltf-samples, those present): glTF files without lights of their own. Both
renderers see them under a constant white world of radiance 1 and nothing else (candela:
--background 1,1,1 --default-light off; its built-in studio light has no Cycles twin), from
candela's camera (the asset's own, else its automatic framing: the "camera" record of a
1-spp `candela render --stats`, made a Blender camera as in scripts/compare/vs_cycles_assets.py). Blender
imports a Draco-compressed .gltf as a decoded copy (scripts/scenes/decode_draco.py; Debian's package
draco), which candela renders to the same image. rusticl renders at --device-spp
rusticl=2 by default (it is 5-15x slower; its samples/s does not depend on spp).

Cycles settings (Blender 3.4; set in one place, scripts/candela_tools/cycles.py, which scripts/compare/converge.py
uses too): engine CYCLES on the CPU, threads = --threads (default
nproc); samples = spp; adaptive sampling off; denoising off; max_bounces and the diffuse,
glossy, transmission, volume and transparent bounce limits = --max-depth; clamping off
(sample_clamp_direct = sample_clamp_indirect = 0); filter glossy 0; caustics on; pixel
filter BOX of width 1 px (candela's default box filter: one pixel); sampling pattern left
at Blender's default (reported); persistent data off; the glTF's camera; resolution
--size x --size at 100 %. World: black, unless the scene's extras.candela set a background
colour (a constant world of that colour) or an environment map (an Environment Texture of
that file and strength; the rotation conventions are not matched).

Fairness traps (see README, Performance):
- Cycles emits light from both faces of an emissive mesh; candela's glTF emitters emit
  from the front face (both only for doubleSided materials). The light that leaves the
  back of an area light is extra work for Cycles where it reaches geometry.
- candela's participating media (extras.candela.medium, NanoVDB grids) are not imported
  by Blender: on the volume scenes Cycles renders the surfaces only.
- Blender 3.4 has no light tree (3.5 added it): many emitters are sampled by power, as in
  candela's alias table. Blender's glTF importer converts punctual lights' units.
- Cycles' samples/s includes its film and colour management; candela's includes its film.
"""

import argparse
import csv
import glob
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import candela_tools as ct  # noqa: E402
from candela_tools import UserError  # noqa: E402
from candela_tools import cycles as cycles_settings  # noqa: E402  (the Blender-side settings)

ROOT = ct.ROOT

# After cycles_settings' candela_scene(cfg): render at each of cfg["spp"], timing each bpy.ops.render.render
BLENDER_BODY = r'''
scene = candela_scene(cfg)
out = candela_info(scene)
out["warmup_seconds"] = candela_warmup(scene)
out.update({"startup_seconds": time.time() - cfg["t_start"], "renders": []})
for spp in cfg["spp"]:
    scene.cycles.samples = spp
    t = time.time()
    bpy.ops.render.render(write_still=False)
    out["renders"].append({"spp": spp, "seconds": time.time() - t})
if cfg.get("image"):  # after the timing
    scene.render.image_settings.file_format = "PNG"
    bpy.data.images["Render Result"].save_render(cfg["image"])
candela_result(out)
'''


def run_cycles(blender, scene, args, tmp, camera=None, name=None):
    """camera: candela's --stats camera record for a sample asset, which is then lit by a white world; name: the
    image's (default: the scene's file name)"""
    more = {"camera": camera, "background": [1.0, 1.0, 1.0], "environment": None} if camera else {}
    cfg = cycles_settings.config(scene, args.max_depth, args.size, args.size, args.threads,
                                 spp=[args.cycles_spp_low, args.spp], **more)
    if args.images:
        name = name or os.path.splitext(os.path.basename(scene))[0]
        cfg["image"] = os.path.abspath(os.path.join(args.images, name + "-cycles.png"))
    try:
        result, wall, _ = cycles_settings.run_blender(blender, BLENDER_BODY, cfg, tmp, "vs_cycles.py")
    except RuntimeError as e:
        raise UserError("Blender failed on %s: %s" % (scene, e))
    lo, hi = result["renders"]
    pixels = args.size * args.size
    dt = hi["seconds"] - lo["seconds"]
    sps = (hi["spp"] - lo["spp"]) * pixels / dt if dt > 0 else float("nan")
    setup = lo["seconds"] - lo["spp"] * pixels / sps if sps > 0 else float("nan")
    return {"renderer": "cycles", "device": "cpu-%d-threads" % args.threads, "spp": args.spp,
            "spp_low": args.cycles_spp_low, "seconds": round(hi["seconds"], 4), "seconds_low": round(lo["seconds"], 4),
            "samples_per_second": round(sps) if sps == sps else sps, "startup_seconds": round(result["startup_seconds"], 3),
            "warmup_seconds": round(result["warmup_seconds"], 3),
            "setup_seconds": round(setup, 3), "process_seconds": round(wall, 3),
            "sampling_pattern": result["pattern"], "blender": result["blender"]}


def blender_readable(asset, tmp):
    """`asset`, or for a .gltf with Draco-compressed meshes (which Debian's Blender cannot import: its
    importer's decoder library is not packaged) a decoded copy in tmp (scripts/scenes/decode_draco.py)."""
    if not asset.endswith(".gltf"):
        return asset
    with open(asset) as f:
        if "KHR_draco_mesh_compression" not in json.load(f).get("extensionsUsed", []):
            return asset
    folder = tempfile.mkdtemp(prefix="decoded-", dir=tmp)  # one per asset: equal file names do not collide
    out = os.path.join(folder, os.path.basename(asset))
    p = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "scenes", "decode_draco.py"), asset, out],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if p.returncode != 0:
        raise UserError(p.stdout.strip()[-300:])
    return out


def asset_camera(binary, asset, args, tmp):
    """The camera candela renders sample asset `asset` from (its --stats "camera" record)."""
    try:
        r = ct.render(asset, os.path.join(tmp, "camera.exr"),
                      ["--width", args.size, "--height", args.size, "--spp", "1", "--max-depth", args.max_depth, "-q"]
                      + WHITE_WORLD, binary=binary, stats=os.path.join(tmp, "camera.json"))
    except UserError as e:
        raise UserError("candela failed on %s: %s" % (asset, e))
    return r.stats["camera"]


def run_candela(binary, scene, dev, spp, args, tmp, asset=False):
    base = ["--width", args.size, "--height", args.size, "--max-depth", args.max_depth, "--device", dev,
            "-q"] + (WHITE_WORLD if asset else [])
    try:
        # Warm-up: kernel caches (candela's, PoCL's) and PoCL's lazily built work-group code
        # (at the timed render's size: PoCL specializes its work-group code on the launch size)
        ct.render(scene, os.path.join(tmp, "w.exr"), base + ["--spp", "1"], binary=binary)
        r = ct.render(scene, os.path.join(tmp, "c.exr"), base + ["--spp", spp], binary=binary,
                      stats=os.path.join(tmp, "stats.json"))
    except UserError as e:
        return {"renderer": "candela", "device": dev, "error": str(e)}
    wall = r.wall
    if args.images:
        try:
            ct.render(scene, os.path.join(args.images, os.path.splitext(os.path.basename(scene))[0] +
                                          "-candela-%s.png" % dev), base + ["--spp", spp], binary=binary)
        except UserError:
            pass
    s = r.stats
    tris = max(1, s["triangles"])
    return {"renderer": "candela", "device": dev, "spp": spp, "seconds": round(s["seconds"], 4),
            "samples_per_second": round(s["samples_per_second"]), "process_seconds": round(wall, 3),
            "kernel_build_seconds": round(s["kernel_build_seconds"], 3),
            "bvh_build_seconds": round(s["bvh_build_seconds"], 4),
            "bvh_triangles_per_second": round(s["triangles"] / max(s["bvh_build_seconds"], 1e-9)),
            "peak_rss_bytes": s.get("peak_rss_bytes"),
            "peak_rss_bytes_per_triangle": round(s["peak_rss_bytes"] / tris, 1) if "peak_rss_bytes" in s else None,
            "device_bytes_per_triangle": round(s["scene_device_bytes"] / tris, 1),
            "device_name": s["device"], "triangles": s["triangles"]}


SUZANNE = os.path.join("build", "bench", "suzanne-1m.gltf")
SAMPLES = os.path.join(os.path.dirname(ROOT), "shared", "gltf-samples")
DEFAULT_ASSETS = [os.path.join(SAMPLES, "DamagedHelmet", "glTF-Binary", "DamagedHelmet.glb"),
                  os.path.join(SAMPLES, "2CylinderEngine_draco", "2CylinderEngine.gltf"),
                  os.path.join(SAMPLES, "Fox", "Fox.gltf")]
# What a sample asset is rendered under, in candela (the same in Cycles: a constant white world)
WHITE_WORLD = ["--background", "1,1,1", "--default-light", "off"]
FALLBACK_MESH = os.path.join("build", "bench", "mesh-1m.gltf")


def make_mesh(mesh, blender):
    """Writes the generated million-triangle mesh `mesh` (SUZANNE through Blender, or FALLBACK_MESH) if missing."""
    if os.path.isfile(mesh):
        return
    if mesh == SUZANNE:
        if not blender:
            raise SystemExit("candela: error: %s is made by Blender (scripts/scenes/make_blender_mesh.py), which is not "
                             "installed" % mesh)
        subprocess.run([blender, "-b", "--factory-startup", "-noaudio", "--python",
                        os.path.join("scripts", "scenes", "make_blender_mesh.py"), "--", mesh],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    else:
        subprocess.run([sys.executable, os.path.join("scripts", "scenes", "make_bench_mesh.py"), mesh], check=True,
                       stdout=subprocess.DEVNULL)


def default_scenes(blender):
    scenes = sorted(glob.glob(os.path.join("scenes", "**", "*.gltf"), recursive=True))
    mesh = SUZANNE if blender else FALLBACK_MESH
    make_mesh(mesh, blender)
    return scenes + [mesh]


def named_scenes(names, blender):
    """--scenes: the generated meshes are made on first use; any other missing file is an error."""
    for scene in names:
        if os.path.normpath(scene) in (SUZANNE, FALLBACK_MESH):
            make_mesh(os.path.normpath(scene), blender)
        elif not os.path.isfile(scene):
            raise SystemExit("candela: error: scene %s not found" % scene)
    return names


def fmt_range(values, scale=1e-6, digits=3):
    if not values:
        return "–"
    med = statistics.median(values)
    if len(values) == 1:
        return "%.*f" % (digits, med * scale)
    return "%.*f (%.*f–%.*f)" % (digits, med * scale, digits, min(values) * scale, digits, max(values) * scale)


def markdown(rows, devices, args):
    """One line per scene: median (range) samples/s of each renderer and the ratios of the
    per-round values, candela / Cycles."""
    out = []
    head = ["scene", "triangles"] + ["candela %s Msamples/s" % d for d in devices] + ["Cycles Msamples/s"]
    head += ["%s / Cycles" % d for d in devices]
    head += ["BVH build s (Mtri/s)", "peak RSS MB (B/tri, from 100k triangles)"]
    out.append("| " + " | ".join(head) + " |")
    out.append("|" + "---|" * len(head))
    scenes = []
    for r in rows:
        if r["scene"] not in scenes:
            scenes.append(r["scene"])
    for sc in scenes:
        rs = [r for r in rows if r["scene"] == sc and "error" not in r]
        cyc = {r["round"]: r["samples_per_second"] for r in rs if r["renderer"] == "cycles"}
        line = [os.path.splitext(os.path.basename(sc))[0]]
        tris = [r["triangles"] for r in rs if r.get("triangles")]
        line.append(str(tris[0]) if tris else "?")
        for d in devices:
            line.append(fmt_range([r["samples_per_second"] for r in rs if r["renderer"] == "candela" and r["device"] == d]))
        line.append(fmt_range(list(cyc.values())))
        for d in devices:
            ratios = [r["samples_per_second"] / cyc[r["round"]] for r in rs
                      if r["renderer"] == "candela" and r["device"] == d and cyc.get(r["round"])]
            line.append(fmt_range(ratios, 1.0, 2))
        first = [r for r in rs if r["renderer"] == "candela" and r["device"] == devices[0]] if devices else []
        if first:
            line.append(fmt_range([r["bvh_build_seconds"] for r in first], 1.0, 3) + " (%s)" %
                        fmt_range([r["bvh_triangles_per_second"] for r in first], 1e-6, 2))
            rss = [r["peak_rss_bytes"] for r in first if r.get("peak_rss_bytes")]
            per_tri = fmt_range([r["peak_rss_bytes_per_triangle"] for r in first], 1.0, 0)
            big = first[0]["triangles"] >= 100000  # per triangle means nothing for small scenes
            line.append("%s (%s)" % (fmt_range(rss, 2 ** -20, 0), per_tri) if big else fmt_range(rss, 2 ** -20, 0))
        else:
            line += ["–", "–"]
        out.append("| " + " | ".join(line) + " |")
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(prog="scripts/compare/vs_cycles.py", description="candela against Blender Cycles, in one run")
    ap.add_argument("--scenes", help="space-separated glTF files (default: scenes/**/*.gltf and the 1M mesh)")
    ap.add_argument("--assets", help="space-separated sample assets, rendered under a white world from candela's camera "
                                     "(default without --scenes: DamagedHelmet, 2CylinderEngine, Fox)")
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--cycles-spp-low", type=int, default=4)
    ap.add_argument("--max-depth", type=int, default=8)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--devices", default="pocl rusticl")
    ap.add_argument("--device-spp", action="append", default=[], help="DEV=N: spp for one candela device")
    ap.add_argument("--threads", type=int, default=os.cpu_count() or 1, help="Cycles' threads (default nproc)")
    ap.add_argument("--blender", default=shutil.which("blender") or "")
    ap.add_argument("--binary", default=os.path.join("build", "candela"))
    fmt = ap.add_mutually_exclusive_group()
    fmt.add_argument("--json", action="store_true")
    fmt.add_argument("--csv", action="store_true")
    fmt.add_argument("--markdown", action="store_true")
    ap.add_argument("--out", help="append the JSON lines to this file too")
    ap.add_argument("--from", dest="from_file", help="print the table of JSON lines saved with --out, render nothing")
    ap.add_argument("--images", help="also write each renderer's image (PNG, untimed) to this folder, to compare")
    ap.add_argument("--record", action="store_true",
                    help="set each scene's figure against Cycles in docs/figures/results.json (the first device's "
                    "samples/s over Cycles', median over the rounds), and the BVH build of scenes of a million "
                    "triangles or more")
    args = ap.parse_args()
    if args.images:
        args.images = os.path.abspath(args.images)
        os.makedirs(args.images, exist_ok=True)
    if args.from_file:
        with open(args.from_file) as f:
            rows = [json.loads(l) for l in f if l.strip()]
        devices = []
        for r in rows:
            if r["renderer"] == "candela" and r["device"] not in devices:
                devices.append(r["device"])
        print(markdown(rows, devices, args))
        return
    os.chdir(ROOT)
    os.environ.setdefault("RUSTICL_ENABLE", "llvmpipe")
    if not args.blender:
        raise SystemExit("candela: error: Blender is not installed (Debian: apt-get install blender), or pass "
                         "--blender PATH; it is a benchmark-only peer, not a test dependency")
    if not os.path.isfile(args.binary):
        raise SystemExit("candela: error: %s not found: build candela first" % args.binary)
    if args.cycles_spp_low >= args.spp:
        raise SystemExit("candela: error: --cycles-spp-low must be below --spp")
    device_spp = {"rusticl": 2}
    for item in args.device_spp:
        dev, _, n = item.partition("=")
        device_spp[dev] = int(n)
    devices = args.devices.split()
    scenes = named_scenes(args.scenes.split(), args.blender) if args.scenes is not None else default_scenes(args.blender)
    if args.assets is not None:
        assets = args.assets.split()
        for a in assets:
            if not os.path.isfile(a):
                raise SystemExit("candela: error: asset %s not found" % a)
    else:
        assets = [] if args.scenes is not None else [a for a in DEFAULT_ASSETS if os.path.isfile(a)]
    scenes = scenes + [a for a in assets if a not in scenes]
    cameras, readable = {}, {}  # asset: candela's camera, the file Blender imports; once per run
    commit = ct.git_commit()
    load = open("/proc/loadavg").read().split()[:3] if os.path.exists("/proc/loadavg") else []
    rows = []
    out_file = open(args.out, "a") if args.out else None
    with tempfile.TemporaryDirectory(prefix="candela-vs-cycles-") as tmp:
        for rnd in range(args.rounds):
            for scene in scenes:
                # Alternate who goes first from round to round
                order = ["cycles"] + devices if rnd % 2 == 0 else devices + ["cycles"]
                tris = None
                asset = scene in assets
                for who in order:
                    try:
                        if who == "cycles":
                            if asset and scene not in cameras:  # both, or neither on an error
                                camera = asset_camera(args.binary, scene, args, tmp)
                                readable[scene] = blender_readable(scene, tmp)
                                cameras[scene] = camera
                            r = run_cycles(args.blender, readable.get(scene, scene), args, tmp, cameras.get(scene),
                                           os.path.splitext(os.path.basename(scene))[0])
                        else:
                            r = run_candela(args.binary, scene, who, device_spp.get(who, args.spp), args, tmp, asset)
                    except UserError as e:
                        r = {"renderer": who, "device": who, "error": str(e)}
                    r.update({"scene": scene, "round": rnd, "width": args.size, "height": args.size,
                              "world": "white (sample asset)" if asset else "the scene's",
                              "max_depth": args.max_depth, "commit": commit,
                              "loadavg": open("/proc/loadavg").read().split()[0],
                              "time": time.strftime("%Y-%m-%dT%H:%M:%S")})
                    tris = tris or r.get("triangles")
                    rows.append(r)
                    if out_file:
                        out_file.write(json.dumps(r) + "\n")
                        out_file.flush()
                    if args.json:
                        print(json.dumps(r), flush=True)
                    elif not args.csv and not args.markdown:
                        if "error" in r:
                            print("%-22s %-8s error: %s" % (os.path.basename(scene)[:22], r["device"][:8], r["error"][:200]),
                                  flush=True)
                        else:
                            print("%-22s round %d %-8s %4d spp %8.3f Msamples/s" % (
                                os.path.basename(scene)[:22], rnd, r["renderer"] if who == "cycles" else who,
                                r["spp"], r["samples_per_second"] * 1e-6), flush=True)
                for r in rows:
                    if r["scene"] == scene and r.get("triangles") is None and tris:
                        r["triangles"] = tris
    if args.csv:
        keys = []
        for r in rows:
            keys += [k for k in r if k not in keys]
        w = csv.DictWriter(sys.stdout, keys)
        w.writeheader()
        w.writerows(rows)
    elif args.markdown or not args.json:
        print()
        print("Load average at the start: %s; %d rounds; %dx%d, %d spp (rusticl: %s), max depth %d; commit %s" % (
            " ".join(load), args.rounds, args.size, args.size, args.spp, device_spp.get("rusticl", args.spp),
            args.max_depth, commit))
        print(markdown(rows, devices, args))
    if args.record:
        record(rows, devices, args)


DEVICE_NAMES = {"pocl": "PoCL", "rusticl": "rusticl"}


def record(rows, devices, args):
    """--record: per scene, the first device's samples/s over Cycles' (median of the per-round ratios) with both
    medians; for a scene of at least a million triangles also its BVH build rate."""
    if not devices:
        return
    dev = devices[0]
    command = ct.command_line()
    scenes = []
    for r in rows:
        if r["scene"] not in scenes:
            scenes.append(r["scene"])
    for sc in scenes:
        rs = [r for r in rows if r["scene"] == sc and "error" not in r]
        mine = [r for r in rs if r["renderer"] == "candela" and r["device"] == dev]
        cyc = {r["round"]: r for r in rs if r["renderer"] == "cycles"}
        ratios = [r["samples_per_second"] / cyc[r["round"]]["samples_per_second"] for r in mine if r["round"] in cyc]
        if not ratios:
            continue
        a = statistics.median(r["samples_per_second"] for r in mine) * 1e-6
        b = statistics.median(r["samples_per_second"] for r in cyc.values()) * 1e-6
        host = "%s, %s, Blender %s" % (ct.cpu_description(), mine[0].get("device_name", dev),
                                       next(iter(cyc.values())).get("blender", "?"))
        ct.record_result(ct.result_key(sc, "vs-cycles"), "%.2f× (%s %.3f vs Cycles %.3f Msamples/s)" % (
            statistics.median(ratios), DEVICE_NAMES.get(dev, dev), a, b), command, host)
        if mine[0].get("triangles", 0) >= 1000000:
            bvh = statistics.median(r["bvh_build_seconds"] for r in mine)
            ct.record_result(ct.result_key(sc, "bvh-build"), "%.2f M triangles/s (%.3f s, median of %d renders)" % (
                mine[0]["triangles"] / max(bvh, 1e-9) * 1e-6, bvh, len(mine)), command, ct.cpu_description())


if __name__ == "__main__":
    main()
