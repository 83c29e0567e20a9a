"""Mitsuba 3 for the comparisons: a candela glTF scene as a Mitsuba scene dictionary (scene_dict), the import
of Mitsuba with a variant (import_mitsuba) and a loaded scene that renders and times (Mitsuba); used by
scripts/compare/vs_mitsuba.py.

    from candela_tools import mitsuba
    scene_dict, notes = mitsuba.scene_dict(mi, "scenes/lights/near-specular.gltf", width, height, max_depth,
                                           tmpdir)
    scene = mi.load_dict(scene_dict)

The glTF JSON and its buffers (data URIs or files beside the .gltf; no sparse accessors) are read here with
numpy; Mitsuba's own glTF support is not used. What is converted, and how:

- Geometry: every triangle primitive (mode 4) of every mesh node of the default scene, with its node's world
  transform baked into the vertices, is written as a binary PLY file into TMPDIR (positions, NORMAL transformed
  by the inverse transpose; without NORMAL, flat face normals). A mirroring transform (negative determinant)
  reverses the winding, as glTF requires. Other primitive modes are skipped (a note says so).
- Camera: the first camera node in scene order becomes a `perspective` sensor: yfov (radians) as `fov` with
  `fov_axis` y, the node's position, its -Z as the view direction and +Y as up (Mitsuba's camera looks along its
  local +Z with +X to the left, so `look_at` is used rather than the node matrix), znear/zfar as the clip planes.
  The film is `hdrfilm` WIDTH x HEIGHT, RGB float32, with a `box` reconstruction filter of one pixel (candela's
  default --filter box), and the sampler plugin SAMPLER (default `independent`). Orthographic cameras and thin
  lenses are not converted (an error).
- Emission: emissiveFactor x KHR_materials_emissive_strength becomes an `area` emitter of that RGB radiance on the
  primitive's shape. Mitsuba's area emitter emits from the front face only, like a glTF material that is not
  doubleSided; a doubleSided emissive material (candela: both faces emit) is approximated by its front face (a
  note says so). emissiveTexture is ignored (a note).
- Materials (glTF metallic-roughness with KHR_materials_*). baseColorTexture becomes a `bitmap` (TEXCOORD_0 as
  the PLY's u, v, glTF's orientation as is; the image decoded from sRGB and multiplied by baseColorFactor into a
  linear EXR; the sampler's magFilter as nearest or bilinear, wrapS as the wrap mode) on the diffuse and
  principled BSDFs below; every other texture, KHR_texture_transform and the alpha modes are ignored with a note,
  their factors used:
  * metallic 0, transmission 0, KHR_materials_specular specularFactor 0, no clearcoat or sheen: `diffuse` of
    reflectance base colour, wrapped in `twosided` (exact: the glTF model is then Lambert, as in candela).
  * transmission 1, metallic 0: with a KHR_materials_volume thickness > 0 (a refracting solid) `roughdielectric`
    (GGX, alpha = roughness^2, int_ior = KHR_materials_ior ior (1.5), ext_ior 1, specular_transmittance = base
    colour), or `dielectric` below candela's delta threshold (alpha < 1e-3); attenuationColor/Distance are
    ignored (a note). Thin-walled (no volume, or thickness 0): `thindielectric` (int_ior ior, transmittance base
    colour), whose reflectance 2R/(1 + R) is candela's thin sheet's; APPROXIMATED: Mitsuba's thin dielectric is
    smooth, so a rough thin sheet (candela: a GGX straight-through lobe) is rendered as a smooth one.
  * materials[i].extras.candela.conductor (candela's measured conductors): `roughconductor` (GGX, alpha =
    roughness^2; `conductor` below alpha 1e-3), twosided, with candela's RGB complex index: the given {"eta",
    "k"}, or a preset's as host/gltf/materials.cpp defines it (read from there). Exact up to Mitsuba's missing
    energy compensation.
  * everything else: `principled` (base_color, metallic, roughness; eta = ior; spec_trans = transmission when it
    is between 0 and 1), wrapped in `twosided` when it does not transmit. Exact for metal (metallic 1: Schlick
    with F0 = base colour, GGX with alpha = roughness^2, as glTF); APPROXIMATED for dielectrics: Mitsuba's
    principled uses the exact dielectric Fresnel term and Disney's diffuse (retro-reflection), where glTF has a
    Schlick layer over Lambert; KHR_materials_specular's factor and colour, clearcoat, sheen, anisotropy and
    iridescence are not mapped (a note names them).
  * Not modelled in Mitsuba at all: candela's multiple-scattering energy compensation of GGX lobes (Kulla & Conty
    2017). It brightens rough metal and glass slightly (a few per cent at roughness 0.3, under 1 % at 0.1), so
    the image ratio candela/Mitsuba is a little above 1 on rough lobes.
- Background (scenes[i].extras.candela): `background` [r, g, b] becomes a `constant` emitter (none when black);
  `environment` {file, strength, rotation} an `envmap` of that file scaled by strength. Rotation convention:
  candela maps direction d to u = atan2(-x, z)/2pi, Mitsuba's envmap to u = atan2(x, -z)/2pi (both: +Y up, v =
  theta/pi from +Y), half a turn apart, and candela's rotation r turns the map counter-clockwise about +Y seen
  from above, so to_world = rotate(+Y, r + 180 degrees). Mitsuba filters the map bilinearly, candela takes the
  nearest texel.
- Integrator: `path` with max_depth = candela's --max-depth + 1 (candela counts scattering events: 0 shows the
  emitters seen directly, 1 adds direct light; Mitsuba counts path vertices: 1 shows emitters, 2 direct light)
  and rr_depth 3 (candela starts Russian roulette at the third scattering event; Mitsuba tests depth >= rr_depth
  after counting the vertex). Both survive with probability max-channel throughput x eta^2, but Mitsuba caps it
  at 0.95 where candela lets a path at or above 1 always survive: a variance difference, no bias. Mitsuba's path
  tracer weights light sampling and BSDF sampling by MIS (power heuristic) at every non-delta vertex and picks
  one emitter uniformly; candela's `auto` takes each light from one of the two per vertex and picks lights by
  power.
"""

import base64
import sys
import time
import json
import math
import os
import re

import numpy as np

from candela_tools import ROOT, UserError

COMPONENT = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
COUNT = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
CONDUCTOR_SOURCE = os.path.join(ROOT, "host", "gltf", "materials.cpp")
DELTA_ALPHA = 1e-3  # candela: a lobe with alpha below this is a mirror or a window (docs/materials.md)


def load_gltf(path):
    with open(path) as f:
        doc = json.load(f)
    base = os.path.dirname(os.path.abspath(path))
    buffers = []
    for b in doc.get("buffers", []):
        uri = b.get("uri")
        if uri is None:
            raise ValueError("%s: a buffer without a uri (GLB) is not supported" % path)
        if uri.startswith("data:"):
            buffers.append(base64.b64decode(uri.split(",", 1)[1]))
        else:
            with open(os.path.join(base, uri), "rb") as f:
                buffers.append(f.read())
    return doc, buffers, base


def accessor(doc, buffers, index):
    acc = doc["accessors"][index]
    if "sparse" in acc:
        raise ValueError("sparse accessors are not supported")
    dtype = np.dtype(COMPONENT[acc["componentType"]])
    n = COUNT[acc["type"]]
    count = acc["count"]
    view = doc["bufferViews"][acc["bufferView"]]
    data = buffers[view["buffer"]]
    start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    stride = view.get("byteStride", dtype.itemsize * n)
    rows = np.ndarray((count, n), dtype=dtype, buffer=data, offset=start, strides=(stride, dtype.itemsize))
    out = np.array(rows, dtype=np.float64 if dtype == np.float32 else dtype)
    if acc.get("normalized") and dtype != np.float32:
        out = np.maximum(out / float(np.iinfo(dtype).max), -1.0)
    return out


def node_matrix(node):
    if "matrix" in node:
        return np.array(node["matrix"], dtype=np.float64).reshape(4, 4).T  # glTF stores column-major
    t = node.get("translation", [0, 0, 0])
    x, y, z, w = node.get("rotation", [0, 0, 0, 1])
    s = node.get("scale", [1, 1, 1])
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    m = np.eye(4)
    m[:3, :3] = r * np.array(s)[None, :]
    m[:3, 3] = t
    return m


def walk(doc, scene_index):
    """(node index, world matrix) of every node under the scene, depth first in scene order"""
    out = []

    def visit(i, parent):
        m = parent @ node_matrix(doc["nodes"][i])
        out.append((i, m))
        for c in doc["nodes"][i].get("children", []):
            visit(c, m)

    for i in doc["scenes"][scene_index].get("nodes", []):
        visit(i, np.eye(4))
    return out


def write_ply(path, positions, normals, faces, uvs=None):
    with open(path, "wb") as f:
        header = ["ply", "format binary_little_endian 1.0", "element vertex %d" % len(positions),
                  "property float x", "property float y", "property float z"]
        if normals is not None:
            header += ["property float nx", "property float ny", "property float nz"]
        if uvs is not None:
            header += ["property float u", "property float v"]
        header += ["element face %d" % len(faces), "property list uchar int vertex_indices", "end_header"]
        f.write(("\n".join(header) + "\n").encode("ascii"))
        verts = np.hstack([a for a in (positions, normals, uvs) if a is not None])
        f.write(np.ascontiguousarray(verts, dtype="<f4").tobytes())
        rec = np.zeros(len(faces), dtype=[("n", "u1"), ("i", "<i4", (3,))])
        rec["n"] = 3
        rec["i"] = faces
        f.write(rec.tobytes())


def rgb(value):
    return {"type": "rgb", "value": [float(v) for v in value[:3]]}


def conductor_presets():
    """candela's named conductors, {name: {"eta": rgb, "k": rgb}}, read from the one table that defines them
    (kConductors in host/gltf/materials.cpp), so that the two cannot drift apart"""
    with open(CONDUCTOR_SOURCE) as f:
        text = f.read()
    number = r"\s*([-+0-9.eE]+)f?\s*"
    vec = r"\{" + ",".join([number] * 3) + r"\}"
    out = {}
    for m in re.finditer(r'\{"(\w+)",\s*' + vec + r",\s*" + vec + r"\}", text):
        out[m.group(1)] = {"eta": [float(v) for v in m.group(2, 3, 4)], "k": [float(v) for v in m.group(5, 6, 7)]}
    return out


def base_color_texture(ctx, info, factor, notes, name):
    """A Mitsuba `bitmap` of glTF texture INFO's image, decoded from sRGB and multiplied by FACTOR (written as a
    linear EXR into the temp folder, read raw), with the glTF sampler's filter and wrap mode"""
    import OpenImageIO as oiio
    doc, buffers, base, tmpdir = ctx
    tex = doc["textures"][info["index"]]
    image = doc["images"][tex["source"]]
    if info.get("texCoord", 0) != 0 or "KHR_texture_transform" in info.get("extensions", {}):
        notes.append("material %s: baseColorTexture's texCoord/KHR_texture_transform not mapped (TEXCOORD_0)" % name)
    if "bufferView" in image:
        view = doc["bufferViews"][image["bufferView"]]
        start = view.get("byteOffset", 0)
        data = buffers[view["buffer"]][start:start + view["byteLength"]]
    elif image["uri"].startswith("data:"):
        data = base64.b64decode(image["uri"].split(",", 1)[1])
    else:
        with open(os.path.join(base, image["uri"]), "rb") as f:
            data = f.read()
    src = os.path.join(tmpdir, "image-%d.%s" % (tex["source"], "jpg" if data[:2] == b"\xff\xd8" else "png"))
    with open(src, "wb") as f:
        f.write(data)
    inp = oiio.ImageInput.open(src)
    if inp is None:
        raise ValueError("cannot read the image of material %s: %s" % (name, oiio.geterror()))
    spec = inp.spec()
    px = np.asarray(inp.read_image(0, 0, 0, spec.nchannels, oiio.FLOAT), dtype=np.float64)
    inp.close()
    px = px.reshape(spec.height, spec.width, spec.nchannels)
    rgb3 = px[:, :, :3] if spec.nchannels >= 3 else np.repeat(px[:, :, :1], 3, axis=2)
    linear = np.where(rgb3 <= 0.04045, rgb3 / 12.92, ((rgb3 + 0.055) / 1.055) ** 2.4)  # sRGB EOTF
    linear = linear * np.array(factor[:3])[None, None, :]
    exr = os.path.join(tmpdir, "texture-%d-%d.exr" % (info["index"], len(os.listdir(tmpdir))))
    out = oiio.ImageOutput.create(exr)
    out.open(exr, oiio.ImageSpec(spec.width, spec.height, 3, oiio.FLOAT))
    out.write_image(np.ascontiguousarray(linear, dtype=np.float32))
    out.close()
    sampler = doc.get("samplers", [{}])[tex["sampler"]] if "sampler" in tex else {}
    wrap = {10497: "repeat", 33071: "clamp", 33648: "mirror"}
    wraps = {wrap.get(sampler.get("wrapS", 10497)), wrap.get(sampler.get("wrapT", 10497))}
    if len(wraps) > 1:
        notes.append("material %s: different wrapS and wrapT: both take wrapS" % name)
    return {"type": "bitmap", "filename": exr, "raw": True,
            "filter_type": "nearest" if sampler.get("magFilter") == 9728 else "bilinear",
            "wrap_mode": wrap.get(sampler.get("wrapS", 10497), "repeat")}


def material_bsdf(mat, notes, ctx=None):
    """(BSDF dict, emitted RGB radiance or None, emits from both faces) of a glTF material"""
    name = mat.get("name", "?")
    pbr = mat.get("pbrMetallicRoughness", {})
    ext = mat.get("extensions", {})
    base = pbr.get("baseColorFactor", [1, 1, 1, 1])[:3]
    metallic = float(pbr.get("metallicFactor", 1.0))
    roughness = float(pbr.get("roughnessFactor", 1.0))
    transmission = float(ext.get("KHR_materials_transmission", {}).get("transmissionFactor", 0.0))
    ior = float(ext.get("KHR_materials_ior", {}).get("ior", 1.5))
    volume = ext.get("KHR_materials_volume")
    thick = volume is not None and float(volume.get("thicknessFactor", 0.0)) > 0
    specular = float(ext.get("KHR_materials_specular", {}).get("specularFactor", 1.0))
    clearcoat = float(ext.get("KHR_materials_clearcoat", {}).get("clearcoatFactor", 0.0))
    sheen = max(ext.get("KHR_materials_sheen", {}).get("sheenColorFactor", [0, 0, 0]))
    base_tex = None
    if "baseColorTexture" in pbr and ctx is not None:
        base_tex = base_color_texture(ctx, pbr["baseColorTexture"], pbr.get("baseColorFactor", [1, 1, 1, 1]), notes,
                                      name)
    textured = [k for k in ("metallicRoughnessTexture",) if k in pbr]
    textured += ["baseColorTexture"] if "baseColorTexture" in pbr and base_tex is None else []
    textured += [k for k in ("normalTexture", "emissiveTexture", "occlusionTexture") if k in mat]
    if textured:
        notes.append("material %s: %s ignored (factors only)" % (name, ", ".join(textured)))
    alpha = roughness * roughness

    conductor = mat.get("extras", {}).get("candela", {}).get("conductor")
    if mat.get("alphaMode", "OPAQUE") != "OPAQUE":
        notes.append("material %s: alphaMode %s ignored (opaque)" % (name, mat["alphaMode"]))
    if conductor is not None:
        bsdf = {"type": "conductor"}
        if isinstance(conductor, str):
            presets = conductor_presets()
            if conductor not in presets:
                raise ValueError("material %s: conductor preset %s is not in %s" % (name, conductor, CONDUCTOR_SOURCE))
            conductor = presets[conductor]
        bsdf.update({"eta": rgb(conductor["eta"]), "k": rgb(conductor["k"])})
        if alpha >= DELTA_ALPHA:
            bsdf.update({"type": "roughconductor", "distribution": "ggx", "alpha": alpha})
        bsdf = {"type": "twosided", "bsdf": bsdf}
    elif metallic == 0 and transmission == 0 and specular == 0 and clearcoat == 0 and sheen == 0:
        bsdf = {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": base_tex or rgb(base)}}
    elif metallic == 0 and transmission == 1:
        if volume is not None and ("attenuationColor" in volume or "attenuationDistance" in volume):
            notes.append("material %s: KHR_materials_volume attenuation ignored" % name)
        if thick:
            bsdf = {"type": "dielectric", "int_ior": ior, "ext_ior": 1.0, "specular_transmittance": rgb(base)}
            if alpha >= DELTA_ALPHA:
                bsdf.update({"type": "roughdielectric", "distribution": "ggx", "alpha": alpha})
        else:
            bsdf = {"type": "thindielectric", "int_ior": ior, "ext_ior": 1.0, "specular_transmittance": rgb(base)}
            if alpha >= DELTA_ALPHA:
                notes.append("material %s: thin-walled glass of roughness %g rendered smooth (Mitsuba's "
                             "thindielectric)" % (name, roughness))
    else:
        bsdf = {"type": "principled", "base_color": base_tex or rgb(base), "metallic": metallic, "roughness": roughness,
                "eta": ior}
        if transmission > 0:
            bsdf["spec_trans"] = transmission
        else:
            bsdf = {"type": "twosided", "bsdf": bsdf}
        if metallic < 1:
            notes.append("material %s: glTF dielectric layer approximated by Mitsuba's principled" % name)
    if base_tex is not None and (bsdf["bsdf"] if bsdf["type"] == "twosided" else bsdf)["type"] not in ("diffuse",
                                                                                                     "principled"):
        notes.append("material %s: baseColorTexture ignored (factors only)" % name)
    handled = {"diffuse": ("KHR_materials_specular",), "conductor": (), "roughconductor": (),
               "principled": ("KHR_materials_transmission", "KHR_materials_ior")}
    inner = bsdf["bsdf"]["type"] if bsdf["type"] == "twosided" else bsdf["type"]
    done = handled.get(inner, ("KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume"))
    unmapped = [k for k in ext if k not in done + ("KHR_materials_emissive_strength",)]
    if unmapped:
        notes.append("material %s: %s not mapped" % (name, ", ".join(sorted(unmapped))))

    emissive = [float(v) for v in mat.get("emissiveFactor", [0, 0, 0])]
    strength = float(ext.get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0))
    emission = [v * strength for v in emissive] if max(emissive) > 0 and strength > 0 else None
    return bsdf, emission, bool(mat.get("doubleSided", False))


def scene_dict(mi, path, width, height, max_depth, tmpdir, rr_depth=3, sampler="independent"):
    """(Mitsuba scene dictionary, list of notes on what was approximated or left out)"""
    doc, buffers, base = load_gltf(path)
    notes = []
    scene_index = doc.get("scene", 0)
    extras = doc["scenes"][scene_index].get("extras", {}).get("candela", {})
    out = {"type": "scene",
           "integrator": {"type": "path", "max_depth": int(max_depth) + 1, "rr_depth": int(rr_depth),
                          "hide_emitters": False}}
    materials = doc.get("materials", [])
    default_mat = {"name": "default", "pbrMetallicRoughness": {}}
    camera = None
    shapes = 0
    for node_index, m in walk(doc, scene_index):
        node = doc["nodes"][node_index]
        if "camera" in node and camera is None:
            camera = (doc["cameras"][node["camera"]], m)
        if "mesh" not in node:
            continue
        normal_m = np.linalg.inv(m[:3, :3]).T
        flip = np.linalg.det(m[:3, :3]) < 0
        for p_index, prim in enumerate(doc["meshes"][node["mesh"]]["primitives"]):
            if prim.get("mode", 4) != 4:
                notes.append("mesh %d primitive %d: mode %d skipped (triangles only)" %
                             (node["mesh"], p_index, prim.get("mode")))
                continue
            pos = accessor(doc, buffers, prim["attributes"]["POSITION"])
            pos = pos @ m[:3, :3].T + m[:3, 3]
            normals = None
            if "NORMAL" in prim["attributes"]:
                normals = accessor(doc, buffers, prim["attributes"]["NORMAL"]) @ normal_m.T
                normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-30)
            if "indices" in prim:
                faces = accessor(doc, buffers, prim["indices"]).reshape(-1, 3).astype(np.int64)
            else:
                faces = np.arange(len(pos)).reshape(-1, 3)
            if flip:
                faces = faces[:, ::-1]
            ply = os.path.join(tmpdir, "shape-%d.ply" % shapes)
            mat = materials[prim["material"]] if "material" in prim else default_mat
            uvs = None  # only where a texture needs them (UVs change Mitsuba's tangent frame, so its random paths)
            if "TEXCOORD_0" in prim["attributes"] and "baseColorTexture" in mat.get("pbrMetallicRoughness", {}):
                uvs = accessor(doc, buffers, prim["attributes"]["TEXCOORD_0"])
            write_ply(ply, pos, normals, faces, uvs)
            bsdf, emission, two_faced = material_bsdf(mat, notes, (doc, buffers, base, tmpdir))
            shape = {"type": "ply", "filename": ply, "face_normals": normals is None, "bsdf": bsdf}
            if emission is not None:
                shape["emitter"] = {"type": "area", "radiance": rgb(emission)}
                if two_faced:
                    notes.append("material %s: doubleSided emission approximated by the front face" %
                                 mat.get("name", "?"))
            out["shape-%d" % shapes] = shape
            shapes += 1
    if camera is None:
        raise ValueError("%s has no camera" % path)
    cam, m = camera
    if cam.get("type") != "perspective":
        raise ValueError("only perspective cameras are converted")
    if "aperture_radius" in cam.get("extras", {}).get("candela", {}):
        raise ValueError("thin-lens cameras are not converted")
    persp = cam["perspective"]
    origin = m[:3, 3]
    forward = -m[:3, 2] / np.linalg.norm(m[:3, 2])
    up = m[:3, 1] / np.linalg.norm(m[:3, 1])
    out["sensor"] = {
        "type": "perspective", "fov": math.degrees(persp["yfov"]), "fov_axis": "y",
        "near_clip": float(persp.get("znear", 0.01)), "far_clip": float(persp.get("zfar", 1e6)),
        "to_world": mi.ScalarTransform4f().look_at(origin=origin.tolist(), target=(origin + forward).tolist(),
                                                   up=up.tolist()),
        "film": {"type": "hdrfilm", "width": int(width), "height": int(height), "pixel_format": "rgb",
                 "component_format": "float32", "rfilter": {"type": "box"}},
        "sampler": {"type": sampler},
    }
    env = extras.get("environment")
    if env:
        rotation = float(env.get("rotation", 0.0))
        out["environment"] = {"type": "envmap", "filename": os.path.join(base, env["file"]),
                              "scale": float(env.get("strength", 1.0)),
                              "to_world": mi.ScalarTransform4f().rotate([0, 1, 0], rotation + 180.0)}
    elif extras.get("background") and max(extras["background"]) > 0:
        out["environment"] = {"type": "constant", "radiance": rgb(extras["background"])}
    return out, sorted(set(notes))


DEFAULT_LLVM = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"


def import_mitsuba(variant):
    if not os.environ.get("DRJIT_LIBLLVM_PATH") and os.path.isfile(DEFAULT_LLVM):
        os.environ["DRJIT_LIBLLVM_PATH"] = DEFAULT_LLVM
    try:
        import mitsuba as mi
    except ImportError:
        raise UserError("Mitsuba 3 is not installed. Install it for Debian's python3: /usr/bin/python3 -m "
                        "pip install --user --break-system-packages mitsuba (then run this script with "
                        "/usr/bin/python3)")
    try:
        mi.set_variant(variant)
    except Exception as e:  # no LLVM library, or a variant this build lacks
        if variant == "scalar_rgb":
            raise UserError("Mitsuba cannot set the scalar_rgb variant: %s" % e)
        print("note: Mitsuba variant %s unavailable (%s; set DRJIT_LIBLLVM_PATH to a libLLVM); falling back to "
              "scalar_rgb, which traces one path per thread without SIMD: its times are not those of llvm_ad_rgb" %
              (variant, e), file=sys.stderr)
        mi.set_variant("scalar_rgb")
    return mi


class Mitsuba:
    def __init__(self, mi, scene_path, width, height, max_depth, sampler, tmp):
        self.mi, self.sampler = mi, sampler
        d, self.notes = scene_dict(mi, scene_path, width, height, max_depth, tmp, sampler=sampler)
        self.scene = mi.load_dict(d)

    def render(self, spp, seed):
        """(image as a float64 array H x W x 3, seconds of mi.render until the pixels are on the host)"""
        import numpy as np
        t = time.perf_counter()
        image = np.array(self.mi.render(self.scene, spp=spp, seed=seed))
        seconds = time.perf_counter() - t
        sampler = self.scene.sensors()[0].sampler()
        if sampler.sample_count() != spp:  # stratified samplers round (ldsampler: to a power of 4)
            raise UserError("Mitsuba's %s sampler rendered %d spp where %d were asked: use sample counts it "
                            "takes (ldsampler: powers of 4)" % (self.sampler, sampler.sample_count(), spp))
        return image[:, :, :3].astype(np.float64), seconds

    def write(self, image, path):
        import numpy as np
        self.mi.Bitmap(np.ascontiguousarray(image, dtype=np.float32)).write(path)
