#!/usr/bin/env python3
"""Write candela's test scenes as self-contained glTF 2.0 files.

Run from the repository root:  python3 scripts/scenes/make_scenes.py

Outputs (deterministic, byte-identical on every run):
  scenes/cornell-box/cornell-box.gltf   Cornell Box (published measured data)
  scenes/furnace/closed-sphere.gltf     emissive+diffuse sphere seen from inside
  scenes/furnace/white-objects.gltf     albedo-1 objects under a white background
  scenes/materials/materials.gltf       grid of material spheres under an area light
  scenes/materials/iridescence.gltf     thin films (KHR_materials_iridescence) on spheres
  scenes/lights/punctual.gltf           point, spot and directional lights (KHR_lights_punctual)
  scenes/lights/sky.hdr, tiny-sun.hdr   equirectangular maps (Radiance RGBE)
  scenes/lights/environment.gltf        spheres on a floor lit by sky.hdr
  scenes/lights/veach.gltf              glossy plates of four roughnesses under four
                                        spherical lights of four sizes (Veach 1997)
  scenes/lights/small-light.gltf        a small bright light over a diffuse floor
  scenes/lights/large-light-glossy.gltf a large light over smooth-ish metal
  scenes/lights/many-lights.gltf        4096 small emissive quads over a floor
  scenes/lights/near-specular.gltf      metal and glass of roughness 0.02-0.3 under a
                                        large area light (near-specular-sky: sky.hdr)
  scenes/volumes/god-rays.gltf          a dusty room lit through a window
  scenes/volumes/liquid-glass.gltf      a glass of absorbing liquid
  scenes/volumes/cloud.gltf             a procedural noise cloud (density grid)
  scenes/volumes/plume.gltf             an emissive smoke plume (density grid) at night

Every file (written with scripts/scenes/gltf_writer.py) embeds its binary buffer as
a base64 data URI.  Meshes use flat (per-face) normals with vertices
duplicated per triangle.  After writing, each file is read back from disk and
checked (accessors, bounds, winding vs normals, watertightness where
expected).
"""

import base64
import json
import math
import os
import struct

from gltf_writer import (DATA_URI_PREFIX, ELEMENT_ARRAY_BUFFER, FLOAT,
                         UNSIGNED_INT, GltfWriter)

GENERATOR = "candela scripts/make_scenes.py"  # as written into the shipped scenes

# KHR_lights_punctual intensities are photometric (candela, lux); candela reads them by
# 683 lm/W, so a light meant to give W radiometric units is written as W x 683
LUMENS_PER_WATT = 683.0


def photometric(watts):
    return watts * LUMENS_PER_WATT

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


# ---------------------------------------------------------------------------
# Small vector helpers (tuples of Python floats)

def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def scale(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0])


def normalize(a):
    return scale(a, 1.0 / math.sqrt(dot(a, a)))


def centroid(points):
    s = (0.0, 0.0, 0.0)
    for p in points:
        s = add(s, p)
    return scale(s, 1.0 / len(points))


def f32(x):
    """Round a Python float to the nearest float32 value."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


def f32v(v):
    return tuple(f32(c) for c in v)


def tri_normal(a, b, c):
    """Unit normal of triangle (a, b, c) from its counter-clockwise winding."""
    return normalize(cross(sub(b, a), sub(c, a)))


# ---------------------------------------------------------------------------
# Triangle soups -> flat-shaded vertex arrays

def flat_mesh(triangles):
    """Turn a list of (a, b, c) float32 triangles into flat-shaded arrays.

    Each triangle gets its own three vertices so its normal is exactly the
    normal of its own winding.  Returns (positions, normals, indices).
    """
    positions, normals, indices = [], [], []
    for a, b, c in triangles:
        n = f32v(tri_normal(a, b, c))
        for p in (a, b, c):
            indices.append(len(positions))
            positions.append(p)
            normals.append(n)
    return positions, normals, indices


def orient_quad(quad, wanted):
    """Return quad vertices ordered so the front faces direction `wanted`.

    Uses the Newell normal of the (possibly slightly non-planar) quad.
    """
    n = (0.0, 0.0, 0.0)
    for i, p in enumerate(quad):
        q = quad[(i + 1) % len(quad)]
        n = add(n, ((p[1] - q[1]) * (p[2] + q[2]),
                    (p[2] - q[2]) * (p[0] + q[0]),
                    (p[0] - q[0]) * (p[1] + q[1])))
    return list(quad) if dot(n, wanted) > 0 else list(reversed(quad))


def quad_triangles(quad):
    """Split a counter-clockwise quad (a, b, c, d) into two triangles."""
    a, b, c, d = quad
    return [(a, b, c), (a, c, d)]


# ---------------------------------------------------------------------------
# Cornell Box (Cornell University Program of Computer Graphics data, in mm)

CORNELL_ROOM = {
    "floor": [(552.8, 0, 0), (0, 0, 0), (0, 0, 559.2), (549.6, 0, 559.2)],
    "ceiling": [(556, 548.8, 0), (556, 548.8, 559.2), (0, 548.8, 559.2),
                (0, 548.8, 0)],
    "back_wall": [(549.6, 0, 559.2), (0, 0, 559.2), (0, 548.8, 559.2),
                  (556, 548.8, 559.2)],
    "right_wall_green": [(0, 0, 559.2), (0, 0, 0), (0, 548.8, 0),
                         (0, 548.8, 559.2)],
    "left_wall_red": [(552.8, 0, 0), (549.6, 0, 559.2), (556, 548.8, 559.2),
                      (556, 548.8, 0)],
}
CORNELL_ROOM_CENTRE = (278.0, 274.0, 280.0)

# Light quad, lowered 0.1 mm below the ceiling.
CORNELL_LIGHT = [(343, 548.7, 227), (343, 548.7, 332), (213, 548.7, 332),
                 (213, 548.7, 227)]

CORNELL_SHORT_BLOCK = [
    [(130, 165, 65), (82, 165, 225), (240, 165, 272), (290, 165, 114)],
    [(290, 0, 114), (290, 165, 114), (240, 165, 272), (240, 0, 272)],
    [(130, 0, 65), (130, 165, 65), (290, 165, 114), (290, 0, 114)],
    [(82, 0, 225), (82, 165, 225), (130, 165, 65), (130, 0, 65)],
    [(240, 0, 272), (240, 165, 272), (82, 165, 225), (82, 0, 225)],
]
CORNELL_TALL_BLOCK = [
    [(423, 330, 247), (265, 330, 296), (314, 330, 456), (472, 330, 406)],
    [(423, 0, 247), (423, 330, 247), (472, 330, 406), (472, 0, 406)],
    [(472, 0, 406), (472, 330, 406), (314, 330, 456), (314, 0, 456)],
    [(314, 0, 456), (314, 330, 456), (265, 330, 296), (265, 0, 296)],
    [(265, 0, 296), (265, 330, 296), (423, 330, 247), (423, 0, 247)],
]


def mm_to_m(quad):
    """Convert a quad from millimetres (floats) to float32 metres."""
    return [f32v(scale(tuple(float(c) for c in p), 0.001)) for p in quad]


def oriented_triangles(quads, wanted_dir):
    """Orient each mm quad with wanted_dir(quad) and return metre triangles."""
    tris = []
    for quad in quads:
        q = orient_quad([tuple(float(c) for c in p) for p in quad],
                        wanted_dir(quad))
        tris.extend(quad_triangles(mm_to_m(q)))
    return tris


def block_triangles(quads):
    """Block faces point away from the centroid of the block's vertices."""
    unique = sorted({tuple(float(c) for c in p) for q in quads for p in q})
    centre = centroid(unique)
    return oriented_triangles(
        quads, lambda q: sub(centroid([tuple(map(float, p)) for p in q]),
                             centre))


def make_cornell_box(path):
    g = GltfWriter(GENERATOR)
    white = g.material("white", (0.725, 0.71, 0.68, 1.0))
    red = g.material("red", (0.63, 0.065, 0.05, 1.0))
    green = g.material("green", (0.14, 0.45, 0.091, 1.0))
    # Emitted radiance = emissiveFactor * strength = (17, 12, 4).
    light = g.material("light", (0.78, 0.78, 0.78, 1.0),
                       emissive=(1.0, 12.0 / 17.0, 4.0 / 17.0), strength=17.0,
                       double_sided=False)
    room_materials = {"floor": white, "ceiling": white, "back_wall": white,
                      "left_wall_red": red, "right_wall_green": green}

    def toward_room_centre(quad):
        return sub(CORNELL_ROOM_CENTRE,
                   centroid([tuple(map(float, p)) for p in quad]))

    objects = []
    for name in ("floor", "ceiling", "back_wall", "left_wall_red",
                 "right_wall_green"):
        tris = oriented_triangles([CORNELL_ROOM[name]], toward_room_centre)
        objects.append((name, tris, room_materials[name]))
    objects.append(("light", oriented_triangles(
        [CORNELL_LIGHT], lambda q: (0.0, -1.0, 0.0)), light))
    objects.append(("short_block", block_triangles(CORNELL_SHORT_BLOCK),
                    white))
    objects.append(("tall_block", block_triangles(CORNELL_TALL_BLOCK), white))

    for name, tris, mat in objects:
        g.node(name, mesh=g.mesh(name, *flat_mesh(tris), mat))

    # 35 mm lens on 25 mm film; look toward +Z (180 degrees about Y).
    cam = g.camera("camera", 2.0 * math.atan(12.5 / 35.0), 1.0)
    g.node("camera", camera=cam, translation=[0.278, 0.273, -0.8],
           rotation=[0.0, 1.0, 0.0, 0.0])
    g.set_background([0, 0, 0])  # lit by its own lights alone: no default light
    g.write(path)


# ---------------------------------------------------------------------------
# Icosphere and cube

def icosphere(subdivisions, radius=1.0, inward=False):
    """Triangles of a watertight icosphere centred at the origin.

    Vertices are shared via an edge-midpoint cache, so neighbouring triangles
    use bit-identical float32 positions.  Fronts face outward unless inward.
    """
    t = (1.0 + math.sqrt(5.0)) / 2.0
    verts = [normalize(v) for v in (
        (-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0),
        (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
        (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1))]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11),
             (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6), (7, 1, 8),
             (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9),
             (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]

    for _ in range(subdivisions):
        cache = {}

        def midpoint(i, j):
            key = (min(i, j), max(i, j))
            if key not in cache:
                verts.append(normalize(scale(add(verts[i], verts[j]), 0.5)))
                cache[key] = len(verts) - 1
            return cache[key]

        new_faces = []
        for a, b, c in faces:
            ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
            new_faces += [(a, ab, ca), (b, bc, ab), (c, ca, bc),
                          (ab, bc, ca)]
        faces = new_faces

    points = [f32v(scale(v, radius)) for v in verts]
    tris = []
    for a, b, c in faces:
        tri = (points[a], points[b], points[c])
        # Orient explicitly: outward means normal along the face centroid.
        outward = dot(cross(sub(tri[1], tri[0]), sub(tri[2], tri[0])),
                      centroid(tri)) > 0
        if outward == inward:
            tri = (tri[0], tri[2], tri[1])
        tris.append(tri)
    return tris


def cube(side):
    """Twelve outward-facing triangles of an origin-centred cube."""
    h = side / 2.0
    tris = []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            u, v = (axis + 1) % 3, (axis + 2) % 3
            corners = []
            for du, dv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = [0.0, 0.0, 0.0]
                p[axis], p[u], p[v] = sign * h, du * h, dv * h
                corners.append(f32v(p))
            normal = [0.0, 0.0, 0.0]
            normal[axis] = sign
            tris += quad_triangles(orient_quad(corners, tuple(normal)))
    return tris


# ---------------------------------------------------------------------------
# Furnace scenes

def make_closed_sphere(path):
    """Sphere with albedo 0.5, emission 0.5, seen from inside: L = 1."""
    g = GltfWriter(GENERATOR)
    mat = g.material("furnace", (0.5, 0.5, 0.5, 1.0),
                     emissive=(0.5, 0.5, 0.5))
    sphere = flat_mesh(icosphere(3, inward=True))
    g.node("sphere", mesh=g.mesh("sphere", *sphere, mat))
    g.node("camera", camera=g.camera("camera", 1.2, 1.0))
    g.set_background([0, 0, 0])
    g.write(path)


def make_white_objects(path):
    """Albedo-1 objects under a white background: L = 1 everywhere."""
    g = GltfWriter(GENERATOR)
    white = g.material("white", (1.0, 1.0, 1.0, 1.0))
    # Hierarchy: parent translation, child uniform scale holding unit sphere.
    sphere_mesh = g.mesh("sphere", *flat_mesh(icosphere(3)), white)
    parent = g.node("sphere", translation=[-0.35, 0.0, 0.0])
    child = g.node("sphere_scaled", root=False, mesh=sphere_mesh,
                   scale=[0.5, 0.5, 0.5])
    g.doc["nodes"][parent]["children"] = [child]
    half = math.radians(30.0) / 2.0
    g.node("cube", mesh=g.mesh("cube", *flat_mesh(cube(0.6)), white),
           translation=[0.4, 0.0, 0.1],
           rotation=[0.0, math.sin(half), 0.0, math.cos(half)])
    g.node("camera", camera=g.camera("camera", 0.8, 1.0),
           translation=[0.0, 0.0, 3.0])
    g.set_background([1, 1, 1])
    g.write(path)


# ---------------------------------------------------------------------------
# Read-back checks

def read_vec3s(doc, blob, index):
    acc = doc["accessors"][index]
    view = doc["bufferViews"][acc["bufferView"]]
    assert acc["componentType"] == FLOAT and acc["type"] == "VEC3"
    assert view["byteLength"] == 12 * acc["count"]
    start = view["byteOffset"] + acc.get("byteOffset", 0)
    return [struct.unpack_from("<3f", blob, start + 12 * i)
            for i in range(acc["count"])]


def read_indices(doc, blob, index):
    acc = doc["accessors"][index]
    view = doc["bufferViews"][acc["bufferView"]]
    assert acc["componentType"] == UNSIGNED_INT and acc["type"] == "SCALAR"
    assert view["byteLength"] == 4 * acc["count"]
    assert view["target"] == ELEMENT_ARRAY_BUFFER
    start = view["byteOffset"] + acc.get("byteOffset", 0)
    return list(struct.unpack_from("<%dI" % acc["count"], blob, start))


def check_watertight(positions, indices):
    """Every directed edge must be matched by exactly one reversed edge."""
    edges = {}
    for k in range(0, len(indices), 3):
        tri = [struct.pack("<3f", *positions[i]) for i in indices[k:k + 3]]
        for e in range(3):
            key = (tri[e], tri[(e + 1) % 3])
            edges[key] = edges.get(key, 0) + 1
    for (a, b), n in edges.items():
        assert n == 1 and edges.get((b, a)) == 1, "mesh is not watertight"


def check_gltf(path):
    """Load a written file back and validate it; returns triangles per mesh."""
    with open(path, encoding="utf-8") as f:
        doc = json.load(f)
    assert doc["asset"]["version"] == "2.0" and doc["scene"] == 0
    buf = doc["buffers"][0]
    assert len(doc["buffers"]) == 1 and buf["uri"].startswith(DATA_URI_PREFIX)
    blob = base64.b64decode(buf["uri"][len(DATA_URI_PREFIX):])
    assert len(blob) == buf["byteLength"]
    counts = {}
    for mesh in doc["meshes"]:
        for prim in mesh["primitives"]:
            attrs = prim["attributes"]
            pos_acc = doc["accessors"][attrs["POSITION"]]
            positions = read_vec3s(doc, blob, attrs["POSITION"])
            normals = read_vec3s(doc, blob, attrs["NORMAL"])
            indices = read_indices(doc, blob, prim["indices"])
            assert len(positions) == len(normals)
            smooth = mesh["name"].startswith("smooth-")
            assert len(indices) % 3 == 0
            assert all(i < len(positions) for i in indices)
            for i in range(3):
                assert pos_acc["min"][i] == min(p[i] for p in positions)
                assert pos_acc["max"][i] == max(p[i] for p in positions)
            for k in range(0, len(indices), 3):
                a, b, c = (positions[i] for i in indices[k:k + 3])
                n = tri_normal(a, b, c)
                for i in indices[k:k + 3]:
                    assert dot(n, normals[i]) > (0.5 if smooth else 0.999), "winding/normal mismatch"
            if mesh["name"] in ("sphere", "cube"):
                check_watertight(positions, indices)
            counts[mesh["name"]] = len(indices) // 3
    return counts


# ---------------------------------------------------------------------------
# Materials scene

def uv_sphere(radius, segments=48, rings=24):
    """Smooth UV sphere: positions, normals, TEXCOORD_0, outward-facing indices."""
    positions, normals, uvs, indices = [], [], [], []
    for r in range(rings + 1):
        theta = math.pi * r / rings
        for k in range(segments + 1):
            phi = 2.0 * math.pi * k / segments
            n = (math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi))
            normals.append(f32v(n))
            positions.append(f32v(scale(n, radius)))
            uvs.append((k / segments, r / rings))
    for r in range(rings):
        for k in range(segments):
            a, b = r * (segments + 1) + k, (r + 1) * (segments + 1) + k
            if r > 0:
                indices += [a, b, a + 1]
            if r < rings - 1:
                indices += [a + 1, b, b + 1]
    return positions, normals, uvs, indices


def rgba_image(width, height, texel):
    """RGBA8 bytes of an image whose texel(x, y) gives 4 values in [0, 1]."""
    out = bytearray()
    for y in range(height):
        for x in range(width):
            out += bytes(max(0, min(255, int(round(255 * c)))) for c in texel(x, y))
    return out


def bump_normal(x, y, size=64, cells=6, depth=0.6):
    """Tangent-space normal of a field of round bumps (glTF: +x right, +y up)."""
    u, v = (x + 0.5) / size * cells, (y + 0.5) / size * cells
    du, dv = u - math.floor(u) - 0.5, v - math.floor(v) - 0.5
    r2 = du * du + dv * dv
    if r2 > 0.16:
        return (0.5, 0.5, 1.0, 1.0)
    # height h = depth * (0.16 - r2): slope along +u is -2 du depth, along +y (image up) 2 dv depth
    n = normalize((2.0 * du * depth, -2.0 * dv * depth, 1.0))
    return (0.5 + 0.5 * n[0], 0.5 + 0.5 * n[1], 0.5 + 0.5 * n[2], 1.0)


def pbr(base, metallic, roughness):
    """pbrMetallicRoughness factors: opaque base colour, metallic, roughness."""
    return {"baseColorFactor": list(base) + [1.0], "metallicFactor": metallic,
            "roughnessFactor": roughness}


def material_rows(g):
    """Materials of the sphere grid, back row first, five a row."""
    spec0 = {"KHR_materials_specular": {"specularFactor": 0.0}}
    glass_volume = {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                    "KHR_materials_volume": {"thicknessFactor": 0.8}}

    def conductor(name, roughness):
        return g.pbr_material("%s-%.2f" % (name, roughness), pbr((1, 1, 1), 1.0, roughness),
                              extras={"candela": {"conductor": name}})
    bumps = g.png_texture(64, 64, rgba_image(64, 64, bump_normal))
    rows = [
        [conductor("gold", r) for r in (0.0, 0.25, 0.5, 0.75, 1.0)],
        [conductor(n, 0.2) for n in ("silver", "copper", "aluminium", "chromium", "iron")],
        [g.pbr_material("glass", pbr((1, 1, 1), 0.0, 0.0), glass_volume),
         g.pbr_material("rough-glass", pbr((1, 1, 1), 0.0, 0.3), glass_volume),
         g.pbr_material("thin-glass", pbr((0.9, 1, 0.95), 0.0, 0.0),
                        {"KHR_materials_transmission": {"transmissionFactor": 1.0}}),
         g.pbr_material("red-plastic", pbr((0.8, 0.05, 0.05), 0.0, 0.2)),
         g.pbr_material("blue-plastic", pbr((0.05, 0.1, 0.7), 0.0, 0.6))],
        [g.pbr_material("clearcoat", pbr((0.9, 0.35, 0.05), 0.0, 0.6),
                        {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0,
                                                     "clearcoatRoughnessFactor": 0.05}}),
         g.pbr_material("anisotropic-metal", pbr((0.9, 0.9, 0.9), 1.0, 0.5),
                        {"KHR_materials_anisotropy": {"anisotropyStrength": 0.8}}),
         g.pbr_material("normal-mapped", pbr((0.7, 0.7, 0.7), 0.0, 0.4),
                        normalTexture={"index": bumps}),
         None,  # the alpha-masked card stands here
         g.pbr_material("brass", pbr((1.0, 0.8, 0.4), 1.0, 0.3))],
    ]
    return rows, spec0


def make_materials(path):
    """A grid of spheres: conductor presets over roughness, glass (refracting,
    rough, thin-walled), plastics, clearcoat, anisotropic metal, a normal-mapped
    sphere and an alpha-masked card, over a checker floor under an area light."""
    g = GltfWriter(GENERATOR)
    rows, spec0 = material_rows(g)
    radius = 0.38
    pos, nrm, uv, idx = uv_sphere(radius)
    sphere = {"POSITION": g.vec3_accessor(pos, True), "NORMAL": g.vec3_accessor(nrm, False),
              "TEXCOORD_0": g.vec_accessor(uv, 2)}
    sphere_indices = g.index_accessor(idx)
    for r, row in enumerate(rows):
        for c, mat in enumerate(row):
            if mat is None:
                continue
            name = g.doc["materials"][mat]["name"]
            mesh = g.mesh_from_accessors("smooth-" + name, sphere, sphere_indices, mat)
            g.node(name, mesh=mesh, translation=[c - 2.0, radius, r - 1.5])
    # Alpha-masked card: a quad with a cut-out checker, standing in the front row
    holes = g.png_texture(8, 8, rgba_image(8, 8, lambda x, y: (0.2, 0.6, 0.2, float((x + y) % 2))),
                          nearest=True)
    card = g.pbr_material("masked-card", {"baseColorTexture": {"index": holes}, "metallicFactor": 0.0},
                          spec0, alphaMode="MASK", doubleSided=True)
    card_pos = [f32v(p) for p in ((-0.35, 0.0, 0.0), (0.35, 0.0, 0.0), (0.35, 0.7, 0.0), (-0.35, 0.7, 0.0))]
    card_mesh = g.mesh_from_accessors(
        "card", {"POSITION": g.vec3_accessor(card_pos, True),
                 "NORMAL": g.vec3_accessor([(0.0, 0.0, 1.0)] * 4, False),
                 "TEXCOORD_0": g.vec_accessor([(0, 1), (1, 1), (1, 0), (0, 0)], 2)},
        g.index_accessor([0, 1, 2, 0, 2, 3]), card)
    g.node("masked-card", mesh=card_mesh, translation=[1.0, 0.0, 1.5])
    # Checker floor and the light
    checker = g.png_texture(2, 2, rgba_image(2, 2, lambda x, y: (0.75, 0.75, 0.75, 1) if (x + y) % 2 else (0.3, 0.3, 0.3, 1)),
                            nearest=True)
    floor_mat = g.pbr_material("floor", {"baseColorTexture": {"index": checker}, "metallicFactor": 0.0}, spec0)
    s = 5.0
    floor_pos = [f32v(p) for p in ((-s, 0, s), (s, 0, s), (s, 0, -s), (-s, 0, -s))]
    floor = g.mesh_from_accessors(
        "floor", {"POSITION": g.vec3_accessor(floor_pos, True),
                  "NORMAL": g.vec3_accessor([(0.0, 1.0, 0.0)] * 4, False),
                  "TEXCOORD_0": g.vec_accessor([(0, 10), (10, 10), (10, 0), (0, 0)], 2)},
        g.index_accessor([0, 1, 2, 0, 2, 3]), floor_mat)
    g.node("floor", mesh=floor)
    light = g.material("light", (0.0, 0.0, 0.0, 1.0), emissive=(1.0, 0.95, 0.85), strength=8.0,
                       double_sided=False)
    h, w = 4.0, 1.5
    light_pos = [f32v(p) for p in ((-w, h, -w), (w, h, -w), (w, h, w), (-w, h, w))]
    g.node("light", mesh=g.mesh("light", light_pos, [(0.0, -1.0, 0.0)] * 4, [0, 1, 2, 0, 2, 3], light))
    # Camera above the front edge, looking down the grid
    eye, target = (0.0, 3.2, 6.0), (0.0, 0.2, 0.3)
    f = normalize(sub(target, eye))
    right = normalize(cross(f, (0.0, 1.0, 0.0)))
    up = cross(right, f)
    g.node("camera", camera=g.camera("camera", 0.55, 1.5), translation=list(eye),
           rotation=quat_from_basis(right, up, scale(f, -1.0)))
    g.set_background([0.08, 0.09, 0.11])
    g.write(path)


def make_iridescence(path):
    """A row of spheres with thin films (KHR_materials_iridescence) under an area light:
    a soap-bubble film over black plastic, its thickness varying from pole to pole (texture
    G), a film over silver, over gold, and half a film over red plastic."""
    g = GltfWriter(GENERATOR)
    gradient = g.png_texture(4, 64, rgba_image(4, 64, lambda x, y: (1.0, y / 63.0, 1.0, 1.0)))

    def film(ior, lo, hi, factor=1.0, texture=None):
        ext = {"iridescenceFactor": factor, "iridescenceIor": ior,
               "iridescenceThicknessMinimum": lo, "iridescenceThicknessMaximum": hi}
        if texture is not None:
            ext["iridescenceThicknessTexture"] = {"index": texture}
        return {"KHR_materials_iridescence": ext}
    materials = [
        g.pbr_material("bubble", pbr((0.02, 0.02, 0.02), 0.0, 0.05), film(1.33, 100.0, 400.0)),
        g.pbr_material("thickness-gradient", pbr((0.02, 0.02, 0.02), 0.0, 0.15),
                       film(1.33, 100.0, 900.0, texture=gradient)),
        g.pbr_material("film-silver", pbr((0.97, 0.96, 0.91), 1.0, 0.2), film(1.8, 300.0, 300.0)),
        g.pbr_material("film-gold", pbr((1.0, 0.78, 0.34), 1.0, 0.3), film(1.5, 500.0, 500.0)),
        g.pbr_material("half-film-red", pbr((0.6, 0.04, 0.03), 0.0, 0.3), film(1.3, 250.0, 250.0, 0.5)),
    ]
    sphere_row(g, materials, 0.4, 1.0, -2.0)
    square_floor(g, 6.0, g.pbr_material("floor", pbr((0.5, 0.5, 0.5), 0.0, 0.8),
                                        {"KHR_materials_specular": {"specularFactor": 0.0}}))
    ceiling_panel(g, [(-2.5, 3.0, -2.0), (-2.5, 3.0, 1.0), (2.5, 3.0, 1.0), (2.5, 3.0, -2.0)], 4.0)
    eye = (0.0, 1.3, 4.6)
    g.node("camera", camera=g.camera("camera", 0.62, 2.0), translation=list(eye),
           rotation=look_at_rotation(eye, (0.0, 0.4, 0.0)))
    g.set_background([0.25, 0.27, 0.3])
    g.write(path)


def quat_from_basis(x, y, z):
    """Unit quaternion [x, y, z, w] of the rotation with columns x, y, z."""
    m = [[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]]
    trace = m[0][0] + m[1][1] + m[2][2]
    if trace > 0:
        s = 0.5 / math.sqrt(trace + 1.0)
        return [(m[2][1] - m[1][2]) * s, (m[0][2] - m[2][0]) * s, (m[1][0] - m[0][1]) * s, 0.25 / s]
    i = max(range(3), key=lambda k: m[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2.0 * math.sqrt(1.0 + m[i][i] - m[j][j] - m[k][k])
    q = [0.0, 0.0, 0.0, 0.0]
    q[i] = 0.25 * s
    q[j] = (m[j][i] + m[i][j]) / s
    q[k] = (m[k][i] + m[i][k]) / s
    q[3] = (m[k][j] - m[j][k]) / s
    return q


def look_at_rotation(eye, target, up=(0.0, 1.0, 0.0)):
    """Node rotation whose -Z axis points from eye to target, +Y toward up."""
    z = normalize(sub(eye, target))
    x = normalize(cross(up, z))
    return quat_from_basis(x, cross(z, x), z)


# ---------------------------------------------------------------------------
# Punctual lights

def make_punctual(path):
    """A floor, a sphere and a cube under a warm point light, a blue spot
    light on the cube and a dim directional light from the upper left."""
    g = GltfWriter(GENERATOR)
    grey = g.material("grey", (0.6, 0.6, 0.6, 1.0))
    white = g.material("white", (0.8, 0.8, 0.8, 1.0))
    red = g.material("red", (0.7, 0.15, 0.1, 1.0))
    s = 4.0
    floor = [(-s, 0.0, -s), (-s, 0.0, s), (s, 0.0, s), (s, 0.0, -s)]
    g.node("floor", mesh=g.mesh("floor", *flat_mesh(quad_triangles(
        orient_quad(floor, (0.0, 1.0, 0.0)))), grey))
    g.node("sphere", mesh=g.mesh("sphere", *flat_mesh(icosphere(3, radius=0.5)), red),
           translation=[-0.8, 0.5, 0.0])
    half = math.radians(25.0) / 2.0
    g.node("cube", mesh=g.mesh("cube", *flat_mesh(cube(0.7)), white),
           translation=[0.9, 0.35, 0.3],
           rotation=[0.0, math.sin(half), 0.0, math.cos(half)])
    point = g.punctual_light("warm point", "point", (1.0, 0.8, 0.6), photometric(6.0))
    g.light_node("point", point, translation=[-1.6, 1.6, 1.2])
    spot = g.punctual_light("blue spot", "spot", (0.5, 0.7, 1.0), photometric(30.0),
                            light_range=6.0, inner_cone=0.2, outer_cone=0.35)
    spot_at = [1.4, 3.2, 1.2]
    g.light_node("spot", spot, translation=spot_at,
                 rotation=look_at_rotation(tuple(spot_at), (0.9, 0.35, 0.3)))
    sun = g.punctual_light("sun", "directional", (1.0, 1.0, 0.95), photometric(0.6))
    g.light_node("sun", sun, rotation=look_at_rotation((-2.0, 3.0, 1.0), (0.0, 0.0, 0.0)))
    eye = (0.0, 2.2, 4.8)
    g.node("camera", camera=g.camera("camera", 0.7, 1.5), translation=list(eye),
           rotation=look_at_rotation(eye, (0.0, 0.4, 0.0)))
    g.set_background([0, 0, 0])  # lit by its own lights alone: no default light
    g.write(path)


# ---------------------------------------------------------------------------
# Environment maps (Radiance RGBE .hdr) and the environment scene

def write_hdr(path, width, height, texel):
    """Radiance RGBE .hdr of texel(x, y) -> (r, g, b), row 0 at the top.

    Scanlines use the run-length format's layout (each channel in literal runs of
    at most 128 bytes, no compression), which every reader accepts."""
    def rgbe(rgb):
        v = max(rgb)
        if v < 1e-32:
            return (0, 0, 0, 0)
        m, e = math.frexp(v)
        f = m * 256.0 / v
        return tuple(min(255, int(c * f)) for c in rgb) + (e + 128,)

    out = bytearray(b"#?RADIANCE\n# %s\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n"
                    % (GENERATOR.encode(), height, width))
    for y in range(height):
        pixels = [rgbe(texel(x, y)) for x in range(width)]
        out += bytes((2, 2, width >> 8, width & 255))
        for ch in range(4):
            channel = bytes(p[ch] for p in pixels)
            for i in range(0, width, 128):
                chunk = channel[i:i + 128]
                out += bytes((len(chunk),)) + chunk
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as f:
        f.write(out)


def read_hdr(path):
    """Read back a file of write_hdr: (width, height, rows of (r, g, b))."""
    with open(path, "rb") as f:
        data = f.read()
    head, _, rest = data.partition(b"\n\n")
    assert head.startswith(b"#?RADIANCE") and b"FORMAT=32-bit_rle_rgbe" in head
    size, _, body = rest.partition(b"\n")
    _, h, _, w = size.split()
    w, h = int(w), int(h)
    rows, i = [], 0
    for _ in range(h):
        assert tuple(body[i:i + 4]) == (2, 2, w >> 8, w & 255)
        i += 4
        channels = []
        for _ in range(4):
            ch = bytearray()
            while len(ch) < w:
                n = body[i]
                assert 0 < n <= 128
                ch += body[i + 1:i + 1 + n]
                i += 1 + n
            channels.append(ch)
        rows.append([tuple(math.ldexp(channels[c][x] + 0.5, channels[3][x] - 136) if channels[3][x] else 0.0
                           for c in range(3)) for x in range(w)])
    assert i == len(body)
    return w, h, rows


def env_direction(u, v):
    """Direction of map coordinates (u, v) at rotation 0 (cl/lights/environment.cl): theta
    from +Y down the rows, the image centre along -Z, u = 3/4 along +X."""
    theta, phi = math.pi * v, 2.0 * math.pi * u
    return (-math.sin(theta) * math.sin(phi), math.cos(theta), math.sin(theta) * math.cos(phi))


SUN_UV = (0.1, (90.0 - 35.0) / 180.0)  # 35 degrees high, behind a camera looking down -Z, to its left


def sky_texel(width, height):
    """Sun and sky: a gradient from a bright horizon to a blue zenith, a darker ground,
    and a sun disc of 2 degrees' radius and radiance about 1000."""
    sun = env_direction(*SUN_UV)
    cos_sun = math.cos(math.radians(2.0))

    def texel(x, y):
        d = env_direction((x + 0.5) / width, (y + 0.5) / height)
        if dot(d, sun) > cos_sun:
            return (1000.0, 950.0, 850.0)
        if d[1] >= 0.0:
            t = math.sqrt(d[1])
            horizon, zenith = (1.2, 1.25, 1.3), (0.3, 0.5, 1.0)
            return tuple(h + (z - h) * t for h, z in zip(horizon, zenith))
        fade = math.exp(d[1] / 0.05)
        return tuple(g + (1.2 - g) * fade for g in (0.25, 0.22, 0.18))
    return texel


def tiny_sun_texel(width, height):
    """A dim uniform 0.02 with a sun of 2 x 2 texels of radiance 1000, 45 degrees high."""
    sx, sy = int(SUN_UV[0] * width), height // 4 - 1

    def texel(x, y):
        return (1000.0,) * 3 if x in (sx, sx + 1) and y in (sy, sy + 1) else (0.02,) * 3
    return texel


def make_sky_map(path):
    write_hdr(path, 256, 128, sky_texel(256, 128))


def make_tiny_sun_map(path):
    write_hdr(path, 128, 64, tiny_sun_texel(128, 64))


def sphere_row(g, materials, radius, spacing, x0):
    """One smooth UV sphere (accessors shared) per material, named after it, resting on
    y = 0 in a row along x: sphere k at x = spacing k + x0."""
    pos, nrm, uv, idx = uv_sphere(radius)
    sphere = {"POSITION": g.vec3_accessor(pos, True), "NORMAL": g.vec3_accessor(nrm, False),
              "TEXCOORD_0": g.vec_accessor(uv, 2)}
    sphere_indices = g.index_accessor(idx)
    for k, mat in enumerate(materials):
        name = g.doc["materials"][mat]["name"]
        mesh = g.mesh_from_accessors("smooth-" + name, sphere, sphere_indices, mat)
        g.node(name, mesh=mesh, translation=[spacing * k + x0, radius, 0.0])


def sky_environment(g):
    """The scene lit by sky.hdr (strength 1, unrotated) through the scene extras."""
    g.doc["scenes"][0]["extras"] = {"candela": {"environment": {"file": "sky.hdr", "strength": 1.0,
                                                                "rotation": 0.0}}}


def square_floor(g, s, material):
    """The node "floor": the square +-s on y = 0, facing up."""
    g.node("floor", mesh=g.mesh("floor", *flat_mesh(quad_triangles(orient_quad(
        [(-s, 0.0, -s), (-s, 0.0, s), (s, 0.0, s), (s, 0.0, -s)], (0.0, 1.0, 0.0)))), material))


def ceiling_panel(g, corners, strength=None):
    """The node "panel": a one-sided white emitter (radiance `strength`, 1 where None)
    over the quad `corners`, facing down."""
    light = g.material("panel", (0.0, 0.0, 0.0, 1.0), emissive=(1.0, 1.0, 1.0), strength=strength,
                       double_sided=False)
    g.node("panel", mesh=g.mesh("panel", *flat_mesh(quad_triangles(orient_quad(
        [f32v(q) for q in corners], (0.0, -1.0, 0.0)))), light))


def make_environment(path):
    """Spheres of several materials on a floor, lit by sky.hdr through the scene extras."""
    g = GltfWriter(GENERATOR)
    spec0 = {"KHR_materials_specular": {"specularFactor": 0.0}}
    materials = [
        g.pbr_material("white-diffuse", pbr((0.8, 0.8, 0.8), 0.0, 1.0), spec0),
        g.pbr_material("gold", pbr((1, 1, 1), 1.0, 0.3), extras={"candela": {"conductor": "gold"}}),
        g.pbr_material("glass", pbr((1, 1, 1), 0.0, 0.0),
                       {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                        "KHR_materials_volume": {"thicknessFactor": 1.0}}),
        g.pbr_material("red-plastic", pbr((0.8, 0.05, 0.05), 0.0, 0.2)),
    ]
    sphere_row(g, materials, 0.45, 1.1, -1.65)
    floor_mat = g.pbr_material("floor", pbr((0.5, 0.5, 0.5), 0.0, 1.0), spec0)
    s = 6.0
    floor_pos = [f32v(p) for p in ((-s, 0, s), (s, 0, s), (s, 0, -s), (-s, 0, -s))]
    g.node("floor", mesh=g.mesh("floor", floor_pos, [(0.0, 1.0, 0.0)] * 4, [0, 1, 2, 0, 2, 3], floor_mat))
    look_camera(g, (0.0, 1.3, 4.2), (0.0, 0.4, 0.0), 0.6, 1.6)
    sky_environment(g)
    g.write(path)


# ---------------------------------------------------------------------------
# Light vs BSDF sampling: where each fails (Veach 1997, ch. 9: his plates' layout)

def metal_pbr(g, name, roughness, base=(0.8, 0.8, 0.8)):
    return g.pbr_material(name, {"baseColorFactor": list(base) + [1.0], "metallicFactor": 1.0,
                                 "roughnessFactor": roughness})


def plate_quad(centre, normal, half_width, half_depth):
    """Corners of a plate spanning +-half_width along x, facing `normal`."""
    x = (1.0, 0.0, 0.0)
    t = normalize(cross(normal, x))  # in the plate, perpendicular to x
    corners = []
    for sx, st in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
        corners.append(f32v(add(centre, add(scale(x, sx * half_width), scale(t, st * half_depth)))))
    return orient_quad(corners, normal)


def look_camera(g, eye, target, yfov, aspect):
    f = normalize(sub(target, eye))
    right = normalize(cross(f, (0.0, 1.0, 0.0)))
    g.node("camera", camera=g.camera("camera", yfov, aspect), translation=list(eye),
           rotation=quat_from_basis(right, cross(right, f), scale(f, -1.0)))


def make_veach(path):
    """Veach's (1997, fig. 9.2) layout with numbers of our own: four metal plates of
    glTF roughness 0.5, 0.3, 0.15, 0.05 (alpha 0.25 ... 0.0025), each tilted to reflect a
    row of four spherical lights of radius 0.1, 0.2, 0.4, 0.8 and equal power
    (radiance 2 (0.8 / r)^2) toward the camera, in front of a dark wall."""
    g = GltfWriter(GENERATOR)
    eye, light_row = (0.0, 2.0, 10.0), (0.0, 4.0, -3.5)
    for k, (roughness, centre) in enumerate(zip((0.5, 0.3, 0.15, 0.05), (
            (0.0, 0.0, 2.4), (0.0, 0.45, 1.3), (0.0, 0.95, 0.2), (0.0, 1.5, -0.9)))):
        normal = normalize(add(normalize(sub(eye, centre)), normalize(sub(light_row, centre))))
        mat = metal_pbr(g, "plate-r%.2f" % roughness, roughness)
        g.node("plate%d" % k, mesh=g.mesh("plate%d" % k, *flat_mesh(quad_triangles(
            plate_quad(centre, normal, 4.0, 0.45))), mat))
    for k, radius in enumerate((0.1, 0.2, 0.4, 0.8)):
        radiance = 2.0 * (0.8 / radius) ** 2
        mat = g.material("light-r%.2f" % radius, (0.0, 0.0, 0.0, 1.0), emissive=(1.0, 1.0, 1.0),
                         strength=radiance, double_sided=False)
        g.node("light%d" % k, mesh=g.mesh("light%d" % k, *flat_mesh(icosphere(3, radius=radius)), mat),
               translation=[-3.0 + 2.0 * k, light_row[1], light_row[2]])
    wall = g.material("wall", (0.15, 0.15, 0.15, 1.0))
    w = [(-12.0, -4.0, -6.0), (12.0, -4.0, -6.0), (12.0, 10.0, -6.0), (-12.0, 10.0, -6.0)]
    g.node("wall", mesh=g.mesh("wall", *flat_mesh(quad_triangles(orient_quad(
        [f32v(p) for p in w], (0.0, 0.0, 1.0)))), wall))
    look_camera(g, eye, (0.0, 0.9, 0.0), 0.55, 1.5)
    g.doc["scenes"][0]["extras"] = {"candela": {"strategy": "auto"}}  # the scene-side default
    g.set_background([0, 0, 0])  # lit by its own lights alone: no default light
    g.write(path)


def make_small_light(path):
    """A diffuse floor under a small (radius 0.05) bright spherical light: light
    sampling finds it every time, BSDF sampling rarely."""
    g = GltfWriter(GENERATOR)
    floor = g.material("floor", (0.5, 0.5, 0.5, 1.0))
    square_floor(g, 2.0, floor)
    light = g.material("light", (0.0, 0.0, 0.0, 1.0), emissive=(1.0, 1.0, 1.0), strength=400.0,
                       double_sided=False)
    g.node("light", mesh=g.mesh("light", *flat_mesh(icosphere(2, radius=0.05)), light),
           translation=[0.0, 0.6, 0.0])
    look_camera(g, (0.0, 2.2, 2.6), (0.0, 0.0, 0.0), 0.8, 1.5)
    g.set_background([0, 0, 0])  # lit by its own lights alone: no default light
    g.write(path)


def make_large_light_glossy(path):
    """A large area light (3 x 1.5, radiance 1) above a metal floor of glTF roughness
    0.08 (alpha 0.0064), seen in reflection: BSDF sampling finds it, light sampling picks
    points the narrow lobe hardly reflects."""
    g = GltfWriter(GENERATOR)
    metal = metal_pbr(g, "metal-r0.08", 0.08, (0.9, 0.9, 0.9))
    square_floor(g, 3.0, metal)
    ceiling_panel(g, [(-1.5, 1.5, -2.0), (1.5, 1.5, -2.0), (1.5, 1.5, -0.5), (-1.5, 1.5, -0.5)])
    look_camera(g, (0.0, 1.2, 3.5), (0.0, 0.0, -0.6), 0.7, 1.5)
    g.set_background([0, 0, 0])  # lit by its own lights alone: no default light
    g.write(path)


def make_near_specular(path, environment):
    """The near-specular failure cases: metal of glTF roughness 0.02, 0.1 and 0.3 and
    glass of roughness 0.1 (thin-walled, then solid) on a diffuse floor, under a large
    area light (3 x 1.5, radiance 4) behind the camera's view and above, or lit by
    sky.hdr. Light sampling alone speckles the sharp lobes and the caustics under the
    glass; BSDF sampling alone the floor (small sun)."""
    g = GltfWriter(GENERATOR)
    glass = {"KHR_materials_transmission": {"transmissionFactor": 1.0}}
    materials = [
        metal_pbr(g, "metal-r0.02", 0.02, (0.9, 0.9, 0.9)),
        metal_pbr(g, "metal-r0.1", 0.1, (0.9, 0.9, 0.9)),
        metal_pbr(g, "metal-r0.3", 0.3, (0.9, 0.9, 0.9)),
        g.pbr_material("thin-glass-r0.1", pbr((1, 1, 1), 0.0, 0.1), dict(glass)),
        g.pbr_material("glass-r0.1", pbr((1, 1, 1), 0.0, 0.1),
                       dict(glass, KHR_materials_volume={"thicknessFactor": 1.0})),
    ]
    sphere_row(g, materials, 0.4, 0.95, -1.9)
    floor = g.material("floor", (0.5, 0.5, 0.5, 1.0))
    square_floor(g, 4.0, floor)
    if environment:
        sky_environment(g)
    else:
        ceiling_panel(g, [(-1.5, 2.5, -1.0), (1.5, 2.5, -1.0), (1.5, 2.5, 0.5), (-1.5, 2.5, 0.5)], 4.0)
        g.set_background([0, 0, 0])  # lit by its own light alone: no default light
    look_camera(g, (0.0, 1.4, 4.0), (0.0, 0.35, 0.0), 0.55, 2.0)
    g.write(path)


def make_many_lights(path):
    """4096 small emissive quads (8192 triangles, 8 colours) floating in a 64 x 64 grid
    over a diffuse floor with a few spheres: light selection by power through the alias
    table must not slow down per light."""
    g = GltfWriter(GENERATOR)
    floor = g.material("floor", (0.6, 0.6, 0.6, 1.0))
    square_floor(g, 4.0, floor)
    ball = g.material("ball", (0.7, 0.7, 0.7, 1.0))
    sphere = flat_mesh(icosphere(2, radius=0.5))
    for k, x in enumerate((-1.5, 0.0, 1.5)):
        g.node("ball%d" % k, mesh=g.mesh("ball%d" % k, *sphere, ball), translation=[x, 0.5, 0.0])
    colours = [(1.0, 0.3, 0.2), (0.2, 1.0, 0.3), (0.3, 0.4, 1.0), (1.0, 0.9, 0.3),
               (1.0, 0.4, 0.9), (0.3, 1.0, 1.0), (1.0, 1.0, 1.0), (1.0, 0.6, 0.2)]
    quads = [[] for _ in colours]
    state, n, h = 12345, 64, 0.02
    for i in range(n):
        for j in range(n):
            state = (1103515245 * state + 12345) % (1 << 31)
            x, z = -3.6 + 7.2 * (i + 0.5) / n, -3.6 + 7.2 * (j + 0.5) / n
            y = 1.6 + 0.8 * ((state >> 8) % 1000) / 1000.0
            quads[state % len(colours)].append(
                [(x - h, y, z - h), (x - h, y, z + h), (x + h, y, z + h), (x + h, y, z - h)])
    for c, (colour, group) in enumerate(zip(colours, quads)):
        mat = g.material("emitter%d" % c, (0.0, 0.0, 0.0, 1.0), emissive=colour, strength=4.0)
        positions, indices = [], []
        for q in group:
            base = len(positions)
            positions += [f32v(p) for p in orient_quad(q, (0.0, -1.0, 0.0))]
            indices += [base, base + 1, base + 2, base, base + 2, base + 3]
        normals = [(0.0, -1.0, 0.0)] * len(positions)
        g.node("emitters%d" % c, mesh=g.mesh("emitters%d" % c, positions, normals, indices, mat))
    look_camera(g, (0.0, 3.0, 7.5), (0.0, 0.6, 0.0), 0.7, 1.5)
    g.set_background([0, 0, 0])  # lit by its own lights alone: no default light
    g.write(path)


# ---------------------------------------------------------------------------
# Volumes

def oriented(tri, wanted):
    """Triangle (a, b, c) wound so that its front faces direction `wanted`."""
    a, b, c = tri
    return tri if dot(cross(sub(b, a), sub(c, a)), wanted) > 0 else (a, c, b)


def box_tris(lo, hi, inward=False):
    """Twelve triangles of the axis-aligned box [lo, hi], fronts outward (or inward)."""
    centre = scale(add(lo, hi), 0.5)
    size = sub(hi, lo)
    tris = []
    for tri in cube(1.0):
        moved = tuple(f32v([centre[k] + size[k] * p[k] for k in range(3)]) for p in tri)
        tris.append((moved[0], moved[2], moved[1]) if inward else moved)
    return tris


def wall_with_window(x, lo, hi, window):
    """The wall x = const spanning y, z in lo..hi (pairs) around a window
    (y0, y1, z0, z1), as quads facing +x."""
    (y_lo, z_lo), (y_hi, z_hi) = lo, hi
    y0, y1, z0, z1 = window
    rects = [(y_lo, y0, z_lo, z_hi), (y1, y_hi, z_lo, z_hi),
             (y0, y1, z_lo, z0), (y0, y1, z1, z_hi)]
    tris = []
    for a, b, c, d in rects:
        quad = [f32v((x, a, c)), f32v((x, b, c)), f32v((x, b, d)), f32v((x, a, d))]
        tris += quad_triangles(orient_quad(quad, (1.0, 0.0, 0.0)))
    return tris


def null_medium_material(g, name, medium):
    """An invisible boundary (no transmission) around the medium in extras."""
    return g.pbr_material(name, {"baseColorFactor": [1, 1, 1, 1]},
                          extras={"candela": {"medium": medium}})


def make_god_rays(path):
    """A dusty room lit by a low sun through one window: the fog fills the room
    (a null boundary just inside the walls) and shows the beam."""
    g = GltfWriter(GENERATOR)
    wall = g.material("plaster", (0.7, 0.68, 0.65, 1.0))
    floor_mat = g.material("floor", (0.45, 0.4, 0.35, 1.0))
    lo, hi = (-2.0, 0.0, -2.0), (2.0, 3.0, 2.0)
    room = [t for t in box_tris(lo, hi, inward=True)
            if not all(abs(p[0] - lo[0]) < 1e-6 for p in t)]  # the window wall apart
    floor = [t for t in room if all(abs(p[1]) < 1e-6 for p in t)]
    rest = [t for t in room if t not in floor]
    g.node("walls", mesh=g.mesh("walls", *flat_mesh(rest), wall))
    g.node("floor", mesh=g.mesh("floor", *flat_mesh(floor), floor_mat))
    g.node("window wall", mesh=g.mesh("window wall", *flat_mesh(
        wall_with_window(lo[0], (lo[1], lo[2]), (hi[1], hi[2]), (1.2, 2.4, -0.6, 0.6))), wall))
    block = g.material("block", (0.6, 0.2, 0.15, 1.0))
    g.node("block", mesh=g.mesh("block", *flat_mesh(box_tris((0.3, 0.0, -0.5), (1.1, 0.8, 0.3))), block))
    fog = null_medium_material(g, "fog", {"sigma_a": [0.01, 0.01, 0.01],
                                          "sigma_s": [0.2, 0.2, 0.2], "g": 0.6})
    inset = 0.001
    g.node("fog", mesh=g.mesh("fog", *flat_mesh(box_tris(
        add(lo, (inset, inset, inset)), sub(hi, (inset, inset, inset)))), fog))
    sun = g.punctual_light("sun", "directional", (1.0, 0.9, 0.75), photometric(25.0))
    g.light_node("sun", sun, rotation=look_at_rotation((-3.0, 3.2, 0.8), (0.0, 0.0, 0.0)))
    eye = (1.8, 1.5, 1.8)
    g.node("camera", camera=g.camera("camera", 1.1, 1.5), translation=list(eye),
           rotation=look_at_rotation(eye, (-1.0, 1.0, -0.6)))
    g.set_background([0.3, 0.4, 0.6])  # sky seen through the window
    g.write(path)


def cup_tris(r_out, r_in, height, bottom, segments=48):
    """A closed glass cup: outer wall and base, inner wall and floor at
    `bottom`, and the rim; fronts face out of the glass."""
    tris = []
    ring = [(math.cos(2 * math.pi * k / segments), math.sin(2 * math.pi * k / segments))
            for k in range(segments)]
    for k in range(segments):
        (c0, s0), (c1, s1) = ring[k], ring[(k + 1) % segments]
        mid = ((c0 + c1) / 2, 0.0, (s0 + s1) / 2)

        def p(r, c, s, y):
            return f32v((r * c, y, r * s))
        ob0, ob1 = p(r_out, c0, s0, 0.0), p(r_out, c1, s1, 0.0)
        ot0, ot1 = p(r_out, c0, s0, height), p(r_out, c1, s1, height)
        ib0, ib1 = p(r_in, c0, s0, bottom), p(r_in, c1, s1, bottom)
        it0, it1 = p(r_in, c0, s0, height), p(r_in, c1, s1, height)
        centre_lo, centre_in = f32v((0.0, 0.0, 0.0)), f32v((0.0, bottom, 0.0))
        tris += [oriented(t, mid) for t in ((ob0, ob1, ot1), (ob0, ot1, ot0))]
        tris += [oriented(t, scale(mid, -1.0)) for t in ((ib0, ib1, it1), (ib0, it1, it0))]
        tris.append(oriented((centre_lo, ob0, ob1), (0.0, -1.0, 0.0)))
        tris.append(oriented((centre_in, ib0, ib1), (0.0, 1.0, 0.0)))
        tris += [oriented(t, (0.0, 1.0, 0.0)) for t in ((ot0, ot1, it1), (ot0, it1, it0))]
    return tris


def cylinder_tris(radius, y0, y1, segments=48):
    """A closed cylinder around the y axis, fronts outward."""
    tris = []
    for k in range(segments):
        a0, a1 = 2 * math.pi * k / segments, 2 * math.pi * (k + 1) / segments
        c0, s0, c1, s1 = math.cos(a0), math.sin(a0), math.cos(a1), math.sin(a1)
        mid = ((c0 + c1) / 2, 0.0, (s0 + s1) / 2)
        b0, b1 = f32v((radius * c0, y0, radius * s0)), f32v((radius * c1, y0, radius * s1))
        t0, t1 = f32v((radius * c0, y1, radius * s0)), f32v((radius * c1, y1, radius * s1))
        tris += [oriented(t, mid) for t in ((b0, b1, t1), (b0, t1, t0))]
        tris.append(oriented((f32v((0.0, y0, 0.0)), b0, b1), (0.0, -1.0, 0.0)))
        tris.append(oriented((f32v((0.0, y1, 0.0)), b0, b1), (0.0, 1.0, 0.0)))
    return tris


def make_liquid_glass(path):
    """A clear glass of red-orange liquid (KHR_materials_volume attenuation) on
    a table under an area light. The liquid reaches 1 mm into the glass wall:
    the medium stack hands the ray from glass to liquid there."""
    g = GltfWriter(GENERATOR)
    table = g.material("table", (0.55, 0.55, 0.5, 1.0))
    s = 3.0
    top = [(-s, 0.0, -s), (-s, 0.0, s), (s, 0.0, s), (s, 0.0, -s)]
    g.node("table", mesh=g.mesh("table", *flat_mesh(quad_triangles(orient_quad(top, (0.0, 1.0, 0.0)))), table))
    light = g.material("light", (0.0, 0.0, 0.0, 1.0), emissive=(1.0, 0.95, 0.9), strength=12.0)
    lq = [f32v(p) for p in ((-0.5, 2.2, -0.9), (0.5, 2.2, -0.9), (0.5, 2.2, 0.1), (-0.5, 2.2, 0.1))]
    g.node("light", mesh=g.mesh("light", *flat_mesh(quad_triangles(orient_quad(lq, (0.0, -1.0, 0.0)))), light))
    volume_ext = {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                  "KHR_materials_ior": {"ior": 1.5},
                  "KHR_materials_volume": {"thicknessFactor": 0.05}}
    glass = g.pbr_material("glass", {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0.0,
                                     "roughnessFactor": 0.0}, volume_ext)
    liquid_ext = {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                  "KHR_materials_ior": {"ior": 1.33},
                  "KHR_materials_volume": {"thicknessFactor": 0.3, "attenuationDistance": 0.15,
                                           "attenuationColor": [0.9, 0.35, 0.08]}}
    liquid = g.pbr_material("liquid", {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0.0,
                                       "roughnessFactor": 0.0}, liquid_ext)
    r_out, r_in, bottom = 0.32, 0.29, 0.05
    g.node("glass", mesh=g.mesh("glass", *flat_mesh(cup_tris(r_out, r_in, 0.9, bottom)), glass))
    g.node("liquid", mesh=g.mesh("liquid", *flat_mesh(cylinder_tris(r_in + 0.001, bottom - 0.001, 0.6)), liquid))
    eye = (0.0, 1.1, 2.2)
    g.node("camera", camera=g.camera("camera", 0.6, 1.0), translation=list(eye),
           rotation=look_at_rotation(eye, (0.0, 0.4, 0.0)))
    g.set_background([0.15, 0.16, 0.18])
    g.write(path)


def value_noise(x, y, z, seed):
    """Smooth value noise in [0, 1] on the integer lattice (a hash per node)."""
    def node(i, j, k):
        h = (i * 73856093) ^ (j * 19349663) ^ (k * 83492791) ^ (seed * 2654435761)
        h = (h ^ (h >> 13)) * 1274126177 & 0xFFFFFFFF
        return ((h ^ (h >> 16)) & 0xFFFF) / 65535.0
    i, j, k = math.floor(x), math.floor(y), math.floor(z)
    fx, fy, fz = x - i, y - j, z - k
    sx, sy, sz = (f * f * (3 - 2 * f) for f in (fx, fy, fz))

    def lerp(a, b, t):
        return a + (b - a) * t
    c = [[[node(i + a, j + b, k + c_) for c_ in (0, 1)] for b in (0, 1)] for a in (0, 1)]
    return lerp(lerp(lerp(c[0][0][0], c[1][0][0], sx), lerp(c[0][1][0], c[1][1][0], sx), sy),
                lerp(lerp(c[0][0][1], c[1][0][1], sx), lerp(c[0][1][1], c[1][1][1], sx), sy), sz)


def cloud_density(n, seed=7):
    """An n^3 density grid: three octaves of value noise under a soft
    ellipsoid falloff, 0 at the box's faces."""
    values = []
    for z in range(n):
        for y in range(n):
            for x in range(n):
                u, v, w = (2.0 * c / (n - 1) - 1.0 for c in (x, y, z))
                r2 = u * u + (1.6 * v) * (1.6 * v) + w * w
                shape = max(0.0, 1.0 - r2)
                f = sum(value_noise(u * 3 * 2 ** o + 10, v * 3 * 2 ** o, w * 3 * 2 ** o, seed + o) / 2 ** o
                        for o in range(3)) / 1.75
                values.append(round(max(0.0, shape * 2.0 * f - 0.15) * 1.5, 4))
    return values


def make_cloud(path):
    """A procedural noise cloud (a density grid in the medium's extras) inside
    a null-boundary box, lit by the sun over a ground plane and a sky."""
    g = GltfWriter(GENERATOR)
    ground = g.material("ground", (0.35, 0.4, 0.3, 1.0))
    s = 8.0
    plane = [(-s, 0.0, -s), (-s, 0.0, s), (s, 0.0, s), (s, 0.0, -s)]
    g.node("ground", mesh=g.mesh("ground", *flat_mesh(quad_triangles(orient_quad(plane, (0.0, 1.0, 0.0)))), ground))
    lo, hi = (-1.5, 0.6, -1.5), (1.5, 2.4, 1.5)
    n = 24
    medium = {"sigma_a": [0.05, 0.05, 0.05], "sigma_s": [4.0, 4.0, 4.0], "g": 0.5,
              "grid": {"size": [n, n, n], "min": list(lo), "max": list(hi),
                       "density": cloud_density(n)}}
    cloud = null_medium_material(g, "cloud", medium)
    g.node("cloud", mesh=g.mesh("cloud", *flat_mesh(box_tris(lo, hi)), cloud))
    sun = g.punctual_light("sun", "directional", (1.0, 0.95, 0.85), photometric(3.0))
    g.light_node("sun", sun, rotation=look_at_rotation((2.0, 3.0, 1.0), (0.0, 0.0, 0.0)))
    eye = (0.0, 1.4, 5.5)
    g.node("camera", camera=g.camera("camera", 0.75, 1.5), translation=list(eye),
           rotation=look_at_rotation(eye, (0.0, 1.3, 0.0)))
    g.set_background([0.35, 0.5, 0.8])
    g.write(path)



def smoothstep(a, b, x):
    t = min(1.0, max(0.0, (x - a) / (b - a)))
    return t * t * (3.0 - 2.0 * t)


def plume_density(size, lo, hi, seed=11):
    """A rising smoke column on a grid of `size` nodes spanning [lo, hi]: its
    radius widens with height, its axis drifts along +x, the density falls as
    the column widens (the same mass through a wider section: the base is the
    densest, and so, with emission = emission x density, the hottest), and
    three octaves of value noise stretched along the rise tear it into wisps.
    0 outside the column and on every face of the box."""
    nx, ny, nz = size
    values = []
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                x = lo[0] + (hi[0] - lo[0]) * i / (nx - 1)
                h = lo[1] + (hi[1] - lo[1]) * j / (ny - 1)
                z = lo[2] + (hi[2] - lo[2]) * k / (nz - 1)
                radius = 0.28 + 0.16 * h
                cx = 0.05 * h * h + 0.04 * math.sin(2.3 * h)
                cz = 0.03 * math.sin(1.7 * h + 1.0)
                r2 = ((x - cx) ** 2 + (z - cz) ** 2) / (radius * radius)
                radial = max(0.0, 1.0 - r2) ** 2
                f = sum(value_noise(x * 4.0 * 2 ** o + 5.0, h * 2.2 * 2 ** o, z * 4.0 * 2 ** o, seed + o)
                        / 2 ** o for o in range(3)) / 1.75
                wisps = max(0.0, 2.2 * f - 0.7)
                rise = (0.28 / radius) ** 3
                ends = smoothstep(lo[1], lo[1] + 0.12, h) * (1.0 - smoothstep(hi[1] - 0.8, hi[1], h))
                v = 2.5 * rise * radial * wisps * ends
                values.append(round(v, 3) if v >= 5e-4 else 0)
    return values


def write_with_inline_list(g, path, key_path):
    """g.write(path), then rewrite the file with the long number list at
    key_path (keys from the document root) on one line: a density grid one
    number per line would be several times the size."""
    g.write(path)
    with open(path, encoding="utf-8") as f:
        doc = json.load(f)
    parent = doc
    for key in key_path[:-1]:
        parent = parent[key]
    values = parent[key_path[-1]]
    parent[key_path[-1]] = "@INLINE@"
    text = json.dumps(doc, indent=2).replace('"@INLINE@"', json.dumps(values, separators=(",", ":")))
    with open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write(text)
        f.write("\n")


def make_plume(path):
    """An emissive smoke plume (a density grid whose emission scales with the
    density, so the dense base glows hottest) over a floor at night: the plume
    is the main light of the scene; a faint blue sky is the only other."""
    g = GltfWriter(GENERATOR)
    floor_mat = g.material("floor", (0.4, 0.38, 0.36, 1.0))
    s = 8.0
    plane = [(-s, 0.0, -s), (-s, 0.0, s), (s, 0.0, s), (s, 0.0, -s)]
    g.node("floor", mesh=g.mesh("floor", *flat_mesh(quad_triangles(orient_quad(plane, (0.0, 1.0, 0.0)))), floor_mat))
    stone = g.material("stone", (0.55, 0.55, 0.55, 1.0))
    g.node("block", mesh=g.mesh("block", *flat_mesh(box_tris((-1.7, 0.0, -0.5), (-1.05, 0.65, 0.15))), stone))
    ball = g.material("ball", (0.7, 0.7, 0.7, 1.0))
    g.node("sphere", mesh=g.mesh("sphere", *flat_mesh(icosphere(2, 0.35)), ball),
           translation=[1.25, 0.35, 0.45])
    lo, hi = (-0.9, 0.002, -0.9), (1.3, 3.4, 0.9)
    size = [28, 40, 24]
    medium = {"sigma_a": [0.5, 0.5, 0.5], "sigma_s": [1.0, 1.0, 1.0], "g": 0.3,
              "emission": [10.0, 3.3, 0.7],
              "grid": {"size": size, "min": list(lo), "max": list(hi),
                       "density": plume_density(size, lo, hi)}}
    plume = null_medium_material(g, "plume", medium)
    g.node("plume", mesh=g.mesh("plume", *flat_mesh(box_tris(lo, hi)), plume))
    eye = (0.3, 1.3, 5.0)
    g.node("camera", camera=g.camera("camera", 0.75, 1.6), translation=list(eye),
           rotation=look_at_rotation(eye, (0.1, 1.35, 0.0)))
    g.set_background([0.004, 0.006, 0.012])
    write_with_inline_list(g, path, ["materials", plume, "extras", "candela", "medium", "grid", "density"])


# ---------------------------------------------------------------------------

MAPS = [
    ("scenes/lights/sky.hdr", make_sky_map),
    ("scenes/lights/tiny-sun.hdr", make_tiny_sun_map),
]

SCENES = [
    ("scenes/cornell-box/cornell-box.gltf", make_cornell_box),
    ("scenes/furnace/closed-sphere.gltf", make_closed_sphere),
    ("scenes/furnace/white-objects.gltf", make_white_objects),
    ("scenes/materials/materials.gltf", make_materials),
    ("scenes/materials/iridescence.gltf", make_iridescence),
    ("scenes/lights/punctual.gltf", make_punctual),
    ("scenes/lights/environment.gltf", make_environment),
    ("scenes/lights/veach.gltf", make_veach),
    ("scenes/lights/small-light.gltf", make_small_light),
    ("scenes/lights/large-light-glossy.gltf", make_large_light_glossy),
    ("scenes/lights/many-lights.gltf", make_many_lights),
    ("scenes/lights/near-specular.gltf", lambda path: make_near_specular(path, False)),
    ("scenes/lights/near-specular-sky.gltf", lambda path: make_near_specular(path, True)),
    ("scenes/volumes/god-rays.gltf", make_god_rays),
    ("scenes/volumes/liquid-glass.gltf", make_liquid_glass),
    ("scenes/volumes/cloud.gltf", make_cloud),
    ("scenes/volumes/plume.gltf", make_plume),
]


def main():
    for rel_path, make in MAPS:
        path = os.path.join(REPO_ROOT, rel_path)
        make(path)
        w, h, rows = read_hdr(path)
        peak = max(max(t) for row in rows for t in row)
        print("wrote %s: %d x %d texels, peak radiance %.0f" % (rel_path, w, h, peak))
    for rel_path, make in SCENES:
        path = os.path.join(REPO_ROOT, rel_path)
        make(path)
        counts = check_gltf(path)
        total = sum(counts.values())
        detail = ", ".join("%s %d" % kv for kv in counts.items())
        print("wrote %s: %d triangles (%s)" % (rel_path, total, detail))


if __name__ == "__main__":
    main()
