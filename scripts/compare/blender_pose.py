#!/usr/bin/python3
"""candela's animation poses against Blender 3.4's glTF importer: silhouette intersection over union.

For each time T of an animation, both programs pose the asset, and their silhouettes, seen by the same
pinhole camera at SIZE x SIZE pixels, are compared:
  Blender  one process (blender -b --factory-startup, through candela_tools.cycles.run_blender, whose set-up
           also makes Debian's Blender 3.4 importer work with numpy 1.24: it restores numpy.bool & co.) imports
           the glTF, makes the chosen animation the active action of every object (the importer keeps each
           animation as NLA tracks named after it, or "Anim_N" when unnamed, and activates the first), sets
           the scene to frame T x fps (the importer writes a key at glTF time t to frame t x scene fps, with
           no offset; fps is the factory 24; a fractional frame is set as a subframe) and saves the evaluated
           (skinned and morphed) world-space vertices and triangles of every mesh, in glTF's coordinates.
  candela  `candela render --animation A --anim-time T --max-depth 0 --background 1,1,1 --default-light off`
           at SPP samples: a camera ray that hits the asset returns black, one that misses white, so
           1 - a pixel's value is its coverage; --stats gives the camera ("camera": position, right, up,
           forward, field of view).
  The Blender triangles are projected with that camera and rasterized here (SUPER x SUPER samples at the
  centres of each pixel's sub-cells, so a pixel's coverage is a fraction as for candela); both coverages
  are thresholded at 0.5 and IoU = |A and B| / |A or B|.

  scripts/compare/blender_pose.py SCENE --animation NAME|N --times T1,T2,... [--look-from X,Y,Z --look-at X,Y,Z
                    --fov DEG] [--size N (256)] [--spp N (16)] [--device pocl] [--binary PATH] [--blender PATH]
                    [--json] [--images DIR]

Prints one line per time (the IoU, the pixels of each silhouette); --json prints one JSON object per time.
--images DIR writes each pair of masks side by side (candela left, Blender right) as PNG.
Blender's LINEAR rotation curves interpolate quaternion components and normalize (candela: spherical
linear interpolation); between keys a few frames apart the two differ by far less than a pixel.
"""

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import candela_tools as ct  # noqa: E402
from candela_tools import cycles  # noqa: E402

# Blender side (after candela_tools.cycles' set-up, which defines cfg): import, pose, save
POSE_BODY = r"""
import math
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=cfg["scene"])
scene = bpy.context.scene
fps = scene.render.fps / scene.render.fps_base
out = {"fps": fps, "blender": bpy.app.version_string, "poses": []}


def activate(track):
    # The importer's stashed NLA track of that name, made the active action (None: not animated by it)
    holders = [o for o in scene.objects] + [o.data.shape_keys for o in scene.objects
                                             if o.type == "MESH" and o.data.shape_keys]
    found = 0
    for h in holders:
        ad = getattr(h, "animation_data", None)
        if not ad:
            continue
        ad.action = None
        for t in ad.nla_tracks:
            if t.name == track and t.strips:
                ad.action = t.strips[0].action
                found += 1
    return found


for pose in cfg["poses"]:
    found = activate(pose["track"])
    frame = pose["time"] * fps
    whole = math.floor(frame)
    scene.frame_set(int(whole), subframe=frame - whole)
    dg = bpy.context.evaluated_depsgraph_get()
    points, tris = [], []
    for o in scene.objects:
        if o.type != "MESH":
            continue
        e = o.evaluated_get(dg)
        m = e.to_mesh()
        m.calc_loop_triangles()
        co = numpy.empty(len(m.vertices) * 3)
        m.vertices.foreach_get("co", co)
        co = co.reshape(-1, 3)
        w = numpy.array(e.matrix_world)
        co = co @ w[:3, :3].T + w[:3, 3]
        tri = numpy.empty(len(m.loop_triangles) * 3, dtype=numpy.int64)
        m.loop_triangles.foreach_get("vertices", tri)
        tris.append(tri.reshape(-1, 3) + sum(len(p) for p in points))
        points.append(co)
        e.to_mesh_clear()
    co = numpy.concatenate(points)
    gltf = numpy.stack([co[:, 0], co[:, 2], -co[:, 1]], axis=1)  # Blender (x, y, z) is glTF (x, -z, y)
    numpy.savez(pose["out"], positions=gltf, triangles=numpy.concatenate(tris))
    out["poses"].append({"time": pose["time"], "frame": frame, "tracks_found": found})
candela_result(out)
"""


def track_names(scene):
    """The importer's NLA track name of each animation: its name, else Anim_<index> (made unique)."""
    doc = json.load(open(scene)) if scene.lower().endswith(".gltf") else None
    if doc is None:
        raise ct.UserError("blender_pose.py reads .gltf files (not %s)" % scene)
    names, used = [], set()
    for i, a in enumerate(doc.get("animations", [])):
        name = a.get("name") or "Anim_%d" % i
        base, n = name, 1
        while name in used:
            name, n = "%s.%03d" % (base, n), n + 1
        used.add(name)
        names.append(name)
    return names


def track_of(scene, animation):
    names = track_names(scene)
    if str(animation).isdigit() and int(animation) < len(names):
        return names[int(animation)]
    if animation in names:
        return animation
    raise ct.UserError("%s has no animation %r (it has %s)" % (scene, animation, ", ".join(names) or "none"))


def blender_poses(blender, scene, animation, times, tmp):
    """Blender's posed geometry at each time: [(positions N x 3, triangles M x 3)] in glTF coordinates, and
    the run's info (fps, blender version, per pose the frame and how many objects the animation drives)."""
    import numpy as np
    track = track_of(scene, animation)
    poses = [{"track": track, "time": float(t), "out": os.path.join(tmp, "blender-pose-%d.npz" % i)}
             for i, t in enumerate(times)]
    try:
        info, _, _ = cycles.run_blender(blender, POSE_BODY, {"scene": os.path.abspath(scene), "poses": poses}, tmp,
                                        "blender_pose.py")
    except RuntimeError as e:
        raise ct.UserError("Blender failed to pose %s: %s" % (scene, e))
    geometry = []
    for p, rec in zip(poses, info["poses"]):
        if rec["tracks_found"] == 0:
            raise ct.UserError("Blender's import of %s has no NLA track %r" % (scene, track))
        with np.load(p["out"]) as z:
            geometry.append((z["positions"], z["triangles"]))
    return geometry, info


def candela_mask(binary, scene, animation, t, size, spp, camera, device, tmp):
    """candela's coverage (SIZE x SIZE, 1 on the asset) posed at T, and its camera record."""
    out, stats = os.path.join(tmp, "candela-%s.exr" % t), os.path.join(tmp, "candela-%s.json" % t)
    options = ["--animation", animation, "--anim-time", t, "--max-depth", 0, "--background", "1,1,1",
               "--default-light", "off", "--width", size, "--height", size, "--spp", spp, "--device", device, "-q"]
    r = ct.render(scene, out, options + list(camera), binary=binary, stats=stats)
    image, _ = ct.read_rgb(out, "candela's silhouette")
    record = r.stats["camera"]
    return 1.0 - image.mean(axis=2), record


def project_mask(positions, triangles, cam, size, super_=4):
    """Coverage (SIZE x SIZE) of the triangles seen by candela's pinhole camera record CAM, from SUPER x SUPER
    samples per pixel at the centres of its sub-cells."""
    import numpy as np
    if cam.get("type") != "perspective":
        raise ct.UserError("blender_pose.py compares through a perspective camera (got %s)" % cam.get("type"))
    p = np.asarray(positions, dtype=np.float64) - np.asarray(cam["position"])
    right, up, fwd = (np.asarray(cam[k], dtype=np.float64) for k in ("right", "up", "forward"))
    z = p @ fwd
    if (z <= 0).any():
        raise ct.UserError("part of the mesh is behind the camera: choose a camera farther away")
    tx = math.tan(math.radians(cam["xfov_degrees"]) / 2)
    ty = math.tan(math.radians(cam["yfov_degrees"]) / 2)
    n = size * super_
    # Sample coordinates: sub-cell centres at k + 0.5 in a raster of n x n, y down
    sx = ((p @ right) / (z * tx) + 1) * 0.5 * n - 0.5
    sy = (1 - (p @ up) / (z * ty)) * 0.5 * n - 0.5
    hit = np.zeros((n, n), dtype=bool)
    for a, b, c in np.asarray(triangles):
        xs, ys = sx[[a, b, c]], sy[[a, b, c]]
        x0, x1 = max(int(math.ceil(xs.min())), 0), min(int(math.floor(xs.max())), n - 1)
        y0, y1 = max(int(math.ceil(ys.min())), 0), min(int(math.floor(ys.max())), n - 1)
        if x0 > x1 or y0 > y1:
            continue
        gx, gy = np.meshgrid(np.arange(x0, x1 + 1), np.arange(y0, y1 + 1))
        e = []
        for (ax, ay), (bx, by) in (((xs[0], ys[0]), (xs[1], ys[1])), ((xs[1], ys[1]), (xs[2], ys[2])),
                                   ((xs[2], ys[2]), (xs[0], ys[0]))):
            e.append((bx - ax) * (gy - ay) - (by - ay) * (gx - ax))
        inside = ((e[0] >= 0) & (e[1] >= 0) & (e[2] >= 0)) | ((e[0] <= 0) & (e[1] <= 0) & (e[2] <= 0))
        hit[y0:y1 + 1, x0:x1 + 1] |= inside
    return hit.reshape(size, super_, size, super_).mean(axis=(1, 3))


def iou(a, b):
    a, b = a >= 0.5, b >= 0.5
    union = float((a | b).sum())
    return float((a & b).sum()) / union if union else 1.0, int(a.sum()), int(b.sum())


def compare(scene, animation, times, camera, size=256, spp=16, device="pocl", binary=None, blender=None,
            images=None):
    """IoU of candela's and Blender's silhouettes of SCENE's ANIMATION at each of TIMES: a list of dicts
    (time, frame, iou, candela_pixels, blender_pixels) and Blender's info."""
    import numpy as np
    blender = blender or shutil.which("blender")
    if not blender:
        raise ct.UserError("blender is not installed (Debian's package blender)")
    binary = binary or ct.BINARY
    with tempfile.TemporaryDirectory() as tmp:
        geometry, info = blender_poses(blender, scene, animation, times, tmp)
        rows = []
        for t, (pos, tri), rec in zip(times, geometry, info["poses"]):
            mine, cam = candela_mask(binary, scene, animation, t, size, spp, camera, device, tmp)
            theirs = project_mask(pos, tri, cam, size)
            value, na, nb = iou(mine, theirs)
            rows.append({"scene": os.path.basename(scene), "animation": str(animation), "time": float(t),
                         "frame": rec["frame"], "iou": value, "candela_pixels": na, "blender_pixels": nb})
            if images:
                from PIL import Image
                os.makedirs(images, exist_ok=True)
                pair = np.concatenate([mine >= 0.5, theirs >= 0.5], axis=1)
                Image.fromarray((255 - 255 * pair).astype(np.uint8)).save(
                    os.path.join(images, "%s-%s-%s.png" % (os.path.splitext(os.path.basename(scene))[0], animation, t)))
    return rows, info


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--animation", default="0")
    ap.add_argument("--times", required=True, help="comma list of seconds")
    ap.add_argument("--look-from")
    ap.add_argument("--look-at")
    ap.add_argument("--fov")
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--device", default="pocl")
    ap.add_argument("--binary")
    ap.add_argument("--blender")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--images")
    args = ap.parse_args()
    camera = []
    for opt in ("look_from", "look_at", "fov"):
        if getattr(args, opt):
            camera += ["--" + opt.replace("_", "-"), getattr(args, opt)]
    try:
        times = [float(t) for t in args.times.split(",")]
        rows, info = compare(args.scene, args.animation, times, camera, args.size, args.spp, args.device,
                             args.binary, args.blender, args.images)
    except ValueError:
        ct.fail("--times takes a comma list of seconds (got %r)" % args.times)
    except ct.UserError as e:
        ct.fail(str(e))
    for r in rows:
        if args.json:
            print(json.dumps(dict(r, blender=info["blender"], fps=info["fps"])))
        else:
            print("%s %s t=%.4g s (Blender frame %.4g at %g fps): IoU %.4f (candela %d px, Blender %d px)" % (
                r["scene"], r["animation"], r["time"], r["frame"], info["fps"], r["iou"], r["candela_pixels"],
                r["blender_pixels"]))


if __name__ == "__main__":
    main()
