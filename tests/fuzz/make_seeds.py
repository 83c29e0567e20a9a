#!/usr/bin/env python3
"""Writes small glTF and GLB seed files for the fuzzer (tests/fuzz/gltf_fuzz.cpp).

They mirror the scenes the loader tests build (tests/gltf_loader_test.cpp,
tests/test_support.cpp) and reach every feature the loader reads: data: URI buffers,
GLB BIN chunks, interleaved and strided views, sparse and zero-filled accessors, all
index types, strips and fans, normals, tangents, two UV sets, vertex colours, 8- and
16-bit PNG and JPEG textures (from a URI and from a bufferView), samplers,
KHR_texture_transform, emissive strength, cameras, node trees, scene extras, and the
features the loader only warns about.

Usage: make_seeds.py OUT_DIR
"""
import base64
import copy
import json
import os
import struct
import sys
import zlib


def png(width, height, pixels, bits=8, channels=3):
    """A PNG of `pixels` (row-major tuples of `channels` ints)."""
    color_type = {1: 0, 2: 4, 3: 2, 4: 6}[channels]
    fmt = ">" + ("B" if bits == 8 else "H") * channels
    raw = b""
    for y in range(height):
        raw += b"\x00" + b"".join(struct.pack(fmt, *pixels[y * width + x]) for x in range(width))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    ihdr = struct.pack(">IIBBBBB", width, height, bits, color_type, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


def jpeg_gray8x8():
    """A baseline JPEG of one 8x8 grey block: one-symbol Huffman tables, DC 0 then EOB."""
    def seg(marker, data):
        return bytes([0xFF, marker]) + struct.pack(">H", len(data) + 2) + data
    dqt = seg(0xDB, bytes([0]) + bytes([1] * 64))
    sof = seg(0xC0, struct.pack(">BHHB", 8, 8, 8, 1) + bytes([1, 0x11, 0]))
    dht = seg(0xC4, bytes([0x00, 1] + [0] * 15 + [0x00]) + bytes([0x10, 1] + [0] * 15 + [0x00]))
    sos = seg(0xDA, bytes([1, 1, 0x00, 0, 63, 0]))
    return b"\xff\xd8" + dqt + sof + dht + sos + bytes([0x3F]) + b"\xff\xd9"


def data_uri(data, mime="application/octet-stream"):
    return "data:%s;base64,%s" % (mime, base64.b64encode(data).decode())


def floats(values):
    return struct.pack("<%df" % len(values), *values)


class Builder:
    """One buffer of views and accessors, appended to as the scene grows."""

    def __init__(self):
        self.bin = b""
        self.views = []
        self.accessors = []

    def view(self, data, stride=None):
        while len(self.bin) % 4:
            self.bin += b"\x00"
        v = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if stride:
            v["byteStride"] = stride
        self.bin += data
        self.views.append(v)
        return len(self.views) - 1

    def accessor(self, data, ctype, count, kind, **extra):
        a = {"bufferView": self.view(data), "componentType": ctype, "count": count, "type": kind}
        a.update(extra)
        self.accessors.append(a)
        return len(self.accessors) - 1

    def gltf(self, **members):
        j = {"asset": {"version": "2.0"},
             "buffers": [{"byteLength": len(self.bin), "uri": data_uri(self.bin)}],
             "bufferViews": self.views, "accessors": self.accessors}
        j.update(members)
        return j


QUAD_POS = [-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0]
QUAD_UV = [0, 1, 1, 1, 1, 0, 0, 0]


def quad(indices=(0, 1, 2, 0, 2, 3), index_type=5123, mode=None, material=None, **attrs):
    """The tests' quad: POSITION, TEXCOORD_0 and indices, plus extra attributes."""
    b = Builder()
    prim = {"attributes": {
        "POSITION": b.accessor(floats(QUAD_POS), 5126, 4, "VEC3", min=[-1, -1, 0], max=[1, 1, 0]),
        "TEXCOORD_0": b.accessor(floats(QUAD_UV), 5126, 4, "VEC2")}}
    fmt = {5121: "B", 5123: "H", 5125: "I"}[index_type]
    prim["indices"] = b.accessor(struct.pack("<%d%s" % (len(indices), fmt), *indices), index_type,
                                 len(indices), "SCALAR")
    for name, (data, ctype, kind, extra) in attrs.items():
        prim["attributes"][name] = b.accessor(data, ctype, 4, kind, **extra)
    if mode is not None:
        prim["mode"] = mode
    prim["material"] = 0 if material is None else material
    return b, prim


def material(**m):
    out = {"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0}}
    out.update(m)
    return out


def scene_of(b, prims, materials, nodes=None, **members):
    nodes = nodes or [{"mesh": 0}]
    return b.gltf(meshes=[{"primitives": prims}], materials=materials, nodes=nodes,
                  scenes=[{"nodes": list(range(len(nodes)))}], scene=0, **members)


def glb(j, bin_chunk):
    """GLB of JSON `j` whose buffer 0 is `bin_chunk`."""
    j = copy.deepcopy(j)
    j["buffers"][0] = {"byteLength": len(bin_chunk)}
    text = json.dumps(j, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    bin_chunk += b"\x00" * (-len(bin_chunk) % 4)
    body = struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(bin_chunk), b"BIN\x00") + bin_chunk
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def seeds():
    out = {}
    camera = {"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.01}}
    white = {"candela": {"background": [1, 1, 1]}}

    b, p = quad()
    out["quad.gltf"] = scene_of(b, [p], [material()])
    out["quad.glb"] = glb(out["quad.gltf"], b.bin)

    b, p = quad()
    out["mirror.gltf"] = scene_of(b, [p], [material()], nodes=[{"mesh": 0, "scale": [-1, 1, 1]}])

    b, p = quad(indices=(0, 1, 3, 2), mode=5)
    out["strip.gltf"] = scene_of(b, [p], [material()], nodes=[
        {"mesh": 0, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 5, 6, 7, 1]}])

    b, p = quad(indices=(0, 1, 2, 3), index_type=5121, mode=6)
    out["fan.gltf"] = scene_of(b, [p], [material(doubleSided=True)])

    colors = bytes([255, 0, 0, 255, 0, 0, 255, 255, 0, 0, 255, 255, 255, 0, 0, 255])
    b, p = quad(index_type=5125, COLOR_0=(colors, 5121, "VEC4", {"normalized": True}))
    out["colors.gltf"] = scene_of(b, [p], [material()], nodes=[{"mesh": 0}, {"camera": 0, "translation": [0, 0, 3]}],
                                  cameras=[camera])
    out["colors.gltf"]["scenes"][0]["extras"] = white

    # Normals, tangents, TEXCOORD_1 and float RGB colours
    b, p = quad(NORMAL=(floats([0, 0, 1] * 4), 5126, "VEC3", {}),
                TANGENT=(floats([1, 0, 0, -1] * 4), 5126, "VEC4", {}),
                TEXCOORD_1=(struct.pack("<8H", 0, 65535, 65535, 65535, 65535, 0, 0, 0), 5123, "VEC2",
                            {"normalized": True}),
                COLOR_0=(floats([0.2, 0.4, 0.6] * 4), 5126, "VEC3", {}))
    out["attributes.gltf"] = scene_of(b, [p], [material()])

    # Textures: an 8-bit sRGB PNG (data URI) with KHR_texture_transform and a 16-bit
    # emissive PNG, clamped and mirrored samplers, emissive strength
    tex8 = png(2, 1, [(188, 60, 20), (20, 60, 100)])
    tex16 = png(2, 2, [(65535, 0, 0, 65535), (0, 65535, 0, 32768), (0, 0, 65535, 0), (1000, 2000, 3000, 65535)],
                bits=16, channels=4)
    b, p = quad()
    m = material(doubleSided=True, emissiveFactor=[1, 1, 1],
                 emissiveTexture={"index": 1, "texCoord": 0},
                 extensions={"KHR_materials_emissive_strength": {"emissiveStrength": 4}})
    m["pbrMetallicRoughness"]["baseColorTexture"] = {
        "index": 0, "extensions": {"KHR_texture_transform": {"offset": [0.5, 0], "scale": [2, 2], "rotation": 1.57}}}
    out["textured.gltf"] = scene_of(
        b, [p], [m], nodes=[{"mesh": 0}, {"camera": 0, "translation": [0, 0, 3]}], cameras=[camera],
        images=[{"uri": data_uri(tex8, "image/png")}, {"uri": data_uri(tex16, "image/png")},
                {"uri": data_uri(jpeg_gray8x8(), "image/jpeg")}],
        samplers=[{"wrapS": 33071, "wrapT": 33648, "magFilter": 9728}],
        textures=[{"source": 0, "sampler": 0}, {"source": 1}, {"source": 2}],
        extensionsUsed=["KHR_texture_transform", "KHR_materials_emissive_strength"])
    out["textured.gltf"]["scenes"][0]["extras"] = white
    jpeg_material = material()
    jpeg_material["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 2, "texCoord": 0}
    out["textured.gltf"]["materials"].append(jpeg_material)
    out["textured.gltf"]["meshes"][0]["primitives"].append(dict(p, material=1))

    # Image from a bufferView inside a GLB
    b, p = quad()
    image_view = b.view(tex8)
    m = material()
    m["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    j = scene_of(b, [p], [m], images=[{"bufferView": image_view, "mimeType": "image/png"}],
                 textures=[{"source": 0}])
    out["image-view.glb"] = glb(j, b.bin)

    # Interleaved POSITION/TEXCOORD_0 with a byteStride, no indices, emissive quad
    b = Builder()
    inter = b"".join(floats(QUAD_POS[3 * i:3 * i + 3] + QUAD_UV[2 * i:2 * i + 2]) for i in (0, 1, 2, 0, 2, 3))
    view = b.view(inter, stride=20)
    b.accessors = [{"bufferView": view, "componentType": 5126, "count": 6, "type": "VEC3"},
                   {"bufferView": view, "byteOffset": 12, "componentType": 5126, "count": 6, "type": "VEC2"}]
    out["interleaved.gltf"] = scene_of(b, [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}}],
                                       [material(emissiveFactor=[17, 12, 4])])

    # Sparse accessors: zero-filled positions with three substituted, and sparse values
    # over a bufferView
    b = Builder()
    idx = b.view(struct.pack("<3H", 0, 1, 2))
    vals = b.view(floats([0, 0, 0, 1, 0, 0, 0, 1, 0]))
    b.accessors.append({"componentType": 5126, "count": 4, "type": "VEC3",
                        "sparse": {"count": 3, "indices": {"bufferView": idx, "componentType": 5123},
                                   "values": {"bufferView": vals}}})
    base = b.accessor(floats(QUAD_POS), 5126, 4, "VEC3")
    b.accessors[base]["sparse"] = {"count": 1, "indices": {"bufferView": b.view(bytes([3])), "componentType": 5121},
                                   "values": {"bufferView": b.view(floats([-1, 1, 0.5]))}}
    out["sparse.gltf"] = scene_of(b, [{"attributes": {"POSITION": 0}, "mode": 4},
                                      {"attributes": {"POSITION": base}, "mode": 6}], [material()])

    # Node tree with TRS, no scenes at all (every root renders), two meshes
    b, p = quad()
    j = scene_of(b, [p], [material()])
    del j["scenes"], j["scene"]
    j["meshes"].append({"primitives": [dict(p, material=1)]})
    j["materials"].append(material(emissiveFactor=[1, 1, 1]))
    j["nodes"] = [{"children": [1, 2], "translation": [-0.35, 0, 0]},
                  {"mesh": 0, "rotation": [0, 0.7071068, 0, 0.7071068], "scale": [0.5, 0.5, 0.5]},
                  {"mesh": 1, "translation": [0, 2, 0], "children": [3]},
                  {"camera": 0, "translation": [0, 0, 5]}]
    j["cameras"] = [camera, {"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0, "zfar": 1}}]
    out["nodes.gltf"] = j

    # Features the loader only warns about
    b, p = quad()
    p["targets"] = [{"POSITION": 0}]
    points = {"attributes": {"POSITION": 0}, "mode": 0}
    draco = dict(p, extensions={"KHR_draco_mesh_compression": {"bufferView": 0, "attributes": {"POSITION": 0}}})
    m = material(alphaMode="BLEND", normalTexture={"index": 0}, occlusionTexture={"index": 0},
                 extensions={"KHR_materials_clearcoat": {"clearcoatFactor": 1}})
    m["pbrMetallicRoughness"].update(metallicFactor=1, metallicRoughnessTexture={"index": 0})
    out["unsupported.gltf"] = scene_of(
        b, [p, points, draco], [m, material()],
        nodes=[{"mesh": 0, "weights": [0.5], "extensions": {"KHR_lights_punctual": {"light": 0}}},
               {"translation": [0, 0, 2]}],
        extensionsUsed=["KHR_materials_clearcoat", "KHR_lights_punctual", "KHR_draco_mesh_compression"],
        extensionsRequired=["KHR_draco_mesh_compression"],
        extensions={"KHR_lights_punctual": {"lights": [{"type": "point"}]}},
        images=[{"uri": "missing-is-not-read.png"}], textures=[{"source": 0}],
        skins=[{"joints": [1]}],
        animations=[{"channels": [{"sampler": 0, "target": {"node": 1, "path": "translation"}}],
                     "samplers": [{"input": 1, "output": 0}]}])
    return out


def main():
    out_dir = sys.argv[1]
    os.makedirs(out_dir, exist_ok=True)
    for name, content in seeds().items():
        data = content if isinstance(content, bytes) else json.dumps(content, separators=(",", ":")).encode()
        with open(os.path.join(out_dir, name), "wb") as f:
            f.write(data)


if __name__ == "__main__":
    main()
