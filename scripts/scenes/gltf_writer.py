"""A small glTF 2.0 writer: one binary buffer, accessors, meshes, materials,
cameras and nodes.

The buffer is embedded as a base64 data URI, or written beside the .gltf as a
.bin.  JSON members keep their insertion order, so output is deterministic.
Used by scripts/scenes/make_scenes.py.
"""

import base64
import json
import math
import os
import struct
import zlib

ARRAY_BUFFER = 34962
ELEMENT_ARRAY_BUFFER = 34963
FLOAT = 5126
UNSIGNED_INT = 5125
TRIANGLES = 4
DATA_URI_PREFIX = "data:application/octet-stream;base64,"


class GltfWriter:
    """Accumulates binary data and JSON objects for one glTF file."""

    def __init__(self, generator):
        self.blob = bytearray()
        self.doc = {
            "asset": {"version": "2.0", "generator": generator},
            "scene": 0,
            "scenes": [{"nodes": []}],
            "nodes": [],
            "meshes": [],
            "materials": [],
            "cameras": [],
            "accessors": [],
            "bufferViews": [],
            "buffers": [],
        }

    def _append(self, member, item):
        self.doc[member].append(item)
        return len(self.doc[member]) - 1

    def _view(self, data, target):
        while len(self.blob) % 4:
            self.blob.append(0)
        view = {"buffer": 0, "byteOffset": len(self.blob),
                "byteLength": len(data), "target": target}
        self.blob.extend(data)
        return self._append("bufferViews", view)

    def vec3_accessor(self, vectors, with_bounds):
        data = b"".join(struct.pack("<3f", *v) for v in vectors)
        acc = {"bufferView": self._view(data, ARRAY_BUFFER),
               "componentType": FLOAT, "count": len(vectors), "type": "VEC3"}
        if with_bounds:
            acc["min"] = [min(v[i] for v in vectors) for i in range(3)]
            acc["max"] = [max(v[i] for v in vectors) for i in range(3)]
        return self._append("accessors", acc)

    def _use(self, extension):
        used = self.doc.setdefault("extensionsUsed", [])
        if extension not in used:
            used.append(extension)

    def vec_accessor(self, vectors, n):
        """VEC2/VEC3/VEC4 float accessor without bounds."""
        data = b"".join(struct.pack("<%df" % n, *v) for v in vectors)
        return self._append("accessors", {
            "bufferView": self._view(data, ARRAY_BUFFER), "componentType": FLOAT,
            "count": len(vectors), "type": "VEC%d" % n})

    def index_accessor(self, indices):
        data = struct.pack("<%dI" % len(indices), *indices)
        return self._append("accessors", {
            "bufferView": self._view(data, ELEMENT_ARRAY_BUFFER),
            "componentType": UNSIGNED_INT, "count": len(indices),
            "type": "SCALAR"})

    def material(self, name, base_color, emissive=None, strength=None,
                 double_sided=True):
        """A Lambertian material (metallic 0, roughness 1, no specular layer:
        KHR_materials_specular's specularFactor 0), maybe emissive."""
        mat = {"name": name,
               "pbrMetallicRoughness": {"baseColorFactor": list(base_color),
                                        "metallicFactor": 0.0,
                                        "roughnessFactor": 1.0},
               "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}}
        self._use("KHR_materials_specular")
        if emissive is not None:
            mat["emissiveFactor"] = list(emissive)
        if strength is not None:
            mat["extensions"]["KHR_materials_emissive_strength"] = {"emissiveStrength": strength}
            self._use("KHR_materials_emissive_strength")
        mat["doubleSided"] = double_sided
        return self._append("materials", mat)

    def pbr_material(self, name, pbr, extensions=None, **fields):
        """A material from its pbrMetallicRoughness dict, KHR extensions (marked
        as used) and other glTF material members (doubleSided, normalTexture, ...)."""
        mat = {"name": name, "pbrMetallicRoughness": pbr}
        if extensions:
            mat["extensions"] = extensions
            for ext in extensions:
                self._use(ext)
        mat.update(fields)
        return self._append("materials", mat)

    def png_texture(self, width, height, rgba, srgb_hint="", nearest=False):
        """A texture of an RGBA8 image (bytes, rows top to bottom) embedded as PNG."""
        raw = b"".join(b"\x00" + bytes(rgba[4 * width * y:4 * width * (y + 1)])
                       for y in range(height))

        def chunk(tag, data):
            body = tag + data
            return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))
        png = (b"\x89PNG\r\n\x1a\n" +
               chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)) +
               chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))
        image = self._append_member("images", {
            "uri": "data:image/png;base64," + base64.b64encode(png).decode("ascii")})
        sampler = {"magFilter": 9728 if nearest else 9729, "minFilter": 9729}
        return self._append_member("textures", {
            "source": image, "sampler": self._append_member("samplers", sampler)})

    def _append_member(self, member, item):
        self.doc.setdefault(member, [])
        return self._append(member, item)

    def mesh_from_accessors(self, name, attributes, indices, material):
        """A one-primitive mesh over existing accessors (meshes may share them)."""
        prim = {"attributes": dict(attributes), "indices": indices,
                "material": material, "mode": TRIANGLES}
        return self._append("meshes", {"name": name, "primitives": [prim]})

    def mesh(self, name, positions, normals, indices, material):
        """Add a one-primitive triangle mesh; normals may be None."""
        attributes = {"POSITION": self.vec3_accessor(positions, True)}
        if normals is not None:
            attributes["NORMAL"] = self.vec3_accessor(normals, False)
        prim = {"attributes": attributes,
                "indices": self.index_accessor(indices),
                "material": material,
                "mode": TRIANGLES}
        return self._append("meshes", {"name": name, "primitives": [prim]})

    def camera(self, name, yfov, aspect, znear=0.01, zfar=100.0):
        return self._append("cameras", {
            "name": name, "type": "perspective",
            "perspective": {"yfov": yfov, "aspectRatio": aspect,
                            "znear": znear, "zfar": zfar}})

    def node(self, name, root=True, **fields):
        """Add a node (fields: mesh, camera, children, translation, ...)."""
        node = {"name": name}
        node.update(fields)
        index = self._append("nodes", node)
        if root:
            self.doc["scenes"][0]["nodes"].append(index)
        return index

    def punctual_light(self, name, light_type, color=(1.0, 1.0, 1.0),
                       intensity=1.0, light_range=None, inner_cone=0.0,
                       outer_cone=math.pi / 4.0):
        """A KHR_lights_punctual light ("point", "spot" or "directional"),
        placed by light_node; returns its index.  Intensity is in candela for
        point and spot lights and in lux for directional ones."""
        self._use("KHR_lights_punctual")
        light = {"name": name, "type": light_type, "color": list(color),
                 "intensity": intensity}
        if light_range is not None:
            light["range"] = light_range
        if light_type == "spot":
            light["spot"] = {"innerConeAngle": inner_cone,
                             "outerConeAngle": outer_cone}
        ext = self.doc.setdefault("extensions", {})
        lights = ext.setdefault("KHR_lights_punctual", {}).setdefault("lights", [])
        lights.append(light)
        return len(lights) - 1

    def light_node(self, name, light, **fields):
        """A node carrying punctual light `light`: it sits at the node's
        origin and points down the node's -Z axis."""
        return self.node(name, extensions={"KHR_lights_punctual": {"light": light}},
                         **fields)

    def set_background(self, rgb):
        """candela's scene background radiance (scene extras)."""
        extras = self.doc["scenes"][0].setdefault("extras", {})
        extras.setdefault("candela", {})["background"] = list(rgb)

    def write(self, path, embed=True):
        """Write the .gltf; embed=False puts the buffer in a .bin beside it."""
        os.makedirs(os.path.dirname(path), exist_ok=True)
        if embed:
            uri = DATA_URI_PREFIX + base64.b64encode(self.blob).decode("ascii")
        else:
            bin_path = os.path.splitext(path)[0] + ".bin"
            with open(bin_path, "wb") as f:
                f.write(self.blob)
            uri = os.path.basename(bin_path)
        self.doc["buffers"] = [{"byteLength": len(self.blob), "uri": uri}]
        with open(path, "w", encoding="utf-8", newline="\n") as f:
            f.write(json.dumps(self.doc, indent=2))
            f.write("\n")
