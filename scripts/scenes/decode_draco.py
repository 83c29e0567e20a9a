#!/usr/bin/python3
"""Writes a copy of a .gltf file whose Draco-compressed primitives (KHR_draco_mesh_compression) are plain
accessors, for tools that cannot decode Draco (Debian's Blender 3.4 lacks the decoder library its glTF importer
loads). Benchmark scripts use it; candela itself reads Draco.

  python3 scripts/scenes/decode_draco.py IN.gltf OUT.gltf

Each compressed primitive's bufferView goes through Debian's `draco_decoder` (package draco) to a binary PLY;
its positions and normals and its triangles become new accessors in OUT.bin, beside OUT.gltf. The input's own
buffers and images stay where they are (referred to by relative paths). Only triangle primitives with POSITION
and NORMAL are decoded; any other attribute (texture coordinates, which draco_decoder writes per face corner,
tangents, colours, joints, weights) or primitive mode is an error.
"""

import json
import os
import urllib.parse
import shutil
import struct
import subprocess
import sys
import tempfile

PLY_TYPES = {"char": "b", "uchar": "B", "short": "h", "ushort": "H", "int": "i", "uint": "I", "float": "f",
             "double": "d", "int8": "b", "uint8": "B", "int16": "h", "uint16": "H", "int32": "i", "uint32": "I",
             "float32": "f", "float64": "d"}
# PLY vertex properties -> glTF attribute and its width
PLY_ATTRIBUTES = {("x", "y", "z"): ("POSITION", 3), ("nx", "ny", "nz"): ("NORMAL", 3)}


def fail(msg):
    raise SystemExit("decode_draco: error: " + msg)


def read_ply(path):
    """(vertex property names, rows of vertex values, triangles) of a binary little-endian PLY."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    if "format binary_little_endian 1.0" not in header:
        fail("%s: not a binary little-endian PLY" % path)
    elements, current = [], None
    for line in header:
        words = line.split()
        if words[:1] == ["element"]:
            current = {"name": words[1], "count": int(words[2]), "props": []}
            elements.append(current)
        elif words[:1] == ["property"]:
            current["props"].append(words[1:])
    pos = end
    vertices, names, triangles = [], [], []
    for el in elements:
        if el["name"] == "vertex":
            names = [p[-1] for p in el["props"]]
            if any(p[0] == "list" for p in el["props"]):
                fail("%s: a list among the vertex properties" % path)
            fmt = "<" + "".join(PLY_TYPES[p[0]] for p in el["props"])
            size = struct.calcsize(fmt)
            for i in range(el["count"]):
                vertices.append(struct.unpack_from(fmt, data, pos))
                pos += size
        elif el["name"] == "face":
            if len(el["props"]) != 1 or el["props"][0][0] != "list" or el["props"][0][-1] != "vertex_indices":
                fail("%s: faces carry more than their vertex indices (per-corner texture coordinates?), which this "
                     "script does not decode" % path)
            (_, count_type, index_type, _), = el["props"]
            cf, xf = "<" + PLY_TYPES[count_type], PLY_TYPES[index_type]
            for i in range(el["count"]):
                (n,) = struct.unpack_from(cf, data, pos)
                pos += struct.calcsize(cf)
                idx = struct.unpack_from("<%d%s" % (n, xf), data, pos)
                pos += struct.calcsize("<%d%s" % (n, xf))
                triangles += [(idx[0], idx[k], idx[k + 1]) for k in range(1, n - 1)]  # a fan, as n-gons go
        else:
            fail("%s: unexpected element %s" % (path, el["name"]))
    return names, vertices, triangles


def main():
    if len(sys.argv) != 3:
        fail("usage: python3 scripts/scenes/decode_draco.py IN.gltf OUT.gltf")
    src, dst = sys.argv[1], sys.argv[2]
    if not src.endswith(".gltf"):
        fail("%s: only .gltf input (with external buffers) is supported" % src)
    if not shutil.which("draco_decoder"):
        fail("draco_decoder not found (Debian: apt-get install draco)")
    with open(src) as f:
        g = json.load(f)
    src_dir, dst_dir = os.path.dirname(os.path.abspath(src)), os.path.dirname(os.path.abspath(dst))
    for item in g.get("buffers", []) + g.get("images", []):
        uri = item.get("uri")
        if uri and not uri.startswith("data:"):
            item["uri"] = os.path.relpath(os.path.join(src_dir, uri), dst_dir)
    blobs = {}

    def view_bytes(index):
        if index not in blobs:
            bv = g["bufferViews"][index]
            uri = g["buffers"][bv["buffer"]].get("uri", "")
            if not uri or uri.startswith("data:"):
                fail("%s: a Draco buffer embedded in the file (data: URI) is not supported" % src)
            path = os.path.join(dst_dir, urllib.parse.unquote(uri))
            with open(path, "rb") as f:
                f.seek(bv.get("byteOffset", 0))
                blobs[index] = f.read(bv["byteLength"])
        return blobs[index]

    out = bytearray()
    new_buffer = len(g.setdefault("buffers", []))

    def add_accessor(fmt, values, gltf_type, component, target, with_bounds):
        while len(out) % 4:
            out.append(0)
        offset = len(out)
        for v in values:
            out.extend(struct.pack(fmt, *v) if isinstance(v, tuple) else struct.pack(fmt, v))
        g.setdefault("bufferViews", []).append({"buffer": new_buffer, "byteOffset": offset,
                                                "byteLength": len(out) - offset, "target": target})
        acc = {"bufferView": len(g["bufferViews"]) - 1, "componentType": component, "count": len(values),
               "type": gltf_type}
        if with_bounds:
            width = len(values[0])
            acc["min"] = [min(v[k] for v in values) for k in range(width)]
            acc["max"] = [max(v[k] for v in values) for k in range(width)]
        g.setdefault("accessors", []).append(acc)
        return len(g["accessors"]) - 1

    decoded = 0
    with tempfile.TemporaryDirectory(prefix="decode-draco-") as tmp:
        for mesh in g.get("meshes", []):
            for prim in mesh.get("primitives", []):
                ext = prim.get("extensions", {}).pop("KHR_draco_mesh_compression", None)
                if ext is None:
                    continue
                if not prim["extensions"]:
                    del prim["extensions"]
                if prim.get("mode", 4) != 4:
                    fail("%s: a Draco primitive of mode %d (only triangles, mode 4, are decoded)" % (src, prim["mode"]))
                drc, ply = os.path.join(tmp, "p.drc"), os.path.join(tmp, "p.ply")
                with open(drc, "wb") as f:
                    f.write(view_bytes(ext["bufferView"]))
                p = subprocess.run(["draco_decoder", "-i", drc, "-o", ply], stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, text=True)
                if p.returncode != 0:
                    fail("draco_decoder failed: " + p.stdout.strip()[-300:])
                names, vertices, triangles = read_ply(ply)
                wanted = set(ext["attributes"])
                attributes = {}
                for props, (name, width) in PLY_ATTRIBUTES.items():
                    if all(n in names for n in props) and name in wanted:
                        cols = [names.index(n) for n in props]
                        vals = [tuple(float(v[c]) for c in cols) for v in vertices]
                        attributes[name] = add_accessor("<%df" % width, vals, "VEC%d" % width, 5126, 34962,
                                                        name == "POSITION")
                missing = wanted - set(attributes)
                if missing:
                    fail("%s: attributes %s are not in draco_decoder's PLY" % (src, ", ".join(sorted(missing))))
                prim["attributes"] = dict(prim["attributes"], **attributes)
                index_fmt, component = ("<I", 5125) if len(vertices) > 65535 else ("<H", 5123)
                flat = [i for t in triangles for i in t]
                prim["indices"] = add_accessor(index_fmt, flat, "SCALAR", component, 34963, False)
                decoded += 1
    for key in ("extensionsUsed", "extensionsRequired"):
        if key in g:
            g[key] = [e for e in g[key] if e != "KHR_draco_mesh_compression"]
            if not g[key]:
                del g[key]
    bin_name = os.path.splitext(os.path.basename(dst))[0] + ".bin"
    with open(os.path.join(dst_dir, bin_name), "wb") as f:
        f.write(out)
    g["buffers"].append({"uri": bin_name, "byteLength": len(out)})
    with open(dst, "w") as f:
        json.dump(g, f)
    print("decode_draco: %s: %d primitives decoded" % (dst, decoded))


if __name__ == "__main__":
    main()
