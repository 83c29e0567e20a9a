#!/usr/bin/python3
"""candela's brightness against Blender Cycles on glTF sample assets, under the same camera and light.

For each asset:
  camera   `candela render ASSET --stats` at 1 spp and the comparison's size gives the camera candela uses (the
           asset's own, else its automatic framing from an elevated three-quarter view): the stats' "camera".
  candela  `candela render ASSET --background 1,1,1 --default-light off` at --spp, --max-depth and the size,
           to an EXR (linear): a constant white world of radiance 1, nothing else.
  Cycles   Blender imports the asset with scripts/candela_tools/cycles.py's settings (box filter of 1 px, no clamping,
           caustics on, bounce limits = --max-depth, Standard view transform), a camera made from candela's record
           (position, orientation, vertical field of view), a constant white world of strength 1, transparent film
           (the alpha is the coverage mask; the white background is put back behind it: RGB + (1 - alpha) x 1), and
           --cycles-spp samples, saved as float EXR.
  compare  over the pixels the object covers (Cycles' alpha > 0.5): the mean linear R, G, B of each renderer and
           their ratios candela / Cycles, and the median over those pixels of the ratio of the pixels' RGB means
           (pixels where Cycles' mean is below 1e-3 are left out of the median). A PNG per asset, candela | Cycles |
           difference (both sRGB-encoded, clipped at 1; the difference of the RGB means x 4: red where candela is
           brighter, blue where darker), goes to --images, with both EXRs (NAME-candela.exr, NAME-cycles.exr; the
           Cycles one with its alpha, over no background).
Output: one JSON line per asset (stdout, and --out FILE appends), then a markdown table (--markdown).

  scripts/compare/vs_cycles_assets.py [--assets "A.glb B.gltf ..."] [--size N (128)] [--spp N (64)] [--cycles-spp N (64)]
                           [--max-depth D (8)] [--device pocl] [--candela-option=ARG ...]
                           [--cycles-gltf-attenuation] [--cycles-neutral-missing-textures]
                           [--images DIR (build/vs-cycles-assets)]
                           [--out FILE] [--markdown] [--blender PATH] [--binary PATH] [--threads N]

Blender 3.4's glTF importer (what Cycles sees): KHR_materials_transmission, _ior, _volume (only with a non-zero
thicknessFactor, as a Volume Absorption of density 1 / attenuationDistance and colour attenuationColor, which is
not glTF's Beer-Lambert law exp(-ln(attenuationColor) / attenuationDistance)), _clearcoat, _specular, _sheen (a
Velvet BSDF *added* to the Principled BSDF, not layered over it), _emissive_strength, _unlit, _texture_transform
and _variants are imported; KHR_materials_anisotropy, _iridescence, _dispersion and KTX2 textures
(KHR_texture_basisu) are not. Cycles' emitters shine from both faces; glTF's from the front (both when
doubleSided). Blender renders an image it cannot load (KTX2) magenta: on a metallicRoughness texture that is
roughness 0, metallic 1, on a normal map a tilted normal; candela ignores such a texture (its factors alone).
Two options take importer mappings out of the comparison: --cycles-gltf-attenuation (Cycles' absorption made
glTF's sigma_a = -ln(attenuationColor) / attenuationDistance) and --cycles-neutral-missing-textures (an image
Blender could not load becomes the glTF's neutral texel, as candela treats it).
"""

import argparse
import json
import os
import shutil
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import candela_tools as ct  # noqa: E402
from candela_tools import UserError  # noqa: E402
from candela_tools import cycles as cycles_settings  # noqa: E402  (the Blender-side settings)

import numpy  # noqa: E402

ROOT = ct.ROOT
SAMPLES = ct.samples_folder()
DEFAULT_ASSETS = [
    SAMPLES + "/DamagedHelmet/glTF-Binary/DamagedHelmet.glb",
    SAMPLES + "/TransmissionRoughnessTest/TransmissionRoughnessTest.glb",
    SAMPLES + "/AttenuationTest/AttenuationTest.glb",
    "/work/shared/gltf-blender-io/roundtrip/19_sheen/19_sheen.gltf",
    SAMPLES + "/ClearCoatTest_glb/ClearCoatTest.glb",
    SAMPLES + "/AnisotropyBarnLamp/AnisotropyBarnLamp.gltf",
]

# After cycles_settings' candela_scene(cfg) (which makes candela's camera and the white world): transparent film,
# one timed render, the float EXR
BLENDER_BODY = r'''
scene = candela_scene(cfg)
if cfg.get("gltf_attenuation"):
    # glTF's Beer-Lambert law: sigma_a = -ln(attenuationColor) / attenuationDistance per channel. The importer sets
    # Volume Absorption's Color = attenuationColor and Density = 1 / attenuationDistance, and Cycles absorbs with
    # sigma_a = Density (1 - Color): rewrite both so that Density (1 - Color) is glTF's sigma_a.
    for m in bpy.data.materials:
        for n in (m.node_tree.nodes if m.use_nodes else []):
            if n.bl_idname != "ShaderNodeVolumeAbsorption" or n.inputs["Color"].is_linked:
                continue
            density = n.inputs["Density"].default_value
            sigma = [-math.log(max(c, 1e-6)) * density for c in n.inputs["Color"].default_value[:3]]
            if max(sigma) > 0:
                n.inputs["Density"].default_value = max(sigma)
                n.inputs["Color"].default_value = [1.0 - x / max(sigma) for x in sigma] + [1.0]
if cfg.get("neutral_missing_textures"):
    # An image Blender could not load (KTX2) renders magenta; candela drops such a texture. Give it the glTF's neutral
    # texel instead: (0.5, 0.5, 1) under a Normal Map node, else white (which leaves the factor alone).
    neutral = {}
    for m in bpy.data.materials:
        for n in (m.node_tree.nodes if m.use_nodes else []):
            if n.bl_idname != "ShaderNodeTexImage" or not n.image or n.image.size[0] > 0:
                continue
            normal = any(l.to_node.bl_idname == "ShaderNodeNormalMap" for o in n.outputs for l in o.links)
            key = (0.5, 0.5, 1.0, 1.0) if normal else (1.0, 1.0, 1.0, 1.0)
            if key not in neutral:
                img = bpy.data.images.new("neutral-%d" % len(neutral), 1, 1, float_buffer=True)
                img.colorspace_settings.name = "Non-Color"
                img.pixels = key
                neutral[key] = img
            n.image = neutral[key]
scene.render.film_transparent = True
scene.cycles.samples = cfg["spp"]
out = candela_info(scene)
out["materials"] = [m.name for m in bpy.data.materials]
t = time.time()
bpy.ops.render.render(write_still=False)
out["seconds"] = time.time() - t
s = scene.render.image_settings
s.file_format = "OPEN_EXR"
s.color_mode = "RGBA"
s.color_depth = "32"
bpy.data.images["Render Result"].save_render(cfg["image"])
candela_result(out)
'''


read_exr = ct.read_channels


def srgb8(linear):
    x = numpy.clip(linear, 0.0, 1.0)
    x = numpy.where(x <= 0.0031308, 12.92 * x, 1.055 * numpy.power(x, 1 / 2.4) - 0.055)
    return (x * 255 + 0.5).astype(numpy.uint8)


def write_png(path, rgb8):
    ct.write_image(path, rgb8, "uint8")


def run_candela(binary, asset, args, tmp):
    """(the camera record, the linear RGB image, candela's render seconds)."""
    base = ["--width", args.size, "--height", args.size, "--device", args.device, "--max-depth", args.max_depth,
            "--background", "1,1,1", "--default-light", "off", "-q"] + args.candela_option
    stats = os.path.join(tmp, "stats.json")
    image = os.path.join(tmp, "candela.exr")
    try:
        camera = ct.render(asset, os.path.join(tmp, "camera.exr"), base + ["--spp", "1"], binary=binary,
                           stats=stats).stats["camera"]
        r = ct.render(asset, image, base + ["--spp", args.spp], binary=binary, stats=stats)
    except UserError as e:
        raise UserError("candela failed on %s: %s" % (asset, e))
    return camera, read_exr(image, "RGB"), r.stats["seconds"], r.notes()


def run_cycles(blender, asset, camera, args, tmp):
    """(linear RGB over the white world, alpha, Cycles' render seconds, Blender's materials)."""
    image = os.path.join(tmp, "cycles.exr")
    cfg = cycles_settings.config(asset, args.max_depth, args.size, args.size, args.threads, spp=args.cycles_spp,
                                 camera=camera, background=[1.0, 1.0, 1.0], environment=None, image=image,
                                 gltf_attenuation=args.cycles_gltf_attenuation,
                                 neutral_missing_textures=args.cycles_neutral_missing_textures)
    try:
        result, _, _ = cycles_settings.run_blender(blender, BLENDER_BODY, cfg, tmp, "vs_cycles_assets.py")
    except RuntimeError as e:
        raise UserError("Blender failed on %s: %s" % (asset, e))
    rgba = read_exr(image, "RGBA")
    alpha = rgba[:, :, 3]
    rgb = rgba[:, :, :3] + (1.0 - alpha)[:, :, None]  # the white world behind the transparent film
    return rgb, alpha, result["seconds"], result


def compare(asset, args, tmp):
    camera, cand, cand_seconds, notes = run_candela(args.binary, asset, args, tmp)
    cyc, alpha, cyc_seconds, info = run_cycles(args.blender, asset, camera, args, tmp)
    mask = alpha > 0.5
    n = int(mask.sum())
    if n == 0:
        raise UserError("%s: the object covers no pixel" % asset)
    mc, my = cand[mask].mean(axis=0), cyc[mask].mean(axis=0)
    pc, py = cand[mask].mean(axis=1), cyc[mask].mean(axis=1)
    keep = py > 1e-3
    median = float(numpy.median(pc[keep] / py[keep])) if keep.any() else float("nan")
    name = os.path.splitext(os.path.basename(asset))[0]
    diff = (cand - cyc).mean(axis=2) * 4.0
    diff_rgb = numpy.stack([numpy.clip(diff, 0, 1), numpy.zeros_like(diff), numpy.clip(-diff, 0, 1)], axis=-1)
    gap = numpy.full((args.size, 4, 3), 255, numpy.uint8)
    strip = numpy.concatenate([srgb8(cand), gap, srgb8(cyc), gap, (diff_rgb * 255 + 0.5).astype(numpy.uint8)], axis=1)
    png = os.path.join(args.images, name + ".png")
    write_png(png, strip)
    shutil.copy(os.path.join(tmp, "candela.exr"), os.path.join(args.images, name + "-candela.exr"))
    shutil.copy(os.path.join(tmp, "cycles.exr"), os.path.join(args.images, name + "-cycles.exr"))
    return {"asset": name, "file": asset, "pixels": n, "candela_mean": [round(float(v), 5) for v in mc],
            "cycles_mean": [round(float(v), 5) for v in my],
            "ratio": [round(float(a / b), 4) if b > 0 else None for a, b in zip(mc, my)],
            "median_pixel_ratio": round(median, 4), "candela_seconds": round(cand_seconds, 3),
            "cycles_seconds": round(cyc_seconds, 3), "image": png, "camera": camera, "candela_notes": notes,
            "blender": info["blender"], "blender_materials": info["materials"]}


def markdown(rows):
    out = ["| asset | covered pixels | candela / Cycles R | G | B | median pixel ratio | candela s | Cycles s |",
           "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "error" in r:
            out.append("| %s | error: %s | | | | | | |" % (r["asset"], r["error"][:120].replace("|", "/")))
            continue
        out.append("| %s | %d | %.3f | %.3f | %.3f | %.3f | %.2f | %.2f |" % (
            r["asset"], r["pixels"], r["ratio"][0], r["ratio"][1], r["ratio"][2], r["median_pixel_ratio"],
            r["candela_seconds"], r["cycles_seconds"]))
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(prog="scripts/compare/vs_cycles_assets.py",
                                 description="candela's brightness against Cycles on glTF sample assets")
    ap.add_argument("--assets", help="space-separated glTF/GLB files (default: the sample assets listed in the help)")
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--spp", type=int, default=64, help="candela's samples per pixel")
    ap.add_argument("--cycles-spp", type=int, default=64)
    ap.add_argument("--max-depth", type=int, default=8)
    ap.add_argument("--device", default="pocl", help="candela's --device")
    ap.add_argument("--candela-option", action="append", default=[],
                    help="one more argument for candela's renders (repeatable), e.g. --candela-option=--no-energy-compensation")
    ap.add_argument("--cycles-gltf-attenuation", action="store_true",
                    help="set the imported Volume Absorption nodes to glTF's Beer-Lambert law")
    ap.add_argument("--cycles-neutral-missing-textures", action="store_true",
                    help="images Blender cannot load (KTX2) become the neutral texel instead of magenta")
    ap.add_argument("--threads", type=int, default=os.cpu_count() or 1, help="Cycles' threads (default nproc)")
    ap.add_argument("--images", default=os.path.join("build", "vs-cycles-assets"))
    ap.add_argument("--out", help="append the JSON lines to this file too")
    ap.add_argument("--markdown", action="store_true", help="print the table after the JSON lines")
    ap.add_argument("--blender", default=shutil.which("blender") or "")
    ap.add_argument("--binary", default=os.path.join("build", "candela"))
    args = ap.parse_args()
    os.chdir(ROOT)
    args.images = os.path.abspath(args.images)
    os.makedirs(args.images, exist_ok=True)
    if not args.blender:
        raise SystemExit("candela: error: Blender is not installed (Debian: apt-get install blender), or pass "
                         "--blender PATH")
    if not os.path.isfile(args.binary):
        raise SystemExit("candela: error: %s not found: build candela first" % args.binary)
    assets = args.assets.split() if args.assets else DEFAULT_ASSETS
    for a in assets:
        if not os.path.isfile(a):
            raise SystemExit("candela: error: asset %s not found" % a)
    commit = ct.git_commit()
    rows = []
    out_file = open(args.out, "a") if args.out else None
    for asset in assets:
        with tempfile.TemporaryDirectory(prefix="candela-vs-cycles-assets-") as tmp:
            try:
                r = compare(asset, args, tmp)
            except UserError as e:
                r = {"asset": os.path.splitext(os.path.basename(asset))[0], "file": asset, "error": str(e)}
        r.update({"width": args.size, "height": args.size, "spp": args.spp, "cycles_spp": args.cycles_spp,
                  "max_depth": args.max_depth, "device": args.device, "candela_options": args.candela_option,
                  "cycles_gltf_attenuation": args.cycles_gltf_attenuation,
                  "cycles_neutral_missing_textures": args.cycles_neutral_missing_textures,
                  "commit": commit,
                  "time": time.strftime("%Y-%m-%dT%H:%M:%S")})
        rows.append(r)
        print(json.dumps(r), flush=True)
        if out_file:
            out_file.write(json.dumps(r) + "\n")
            out_file.flush()
    if args.markdown:
        print()
        print("%dx%d, candela %d spp on %s, Cycles %d spp, max depth %d; commit %s" % (
            args.size, args.size, args.spp, args.device, args.cycles_spp, args.max_depth, commit))
        print(markdown(rows))


if __name__ == "__main__":
    main()
