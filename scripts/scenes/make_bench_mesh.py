#!/usr/bin/env python3
"""Write the benchmark's large-mesh scene: a noise-displaced sphere of about a
million triangles (smooth shared-vertex normals) over a floor, lit by a square
area light, with a camera.  Not committed: scripts/bench/bench.sh writes it to
build/bench/ on demand.

Usage: scripts/scenes/make_bench_mesh.py OUT.gltf [TRIANGLES (default 1000000)]

The buffer goes to OUT.bin beside the .gltf.  Deterministic output.
"""

import array
import json
import math
import os
import sys


def displaced_sphere(segments, rings):
    """Lat-long grid sphere with a bumpy radius; returns positions, normals
    (flat lists of floats) and triangle indices (flat list)."""
    def radius(theta, phi):
        return 0.8 * (1.0 + 0.06 * math.sin(7.0 * theta) * math.sin(5.0 * phi)
                      + 0.025 * math.sin(23.0 * theta + 1.3) * math.sin(19.0 * phi + 0.7)
                      + 0.01 * math.sin(61.0 * theta + 0.4) * math.sin(57.0 * phi + 2.1))

    def point(theta, phi):
        r = radius(theta, phi)
        st = math.sin(theta)
        return (r * st * math.cos(phi), 1.0 + r * math.cos(theta), r * st * math.sin(phi))

    pos = array.array("f")
    nrm = array.array("f")
    h = 1e-4
    for i in range(rings + 1):  # theta from 0 (top) to pi
        theta = math.pi * i / rings
        for j in range(segments):
            phi = 2.0 * math.pi * j / segments
            p = point(theta, phi)
            pos.extend(p)
            # Normal from the finite-difference tangents (outward); poles: radial
            a = point(theta + h, phi)
            b = point(theta, phi + h)
            ta = (a[0] - p[0], a[1] - p[1], a[2] - p[2])
            tb = (b[0] - p[0], b[1] - p[1], b[2] - p[2])
            n = (ta[1] * tb[2] - ta[2] * tb[1], ta[2] * tb[0] - ta[0] * tb[2], ta[0] * tb[1] - ta[1] * tb[0])
            length = math.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
            if not length > 1e-12 or i == 0 or i == rings:
                n = (p[0], p[1] - 1.0, p[2])
                length = math.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) or 1.0
            nrm.extend((n[0] / length, n[1] / length, n[2] / length))
    idx = array.array("I")
    for i in range(rings):
        row, nxt = i * segments, (i + 1) * segments
        for j in range(segments):
            j1 = (j + 1) % segments
            a, b, c, d = row + j, row + j1, nxt + j, nxt + j1
            if i > 0:  # the top row's quads collapse to triangles (a == b in space)
                idx.extend((a, b, c))
            if i < rings - 1:
                idx.extend((b, d, c))
    return pos, nrm, idx


def bounds(values):
    return ([min(values[k::3]) for k in range(3)], [max(values[k::3]) for k in range(3)])


def main():
    out = sys.argv[1]
    target = int(sys.argv[2]) if len(sys.argv) > 2 else 1000000
    # About 2 * segments * rings triangles, segments = 2 * rings
    rings = max(4, int(round(math.sqrt(target / 4.0))))
    segments = 2 * rings
    pos, nrm, idx = displaced_sphere(segments, rings)
    s, l, y = 4.0, 0.5, 3.5  # floor half size, light half size, light height
    floor_pos = array.array("f", [-s, 0, s, s, 0, s, s, 0, -s, -s, 0, -s])
    light_pos = array.array("f", [-l, y, -l, l, y, -l, l, y, l, -l, y, l])
    up = array.array("f", [0, 1, 0] * 4)
    down = array.array("f", [0, -1, 0] * 4)
    quad = array.array("I", [0, 1, 2, 0, 2, 3])
    light_quad = array.array("I", [0, 1, 2, 0, 2, 3])  # faces -y (light's normal points down)

    blob = bytearray()
    views, accessors = [], []

    def add(data, target, count, kind, ctype, with_bounds=False):
        while len(blob) % 4:
            blob.append(0)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data) * data.itemsize,
                      "target": target})
        blob.extend(data.tobytes())
        acc = {"bufferView": len(views) - 1, "componentType": ctype, "count": count, "type": kind}
        if with_bounds:
            acc["min"], acc["max"] = bounds(data)
        accessors.append(acc)
        return len(accessors) - 1

    def mesh(p, n, i, material):
        return {"primitives": [{"attributes": {"POSITION": add(p, 34962, len(p) // 3, "VEC3", 5126, True),
                                               "NORMAL": add(n, 34962, len(n) // 3, "VEC3", 5126)},
                                "indices": add(i, 34963, len(i), "SCALAR", 5125),
                                "material": material, "mode": 4}]}

    def diffuse(name, rgb, emissive=None):
        m = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": list(rgb) + [1.0],
                                                    "metallicFactor": 0.0, "roughnessFactor": 1.0},
             "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}, "doubleSided": True}
        if emissive:
            m["emissiveFactor"] = [1.0, 1.0, 1.0]
            m["extensions"]["KHR_materials_emissive_strength"] = {"emissiveStrength": emissive}
        return m

    meshes = [mesh(pos, nrm, idx, 0), mesh(floor_pos, up, quad, 1), mesh(light_pos, down, light_quad, 2)]
    eye, target_pt = (0.0, 1.6, 3.6), (0.0, 0.9, 0.0)
    f = [target_pt[k] - eye[k] for k in range(3)]
    fl = math.sqrt(sum(c * c for c in f))
    f = [c / fl for c in f]
    # Rotation about +x that turns -z into f (f has no x component)
    angle = math.atan2(f[1], -f[2])
    rot = [math.sin(angle / 2.0), 0.0, 0.0, math.cos(angle / 2.0)]
    doc = {
        "asset": {"version": "2.0", "generator": "candela scripts/scenes/make_bench_mesh.py"},
        "extensionsUsed": ["KHR_materials_specular", "KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2, 3]}],
        "nodes": [{"name": "bumpy-sphere", "mesh": 0}, {"name": "floor", "mesh": 1},
                  {"name": "light", "mesh": 2},
                  {"name": "camera", "camera": 0, "translation": list(eye), "rotation": rot}],
        "meshes": meshes,
        "materials": [diffuse("sphere", (0.7, 0.6, 0.5)), diffuse("floor", (0.5, 0.5, 0.5)),
                      diffuse("light", (0.0, 0.0, 0.0), emissive=20.0)],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "aspectRatio": 1.0,
                                                            "znear": 0.01, "zfar": 100.0}}],
        "accessors": accessors,
        "bufferViews": views,
    }
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    bin_path = os.path.splitext(out)[0] + ".bin"
    with open(bin_path, "wb") as fbin:
        fbin.write(blob)
    doc["buffers"] = [{"byteLength": len(blob), "uri": os.path.basename(bin_path)}]
    with open(out, "w", encoding="utf-8", newline="\n") as fj:
        json.dump(doc, fj, indent=1)
    print("wrote %s: %d triangles" % (out, len(idx) // 3 + 4))


if __name__ == "__main__":
    main()
