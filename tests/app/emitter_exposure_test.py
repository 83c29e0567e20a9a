#!/usr/bin/python3
"""The automatic exposure of a scene lit by small bright emitters: a closed room (8 x 3 x 8 m,
white walls) lit inside by 3,840 small emissive triangles of emissive strength 20 along its
ceiling, under a sun of 6,800 lx outside it. The estimate of the scene's own light before the
render ignores occlusion, so it counts the sun on every wall: it flags the scene as lit far
brighter than the studio. The exposure applied is metered from the image: the PNG is no black
frame (mean of its 8-bit values at least 8 % of full scale), the note on stderr names the
exposure applied, the EXR stays linear (the same with and without the automatic exposure), and
--exposure overrides it.
Usage: emitter_exposure_test.py path/to/candela repo_root
"""
import math
import os
import struct
import subprocess
import sys
import tempfile

import numpy as np
import OpenImageIO as oiio
from candela_test_util import write_gltf



def room_scene(path):
    pos, idx = [], []

    def quad(a, b, c, d):  # counter-clockwise seen from the front
        base = len(pos)
        pos.extend([a, b, c, d])
        idx.extend([base, base + 1, base + 2, base, base + 2, base + 3])

    h, y = 4.0, 3.0
    quad((-h, 0, h), (h, 0, h), (h, 0, -h), (-h, 0, -h))  # floor, facing up
    quad((-h, y, -h), (h, y, -h), (h, y, h), (-h, y, h))  # ceiling, facing down
    quad((-h, 0, -h), (h, 0, -h), (h, y, -h), (-h, y, -h))  # back wall, facing +z
    quad((h, 0, h), (-h, 0, h), (-h, y, h), (h, y, h))  # front wall, facing -z
    quad((-h, 0, h), (-h, 0, -h), (-h, y, -h), (-h, y, h))  # left wall, facing +x
    quad((h, 0, -h), (h, 0, h), (h, y, h), (h, y, -h))  # right wall, facing -x
    room_count = len(idx)
    # 64 x 60 emitters: triangles of legs 1 cm, 1 cm under the ceiling, facing down
    for i in range(64):
        for j in range(60):
            x, z = -3.8 + 7.6 * (i + 0.5) / 64, -3.8 + 7.6 * (j + 0.5) / 60
            base = len(pos)
            pos.extend([(x, y - 0.01, z), (x + 0.01, y - 0.01, z), (x, y - 0.01, z + 0.01)])
            idx.extend([base, base + 1, base + 2])
    emitters = (len(idx) - room_count) // 3
    assert emitters == 3840
    pb = b"".join(struct.pack("<3f", *p) for p in pos)
    ib_room = b"".join(struct.pack("<I", i) for i in idx[:room_count])
    ib_em = b"".join(struct.pack("<I", i) for i in idx[room_count:])
    lo = [min(p[k] for p in pos) for k in range(3)]
    hi = [max(p[k] for p in pos) for k in range(3)]
    # The sun's direction (0.3, -0.9, 0.3) normalized: the rotation of -z onto it
    d = np.array([0.3, -0.9, 0.3])
    d /= np.linalg.norm(d)
    f = np.array([0.0, 0.0, -1.0])
    axis = np.cross(f, d)
    angle = math.acos(float(np.dot(f, d)))
    axis /= np.linalg.norm(axis)
    q = list(axis * math.sin(angle / 2)) + [math.cos(angle / 2)]
    doc = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "directional", "intensity": 6800.0}]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [
            {"mesh": 0},
            {"extensions": {"KHR_lights_punctual": {"light": 0}}, "rotation": q},
            {"camera": 0, "translation": [0.0, 1.5, 3.6]},
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.01, "aspectRatio": 1.0}}],
        "materials": [
            {"pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.7, 0.7, 1.0], "metallicFactor": 0.0,
                                      "roughnessFactor": 1.0}},
            {"pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0], "metallicFactor": 0.0},
             "emissiveFactor": [1.0, 1.0, 1.0],
             "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 20.0}}},
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0},
                                   {"attributes": {"POSITION": 0}, "indices": 2, "material": 1}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(pos), "type": "VEC3", "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5125, "count": room_count, "type": "SCALAR"},
            {"bufferView": 2, "componentType": 5125, "count": len(idx) - room_count, "type": "SCALAR"},
        ],
    }
    write_gltf(path, doc, [pb, ib_room, ib_em])


def pixels(path):
    return oiio.ImageBuf(path).get_pixels(oiio.FLOAT)


def main():
    binary = sys.argv[1]
    fails = 0
    with tempfile.TemporaryDirectory() as tmp:
        scene = os.path.join(tmp, "room.gltf")
        room_scene(scene)
        common = ["--width", "48", "--height", "48", "--spp", "8", "--device", "pocl", "-q"]
        auto = subprocess.run([binary, "render", scene, "-o", os.path.join(tmp, "auto.png"), "-o",
                               os.path.join(tmp, "auto.exr")] + common, capture_output=True, text=True)
        plain = subprocess.run([binary, "render", scene, "-o", os.path.join(tmp, "plain.png"), "-o",
                                os.path.join(tmp, "plain.exr"), "--exposure", "0"] + common,
                               capture_output=True, text=True)
        if auto.returncode != 0 or plain.returncode != 0:
            print("FAIL: the renders failed:\n" + auto.stderr + plain.stderr)
            return 1
        notes = [l for l in auto.stderr.splitlines() if l.startswith("note: exposing PNG/JPEG outputs at ")]
        png = pixels(os.path.join(tmp, "auto.png"))
        exr, exr0 = pixels(os.path.join(tmp, "auto.exr")), pixels(os.path.join(tmp, "plain.exr"))
        mean = float(png.mean())
        print("PNG mean %.3f of full scale; %s" % (mean, notes[0] if notes else "no exposure note"))

        def check(ok, what):
            nonlocal fails
            print(("ok: " if ok else "FAIL: ") + what)
            fails += not ok

        check(len(notes) == 1, "the automatic exposure is announced once")
        check(mean >= 0.08, "the PNG is no black frame (mean %.3f >= 0.08)" % mean)
        check(np.array_equal(exr, exr0), "the EXR stays linear: the same with --exposure 0")
        check("exposing" not in plain.stderr, "--exposure 0 announces no automatic exposure")
        if notes:
            # The exposure said is the one applied: the PNG at that --exposure is the same
            ev = notes[0].split(" stops")[0].split(" at ")[-1]
            said = subprocess.run([binary, "render", scene, "-o", os.path.join(tmp, "said.png"), "--exposure", ev] +
                                  common, capture_output=True, text=True)
            check(said.returncode == 0 and np.array_equal(pixels(os.path.join(tmp, "said.png")), png),
                  "the exposure said (%s stops) is the one applied" % ev)
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
