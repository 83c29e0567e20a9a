"""Blender Cycles with the settings that match candela's, in one place for the scripts of scripts/compare/.

They run `blender -b --factory-startup -noaudio --python SCRIPT -- CONFIG_JSON`, where SCRIPT is
blender_script(BODY): the text below (which defines candela_scene(cfg) inside Blender) followed by the caller's
BODY, which reads `cfg` (the decoded CONFIG_JSON), calls candela_warmup(scene) before its timed renders, and renders. candela_scene(cfg) imports the glTF and sets:

  engine CYCLES on the CPU, threads = cfg["threads"] (FIXED; callers pass nproc by default);
  adaptive sampling off; denoising off;
  max_bounces and the diffuse, glossy, transmission, volume and transparent bounce limits = cfg["max_depth"]
    (candela's --max-depth);
  clamping off (sample_clamp_direct = sample_clamp_indirect = 0); filter glossy (blur_glossy) 0;
  caustics (reflective and refractive) on;
  pixel filter BOX of width 1 px (candela's default box filter: one pixel);
  persistent data off (every render syncs the scene and builds its BVH again);
  seed = cfg["seed"] (default 0); the sampling pattern is Blender's default (reported by the caller);
  the glTF's first camera, or cfg["camera"] when given (candela's --stats "camera" record, in glTF coordinates:
    a new camera at that position and orientation with that vertical field of view, or orthographic half-height,
    and thin lens, replacing the imported ones); resolution cfg["width"] x cfg["height"] at 100 %; Standard view
    transform;
  world black, unless cfg["background"] (config(..., background=[R, G, B])) or the scene's extras.candela set a
    background colour (a constant world of that colour) or an environment map (an Environment Texture of that file
    and strength; rotation conventions are not matched).

config(...) builds the CONFIG_JSON dictionary on the host side (it reads the glTF's extras.candela), so that the
scripts cannot drift apart. run_ladder(...) renders a ladder of sample counts in one Blender process.
"""

import json
import os
import subprocess
import time

BLENDER_SETUP = r'''
import bpy, json, math, sys, time
import numpy
# Debian's Blender 3.4 glTF importer uses numpy.bool & co., which numpy 1.24 removed
for _name, _type in (("bool", bool), ("int", int), ("float", float), ("object", object)):
    if _name not in numpy.__dict__:
        setattr(numpy, _name, _type)
cfg = json.loads(sys.argv[sys.argv.index("--") + 1])


def candela_camera(scene, rec):
    """A camera from candela's --stats "camera" record (glTF's Y-up coordinates; the importer maps glTF (x, y, z)
    to Blender (x, -z, y)), made the scene's camera in place of any imported one."""
    import mathutils
    for o in [o for o in scene.objects if o.type == "CAMERA"]:
        bpy.data.objects.remove(o, do_unlink=True)
    to_blender = lambda v: mathutils.Vector((v[0], -v[2], v[1]))
    right, up, forward = (to_blender(rec[k]).normalized() for k in ("right", "up", "forward"))
    rotation = mathutils.Matrix((right, up, -forward)).transposed()  # columns: camera X, Y, Z (Z looks back)
    data = bpy.data.cameras.new("candela-camera")
    data.sensor_fit = "VERTICAL"
    if rec["type"] == "orthographic":
        data.type = "ORTHO"
        data.ortho_scale = 2.0 * rec["ymag"]
    else:
        data.type = "PERSP"
        data.angle_y = math.radians(rec["yfov_degrees"])
        if rec.get("lens_radius", 0) > 0:  # Cycles' aperture radius is lens / (2 f-stop), lens in mm
            data.dof.use_dof = True
            data.dof.focus_distance = rec["focus_distance"]
            data.dof.aperture_fstop = data.lens * 1e-3 / (2.0 * rec["lens_radius"])
    data.clip_start = 1e-4
    data.clip_end = 1e6
    cam = bpy.data.objects.new("candela-camera", data)
    cam.matrix_world = mathutils.Matrix.Translation(to_blender(rec["position"])) @ rotation.to_4x4()
    scene.collection.objects.link(cam)
    scene.camera = cam


def candela_scene(cfg):
    """Import cfg["scene"] and set Cycles to candela's settings (see candela_tools/cycles.py)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=cfg["scene"])
    scene = bpy.context.scene
    cams = [o for o in scene.objects if o.type == "CAMERA"]
    if cams:
        scene.camera = cams[0]
    if cfg.get("camera"):
        candela_camera(scene, cfg["camera"])
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.use_adaptive_sampling = False
    c.use_denoising = False
    d = cfg["max_depth"]
    c.max_bounces = d
    for name in ("diffuse_bounces", "glossy_bounces", "transmission_bounces", "volume_bounces",
                 "transparent_max_bounces"):
        setattr(c, name, d)
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.caustics_reflective = True
    c.caustics_refractive = True
    c.filter_type = "BOX"
    c.filter_width = 1.0
    c.seed = cfg.get("seed", 0)
    scene.render.use_persistent_data = False
    scene.render.threads_mode = "FIXED"
    scene.render.threads = cfg["threads"]
    scene.render.resolution_x = cfg["width"]
    scene.render.resolution_y = cfg["height"]
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    # World: black unless the scene sets a background or an environment map
    world = bpy.data.worlds.new("candela-world")
    world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    bg.inputs["Strength"].default_value = 1.0
    if cfg.get("background"):
        r, g, b = cfg["background"]
        bg.inputs["Color"].default_value = (r, g, b, 1.0)
    if cfg.get("environment"):
        env = world.node_tree.nodes.new("ShaderNodeTexEnvironment")
        env.image = bpy.data.images.load(cfg["environment"]["path"])
        world.node_tree.links.new(env.outputs["Color"], bg.inputs["Color"])
        bg.inputs["Strength"].default_value = cfg["environment"].get("strength", 1.0)
    scene.world = world
    return scene


def candela_warmup(scene):
    """An untimed 1-spp render: Cycles' first render in a process also initializes it (about 0.1 s here), which
    would otherwise be counted in the first timed render. Returns its seconds."""
    samples = scene.cycles.samples
    scene.cycles.samples = 1
    t = time.time()
    bpy.ops.render.render(write_still=False)
    scene.cycles.samples = samples
    return time.time() - t


def candela_info(scene):
    return {"pattern": getattr(scene.cycles, "sampling_pattern", "?"), "blender": bpy.app.version_string}


def candela_result(out):
    print("CANDELA_CYCLES_RESULT " + json.dumps(out))

'''

RESULT_MARKER = "CANDELA_CYCLES_RESULT "


def blender_script(body):
    """The whole Blender-side script: the shared settings, then BODY (which uses cfg, candela_scene(cfg),
    candela_warmup(scene), candela_info(scene) and candela_result(dict))."""
    return BLENDER_SETUP + body


def scene_extras(path):
    """extras.candela of the glTF's scene (or of the document, or its asset)."""
    if os.path.splitext(path)[1].lower() != ".gltf":
        return {}
    with open(path) as f:
        doc = json.load(f)
    scenes = doc.get("scenes") or [{}]
    for holder in (scenes[doc.get("scene", 0)] if doc.get("scene", 0) < len(scenes) else {}, doc,
                   doc.get("asset", {})):
        ex = (holder.get("extras") or {}).get("candela") if isinstance(holder, dict) else None
        if isinstance(ex, dict):
            return ex
    return {}


def config(scene, max_depth, width, height, threads=None, seed=0, **more):
    """The settings dictionary for candela_scene(cfg): the scene's absolute path, candela's max depth, the size,
    Cycles' thread count (default: nproc), its seed, and the world from the glTF's extras.candela. MORE is added
    last: background=[R, G, B] (a constant world), camera=candela's --stats "camera" record, or the caller's own."""
    cfg = {"scene": os.path.abspath(scene), "max_depth": int(max_depth), "width": int(width), "height": int(height),
           "threads": int(threads or os.cpu_count() or 1), "seed": int(seed)}
    ex = scene_extras(scene)
    if "background" in ex:
        cfg["background"] = ex["background"]
    if "environment" in ex:
        env = dict(ex["environment"])
        env["path"] = os.path.join(os.path.dirname(os.path.abspath(scene)), env["file"])
        cfg["environment"] = env
    cfg.update(more)
    return cfg


def run_blender(blender, body, cfg, tmp, name="cycles_render.py"):
    """Run blender_script(body) with cfg; returns (the dictionary the body passed to candela_result, the process's
    wall seconds, its output). Raises RuntimeError with the output's tail when Blender fails."""
    script = os.path.join(tmp, name)
    with open(script, "w") as f:
        f.write(blender_script(body))
    start = time.time()
    cfg = dict(cfg, t_start=start)  # the body can report its start-up: time.time() - cfg["t_start"]
    p = subprocess.run([blender, "-b", "--factory-startup", "-noaudio", "--python", script, "--", json.dumps(cfg)],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    wall = time.time() - start
    result = None
    for line in p.stdout.splitlines():
        if line.startswith(RESULT_MARKER):
            result = json.loads(line[len(RESULT_MARKER):])
    if p.returncode != 0 or result is None:
        raise RuntimeError(p.stdout.strip()[-800:])
    return result, wall, p.stdout


# After candela_scene(cfg): a 1-spp warm-up (the first render initializes Cycles), a timed 1-spp setup probe, then
# each of cfg["spp"], timing each bpy.ops.render.render and writing its EXR
LADDER_BODY = r"""
scene = candela_scene(cfg)
out = candela_info(scene)
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
out["warmup_seconds"] = candela_warmup(scene)
out["startup_seconds"] = time.time() - cfg["t_start"]
scene.cycles.samples = 1
t = time.time()
bpy.ops.render.render(write_still=False)  # probe: what every render costs beyond its samples
out["probe_seconds"] = time.time() - t
out["renders"] = []
for spp, path in zip(cfg["spp"], cfg["outputs"]):
    scene.cycles.samples = spp
    scene.render.filepath = path
    t = time.time()
    bpy.ops.render.render(write_still=True)
    out["renders"].append({"spp": spp, "seconds": time.time() - t})
candela_result(out)
"""


def run_ladder(blender, scene, ladder, width, height, max_depth, seed, tmp, threads=None, tag="cycles"):
    """Cycles renders of SCENE at each spp of LADDER in one Blender process, with these settings. Returns
    ([(spp, image path, seconds inside bpy.ops.render.render)], info): info has startup_seconds (process start,
    import and the 1-spp warm-up), warmup_seconds, probe_seconds (a second 1-spp render: what every render costs
    beyond its samples, i.e. Cycles' scene sync and BVH build, plus one sample), pattern, blender. Raises
    candela_tools.UserError when Blender fails."""
    from candela_tools import UserError
    outs = [os.path.join(tmp, "%s-%d.exr" % (tag, spp)) for spp in ladder]
    cfg = config(scene, max_depth, width, height, threads, seed, spp=list(ladder), outputs=outs)
    try:
        result, wall, _ = run_blender(blender, LADDER_BODY, cfg, tmp, "converge_cycles.py")
    except RuntimeError as e:
        raise UserError("Blender failed to render %s with Cycles: %s" % (scene, e))
    for path in outs:
        if not os.path.isfile(path):
            raise UserError("Blender did not write %s" % path)
    renders = [(r["spp"], path, r["seconds"]) for r, path in zip(result["renders"], outs)]
    info = {k: result[k] for k in ("startup_seconds", "warmup_seconds", "probe_seconds", "pattern", "blender")}
    info["process_seconds"] = wall
    return renders, info


def setup_seconds(probe_seconds, renders):
    """What one Cycles render spends beyond its samples (sync, BVH build, film): the 1-spp probe's time less one
    sample's worth, the per-sample cost taken from the largest render."""
    spp, _, seconds = max(renders)
    if spp <= 1:
        return probe_seconds
    per_sample = max(0.0, (seconds - probe_seconds) / (spp - 1))
    return max(0.0, probe_seconds - per_sample)
