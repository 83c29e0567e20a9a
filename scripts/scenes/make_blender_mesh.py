# Blender-exported benchmark mesh: Suzanne (Blender's monkey primitive) with a
# subdivision-surface modifier applied (level 5: 968 triangles x 4^5 = 991,232), on a
# floor plane, under a square emissive area light, with a camera. Exported as glTF
# (separate .bin) by Blender's own exporter. Not committed: scripts/bench/bench.sh and
# scripts/compare/vs_cycles.py write it to build/bench/ on demand.
#
# Usage: blender -b --factory-startup -noaudio --python scripts/scenes/make_blender_mesh.py -- OUT.gltf [LEVEL (5)]
#
# Runs inside Blender (bpy); needs Blender 3.x (Debian: apt-get install blender). Without
# Blender, scripts/scenes/make_bench_mesh.py (a displaced sphere, plain Python) is the fallback.
import json
import math
import os
import sys

import bpy

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
if not argv:
    sys.exit("usage: blender -b --python scripts/scenes/make_blender_mesh.py -- OUT.gltf [LEVEL]")
out = os.path.abspath(argv[0])
level = int(argv[1]) if len(argv) > 1 else 5

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene


def material(name, rgb, emission=None):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (rgb[0], rgb[1], rgb[2], 1.0)
    bsdf.inputs["Metallic"].default_value = 0.0
    bsdf.inputs["Roughness"].default_value = 1.0
    bsdf.inputs["Specular"].default_value = 0.0
    if emission:
        bsdf.inputs["Emission"].default_value = (1.0, 1.0, 1.0, 1.0)
        bsdf.inputs["Emission Strength"].default_value = emission
    return m


# Suzanne, subdivided (Catmull-Clark), smooth shaded, sitting on the floor
bpy.ops.mesh.primitive_monkey_add(size=2.0, location=(0.0, 0.0, 1.0), rotation=(0.0, 0.0, 0.0))
monkey = bpy.context.active_object
monkey.name = "suzanne"
mod = monkey.modifiers.new("subdivision", "SUBSURF")
mod.levels = level
mod.render_levels = level
bpy.ops.object.modifier_apply(modifier=mod.name)
bpy.ops.object.shade_smooth()
monkey.data.materials.append(material("suzanne", (0.7, 0.6, 0.5)))
# Rest it on the floor (z = 0 in Blender, y = 0 in glTF)
zmin = min((monkey.matrix_world @ v.co).z for v in monkey.data.vertices)
monkey.location.z -= zmin

bpy.ops.mesh.primitive_plane_add(size=8.0, location=(0.0, 0.0, 0.0))
floor = bpy.context.active_object
floor.name = "floor"
floor.data.materials.append(material("floor", (0.5, 0.5, 0.5)))

# Area light as an emissive quad facing down (glTF has no area lights)
bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0.0, 0.0, 3.5), rotation=(math.pi, 0.0, 0.0))
light = bpy.context.active_object
light.name = "light"
light.data.materials.append(material("light", (0.0, 0.0, 0.0), emission=20.0))

# Camera in front of the monkey's face (Suzanne looks along -y)
bpy.ops.object.camera_add(location=(0.0, -4.2, 2.0))
cam = bpy.context.active_object
cam.name = "camera"
cam.data.sensor_fit = "VERTICAL"
cam.data.angle_y = 0.7
target = monkey.location.copy()
target.z = 1.0
direction = target - cam.location
cam.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
scene.camera = cam
scene.render.resolution_x = scene.render.resolution_y = 512

tris = sum(len(p.vertices) - 2 for o in (monkey, floor, light) for p in o.data.polygons)
os.makedirs(os.path.dirname(out), exist_ok=True)
bpy.ops.export_scene.gltf(filepath=out, export_format="GLTF_SEPARATE", export_cameras=True,
                          export_lights=False, export_apply=True, export_yup=True,
                          export_texcoords=False, export_materials="EXPORT")
# Blender exports doubleSided (backface culling off) and the emission strength; only a
# note of where the file came from is added
with open(out) as f:
    doc = json.load(f)
doc.setdefault("asset", {})["extras"] = {"candela": "scripts/scenes/make_blender_mesh.py, subdivision level %d" % level}
with open(out, "w") as f:
    json.dump(doc, f, indent=1)
print("wrote %s: %d triangles (Blender %s)" % (out, tris, bpy.app.version_string))
