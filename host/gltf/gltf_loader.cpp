#include "gltf/gltf_loader.hpp"

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string_view>

#include "scene/environment.hpp"
#include "base/error.hpp"
#include "scene/vdb_grid.hpp"

namespace candela {
namespace {

// Extensions this loader implements fully; any other one is named in a warning
const std::set<std::string> kSupportedExtensions = {
    "KHR_materials_emissive_strength", "KHR_texture_transform", "KHR_mesh_quantization",
    "KHR_materials_ior", "KHR_materials_specular", "KHR_materials_transmission",
    "KHR_materials_volume", "KHR_materials_clearcoat", "KHR_materials_anisotropy", "KHR_lights_punctual"};

// Measured conductors as RGB complex indices of refraction (eta + i k at about 650, 550
// and 450 nm), selectable by name in a material's extras.candela.conductor
struct ConductorPreset {
  const char* name;
  glm::vec3 eta, k;
};
const ConductorPreset kConductors[] = {
    {"gold", {0.143119f, 0.374957f, 1.44248f}, {3.98316f, 2.38572f, 1.60322f}},
    {"silver", {0.155265f, 0.116723f, 0.138342f}, {4.82835f, 3.12225f, 2.14696f}},
    {"copper", {0.200438f, 0.924033f, 1.10221f}, {3.91295f, 2.45285f, 2.14219f}},
    {"aluminium", {1.65746f, 0.880369f, 0.521229f}, {9.22387f, 6.26952f, 4.837f}},
    {"chromium", {4.36968f, 2.9167f, 1.6547f}, {5.20637f, 4.23137f, 3.75491f}},
    {"iron", {2.91140f, 2.94970f, 2.58450f}, {3.08930f, 2.93180f, 2.76700f}},
};

class Warnings {
 public:
  explicit Warnings(std::vector<std::string>* out) : out_(out) {}
  void add(const std::string& w) {
    if (seen_.insert(w).second) out_->push_back(w);
  }

 private:
  std::vector<std::string>* out_;
  std::set<std::string> seen_;
};

// Limit on the values (elements x components) of one accessor without a bufferView
// (zero-filled): it takes no room in the file, so a few bytes could ask for gigabytes
constexpr size_t kMaxZeroFilledValues = size_t(1) << 24;

// One component as a float: normalized integers map to [0,1] / [-1,1] (glTF 3.11)
float decode_float(const unsigned char* p, int ctype, bool normalized) {
  switch (ctype) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float f;
      std::memcpy(&f, p, 4);
      return f;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return normalized ? *p / 255.0f : float(*p);
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      int8_t v = int8_t(*p);
      return normalized ? std::max(v / 127.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0f : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return float(v);
    }
    default:
      throw Error("glTF accessor has an unsupported component type");
  }
}

// One unsigned integer component (indices)
uint32_t decode_uint(const unsigned char* p, int ctype, bool) {
  switch (ctype) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return *p;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    default:
      throw Error("glTF indices must be unsigned bytes, shorts or ints");
  }
}

// Reads `count` elements of `ncomp` components from a bufferView, `offset` bytes in,
// after checking every byte lies inside the view and the buffer (no overflow possible:
// only subtractions of checked values and one division).
template <typename T, typename Decode>
void read_view(const tinygltf::Model& model, int view_index, size_t offset, size_t count, int ncomp,
               int ctype, bool normalized, Decode decode, std::vector<T>* out) {
  if (view_index < 0 || view_index >= (int)model.bufferViews.size())
    throw Error("glTF accessor refers to a missing bufferView");
  const tinygltf::BufferView& view = model.bufferViews[view_index];
  if (view.buffer < 0 || view.buffer >= (int)model.buffers.size())
    throw Error("glTF bufferView refers to a missing buffer");
  const std::vector<unsigned char>& buf = model.buffers[view.buffer].data;
  int csize = tinygltf::GetComponentSizeInBytes(ctype);
  if (csize <= 0) throw Error("glTF accessor has an unsupported component type");
  size_t elem = size_t(ncomp) * size_t(csize);
  size_t stride = view.byteStride ? view.byteStride : elem;
  if (stride < elem) throw Error("glTF bufferView byteStride is smaller than its elements");
  if (view.byteOffset > buf.size() || view.byteLength > buf.size() - view.byteOffset)
    throw Error("glTF bufferView lies outside its buffer (is the .bin file complete?)");
  out->clear();
  if (count == 0) return;
  if (offset > view.byteLength || elem > view.byteLength - offset ||
      count - 1 > (view.byteLength - offset - elem) / stride)
    throw Error("glTF accessor reads past the end of its bufferView");
  out->resize(count * ncomp);
  const unsigned char* base = buf.data() + view.byteOffset + offset;
  for (size_t i = 0; i < count; ++i)
    for (int c = 0; c < ncomp; ++c)
      (*out)[i * ncomp + c] = decode(base + i * stride + size_t(c) * csize, ctype, normalized);
}

// Accessor elements as T (count * components values), sparse substitution applied
template <typename T, typename Decode>
std::vector<T> read_accessor_as(const tinygltf::Model& model, int index, int want_components,
                                Decode decode) {
  if (index < 0 || index >= (int)model.accessors.size())
    throw Error("glTF accessor " + std::to_string(index) + " does not exist");
  const tinygltf::Accessor& acc = model.accessors[index];
  int comps = tinygltf::GetNumComponentsInType(acc.type);
  if (comps <= 0) throw Error("glTF accessor " + std::to_string(index) + " has an invalid type");
  if (want_components > 0 && comps != want_components)
    throw Error("glTF accessor " + std::to_string(index) + " has " + std::to_string(comps) +
                " components, expected " + std::to_string(want_components));
  std::vector<T> values;
  if (acc.bufferView >= 0) {
    read_view(model, acc.bufferView, acc.byteOffset, acc.count, comps, acc.componentType,
              acc.normalized, decode, &values);
  } else {
    if (acc.count > kMaxZeroFilledValues / size_t(comps))
      throw Error("glTF accessor " + std::to_string(index) + " is too large for one without a bufferView (" +
                  std::to_string(acc.count) + " elements)");
    values.assign(acc.count * comps, T(0));
  }
  if (acc.sparse.isSparse) {
    if (acc.sparse.count < 0 || size_t(acc.sparse.count) > acc.count || acc.sparse.indices.byteOffset < 0 ||
        acc.sparse.values.byteOffset < 0)
      throw Error("glTF sparse accessor " + std::to_string(index) + " is malformed");
    std::vector<uint32_t> idx;
    std::vector<T> vals;
    read_view(model, acc.sparse.indices.bufferView, size_t(acc.sparse.indices.byteOffset),
              size_t(acc.sparse.count), 1, acc.sparse.indices.componentType, false, decode_uint, &idx);
    read_view(model, acc.sparse.values.bufferView, size_t(acc.sparse.values.byteOffset),
              size_t(acc.sparse.count), comps, acc.componentType, acc.normalized, decode, &vals);
    for (size_t i = 0; i < idx.size(); ++i) {
      if (idx[i] >= acc.count) throw Error("glTF sparse accessor index out of range");
      for (int c = 0; c < comps; ++c) values[size_t(idx[i]) * comps + c] = vals[i * comps + c];
    }
  }
  return values;
}

std::vector<float> read_accessor(const tinygltf::Model& model, int index, int want_components) {
  return read_accessor_as<float>(model, index, want_components, decode_float);
}

std::vector<uint32_t> read_indices(const tinygltf::Model& model, int index) {
  return read_accessor_as<uint32_t>(model, index, 1, decode_uint);
}

glm::mat4 local_transform(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) {
    glm::mat4 m;
    for (int i = 0; i < 16; ++i) glm::value_ptr(m)[i] = float(node.matrix[i]);  // column-major
    return m;
  }
  glm::mat4 m(1.0f);
  if (node.translation.size() == 3)
    m = glm::translate(m, glm::vec3(node.translation[0], node.translation[1], node.translation[2]));
  if (node.rotation.size() == 4) {
    glm::quat q(float(node.rotation[3]), float(node.rotation[0]), float(node.rotation[1]),
                float(node.rotation[2]));
    m *= glm::mat4_cast(glm::normalize(q));
  }
  if (node.scale.size() == 3)
    m = glm::scale(m, glm::vec3(node.scale[0], node.scale[1], node.scale[2]));
  return m;
}

double number_or(const tinygltf::Value& obj, const char* key, int index, double fallback) {
  if (!obj.Has(key)) return fallback;
  const tinygltf::Value& v = obj.Get(key);
  if (index >= 0) {
    if (!v.IsArray() || int(v.ArrayLen()) <= index || !v.Get(index).IsNumber()) return fallback;
    return v.Get(index).GetNumberAsDouble();
  }
  return v.IsNumber() ? v.GetNumberAsDouble() : fallback;
}

// A dense grid {"size": [nx, ny, nz], "min": [x, y, z], "max": [x, y, z], key: [nx ny nz
// values, x fastest]} (gw names it in errors)
void read_dense_grid(const tinygltf::Value& grid, const std::string& gw, const char* key, glm::ivec3* size,
                     glm::vec3* lo, glm::vec3* hi, std::vector<float>* values) {
  if (!grid.IsObject()) throw Error(gw + " must be an object");
  size_t count = 1;
  for (int k = 0; k < 3; ++k) {
    double n = number_or(grid, "size", k, 0.0);
    if (!(n >= 2.0 && n <= 1024.0) || n != std::floor(n)) throw Error(gw + ".size must hold 3 integers in [2, 1024]");
    (*size)[k] = int(n);
    count *= size_t(n);
    (*lo)[k] = float(number_or(grid, "min", k, NAN));
    (*hi)[k] = float(number_or(grid, "max", k, NAN));
    if (!((*lo)[k] < (*hi)[k]) || !std::isfinite((*lo)[k]) || !std::isfinite((*hi)[k]))
      throw Error(gw + ": min and max must be finite with min < max on every axis");
  }
  if (!grid.Has(key) || !grid.Get(key).IsArray() || grid.Get(key).ArrayLen() != count)
    throw Error(gw + "." + key + " must be an array of size[0] x size[1] x size[2] numbers");
  const tinygltf::Value& d = grid.Get(key);
  values->resize(count);
  for (size_t i = 0; i < count; ++i) {
    const tinygltf::Value& x = d.Get(int(i));
    (*values)[i] = x.IsNumber() ? float(x.GetNumberAsDouble()) : -1.0f;
    if (!((*values)[i] >= 0.0f) || !std::isfinite((*values)[i]))
      throw Error(gw + "." + key + " must hold finite non-negative numbers");
  }
}

// "emission_grid": a dense grid ("values" in place of "density") scaling the emission, its
// box inside the density grid's (where the majorant cells are)
void read_emission_grid(const tinygltf::Value& v, const std::string& where, MediumDesc* m) {
  if (!v.Has("emission_grid")) return;
  std::string ew = where + ".emission_grid";
  read_dense_grid(v.Get("emission_grid"), ew, "values", &m->emission_grid_size, &m->emission_grid_min,
                  &m->emission_grid_max, &m->emission_grid);
  for (int k = 0; k < 3; ++k)
    if (m->emission_grid_min[k] < m->grid_min[k] || m->emission_grid_max[k] > m->grid_max[k])
      throw Error(ew + ": its box must lie inside the density grid's box (min " + std::to_string(m->grid_min[k]) +
                  ", max " + std::to_string(m->grid_max[k]) + " on axis " + std::to_string(k) + ")");
}

// A medium from candela's extras: {"sigma_a": [r, g, b], "sigma_s": [r, g, b], "g": g,
// "emission": [r, g, b], "density_scale": s, "grid": {"size": [nx, ny, nz], "min": [x, y, z],
// "max": [x, y, z], "density": [nx ny nz values, x fastest]} or {"nanovdb": "f.nvdb"} or
// {"vdb": "f.vdb"} with an optional "name"}, "emission_grid": {"size", "min", "max", "values"}
// (with a dense grid) and "emission_scale": s; every entry optional
MediumDesc read_medium(const tinygltf::Value& v, const std::string& where, const std::string& base_dir) {
  if (!v.IsObject()) throw Error(where + " must be an object");
  MediumDesc m;
  auto rgb = [&](const char* key, glm::vec3* out) {
    if (!v.Has(key)) return;
    const tinygltf::Value& a = v.Get(key);
    if (!a.IsArray() || a.ArrayLen() != 3) throw Error(where + "." + key + " must be an array of 3 numbers");
    for (int c = 0; c < 3; ++c) {
      (*out)[c] = float(number_or(v, key, c, -1.0));
      if (!((*out)[c] >= 0.0f) || !std::isfinite((*out)[c]))
        throw Error(where + "." + key + " must hold finite non-negative numbers");
    }
  };
  rgb("sigma_a", &m.sigma_a);
  rgb("sigma_s", &m.sigma_s);
  rgb("emission", &m.emission);
  m.g = float(number_or(v, "g", -1, 0.0));
  if (!(std::fabs(m.g) < 1.0f)) throw Error(where + ".g must lie in (-1, 1)");
  m.density_scale = float(number_or(v, "density_scale", -1, 1.0));
  if (!(m.density_scale >= 0.0f) || !std::isfinite(m.density_scale))
    throw Error(where + ".density_scale must be finite and non-negative");
  if (v.Has("emission_scale")) {
    m.emission_scale = float(number_or(v, "emission_scale", -1, -1.0));
    if (!(m.emission_scale >= 0.0f) || !std::isfinite(m.emission_scale))
      throw Error(where + ".emission_scale must be finite and non-negative");
    if (!v.Has("emission_grid")) throw Error(where + ".emission_scale needs an emission_grid");
  }
  if (v.Has("emission_grid") && (!v.Has("grid") || !v.Get("grid").IsObject() || !v.Get("grid").Has("size")))
    throw Error(where + ".emission_grid needs an inline dense grid (size, min, max, density) beside it");
  if (!v.Has("grid")) return m;
  const tinygltf::Value& grid = v.Get("grid");
  std::string gw = where + ".grid";
  // {"nanovdb": "file.nvdb"} or {"vdb": "file.vdb"}, relative to the glTF file, and "name": a grid
  for (const char* key : {"nanovdb", "vdb"}) {
    if (!grid.Has(key)) continue;
    const tinygltf::Value& file = grid.Get(key);
    if (!file.IsString() || file.Get<std::string>().empty()) throw Error(gw + "." + key + " must name a file");
    if (base_dir.empty()) throw Error(gw + "." + key + ": a scene loaded from memory cannot name files");
    if (grid.Has("name") && !grid.Get("name").IsString()) throw Error(gw + ".name must be a string");
    std::string name = grid.Has("name") ? grid.Get("name").Get<std::string>() : "";
    std::filesystem::path path(file.Get<std::string>());
    if (path.is_relative()) path = std::filesystem::path(base_dir) / path;
    if (std::string(key) == "vdb")
      load_openvdb_density(path.string(), name, &m);
    else
      load_nanovdb_density(path.string(), name, &m);
    return m;
  }
  read_dense_grid(grid, gw, "density", &m.grid_size, &m.grid_min, &m.grid_max, &m.density);
  read_emission_grid(v, where, &m);
  return m;
}

// KHR_texture_transform: uv' = T(offset) * R(rotation) * S(scale) * uv, and its texCoord
void read_texture_transform(const tinygltf::Value& ext, TextureSlot* ref) {
  float ox = float(number_or(ext, "offset", 0, 0.0)), oy = float(number_or(ext, "offset", 1, 0.0));
  float r = float(number_or(ext, "rotation", -1, 0.0));
  float sx = float(number_or(ext, "scale", 0, 1.0)), sy = float(number_or(ext, "scale", 1, 1.0));
  float c = std::cos(r), s = std::sin(r);
  // Column-major: columns are the images of (1,0,0), (0,1,0), (0,0,1)
  ref->transform = glm::mat3(glm::vec3(c * sx, -s * sx, 0.0f), glm::vec3(s * sy, c * sy, 0.0f),
                             glm::vec3(ox, oy, 1.0f));
  if (ext.Has("texCoord")) ref->texcoord = int(number_or(ext, "texCoord", -1, ref->texcoord));
}

// A KHR_lights_punctual light's own properties, checked against what the extension says
// they must be (an Error) or should be (a warning); the node reader places it
PunctualLightDesc read_punctual_light(const tinygltf::Light& gl, size_t index, Warnings* warn) {
  const std::string what = "KHR_lights_punctual light " + std::to_string(index);
  PunctualLightDesc l;
  if (gl.type == "point") l.type = PunctualType::Point;
  else if (gl.type == "spot") l.type = PunctualType::Spot;
  else if (gl.type == "directional") l.type = PunctualType::Directional;
  else throw Error(what + " has type '" + gl.type + "'; it must be point, spot or directional");
  if (!gl.color.empty()) {
    if (gl.color.size() != 3) throw Error(what + ": color must hold 3 numbers");
    for (int c = 0; c < 3; ++c) {
      l.color[c] = float(gl.color[size_t(c)]);
      if (!(l.color[c] >= 0.0f && std::isfinite(l.color[c]))) throw Error(what + ": color must be finite and non-negative");
    }
    if (l.color.x > 1.0f || l.color.y > 1.0f || l.color.z > 1.0f)
      warn->add(what + ": color components above 1 are outside the extension's range; used as given");
  }
  l.intensity = float(gl.intensity);
  if (!(l.intensity >= 0.0f && std::isfinite(l.intensity))) throw Error(what + ": intensity must be finite and non-negative");
  // tinygltf reads an absent range as 0: both mean infinite
  l.range = float(gl.range);
  if (!(l.range >= 0.0f && std::isfinite(l.range))) throw Error(what + ": range must be greater than 0");
  if (l.type == PunctualType::Directional && l.range > 0.0f) {
    warn->add(what + ": range applies only to point and spot lights; it is ignored on a directional light");
    l.range = 0.0f;
  }
  if (l.type == PunctualType::Spot) {
    l.inner_cone = float(gl.spot.innerConeAngle);
    l.outer_cone = float(gl.spot.outerConeAngle);
    const double half_pi = 1.57079632679489662;
    if (!(gl.spot.innerConeAngle >= 0.0 && gl.spot.innerConeAngle < gl.spot.outerConeAngle &&
          gl.spot.outerConeAngle <= half_pi + 1e-9))
      throw Error(what + ": spot cone angles must satisfy 0 <= innerConeAngle < outerConeAngle <= pi/2");
  }
  return l;
}

// Materials and the textures they use
class MaterialReader {
 public:
  // `image_errors`: why each image that load_checked_image left empty was not decoded
  // `base_dir`: where files a medium names (NanoVDB grids) are found; empty: nowhere
  MaterialReader(const tinygltf::Model& model, const std::map<int, std::string>& image_errors, Scene* scene,
                 Warnings* warn, const std::string& base_dir)
      : model_(model), image_errors_(image_errors), scene_(scene), warn_(*warn), base_dir_(base_dir) {}

  // Reads every material, then the default one (index = model's material count)
  void read_all() {
    for (size_t i = 0; i < model_.materials.size(); ++i) scene_->materials.push_back(read(int(i)));
    scene_->materials.push_back(MaterialDesc());  // glTF default: white, for primitives without one
  }

 private:
  MaterialDesc read(int index) {
    const tinygltf::Material& gm = model_.materials[size_t(index)];
    std::string name = "material '" + (gm.name.empty() ? std::to_string(index) : gm.name) + "'";
    const auto& pbr = gm.pbrMetallicRoughness;
    MaterialDesc m;
    for (int c = 0; c < 4; ++c) m.base_color[c] = float(pbr.baseColorFactor[c]);
    m.metallic = float(pbr.metallicFactor);
    m.roughness = float(pbr.roughnessFactor);
    set_slot(&m, TEX_BASE_COLOR, pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
             pbr.baseColorTexture.extensions, true);
    set_slot(&m, TEX_METALLIC_ROUGHNESS, pbr.metallicRoughnessTexture.index,
             pbr.metallicRoughnessTexture.texCoord, pbr.metallicRoughnessTexture.extensions, false);
    set_slot(&m, TEX_NORMAL, gm.normalTexture.index, gm.normalTexture.texCoord, gm.normalTexture.extensions, false);
    m.normal_scale = float(gm.normalTexture.scale);
    set_slot(&m, TEX_EMISSION, gm.emissiveTexture.index, gm.emissiveTexture.texCoord, gm.emissiveTexture.extensions, true);
    float strength = float(number_or(extension(gm, "KHR_materials_emissive_strength"), "emissiveStrength", -1, 1.0));
    for (int c = 0; c < 3; ++c) {
      m.emission[c] = float(gm.emissiveFactor[c]) * strength;
      if (!(m.emission[c] >= 0.0f) || !std::isfinite(m.emission[c]))
        throw Error(name + " has a negative or non-finite emission (emissiveFactor x emissiveStrength)");
    }
    m.double_sided = gm.doubleSided;
    m.alpha_mode = gm.alphaMode == "MASK" ? AlphaMode::Mask : gm.alphaMode == "BLEND" ? AlphaMode::Blend : AlphaMode::Opaque;
    m.alpha_cutoff = float(gm.alphaCutoff);
    read_extensions(gm, &m);
    read_extras(gm.extras, name, &m);
    read_medium_of(gm, name, &m);
    check_ranges(name, &m);
    warn_unsupported(gm);
    return m;
  }

  static const tinygltf::Value& extension(const tinygltf::Material& gm, const char* name) {
    static const tinygltf::Value none;
    auto it = gm.extensions.find(name);
    return it == gm.extensions.end() ? none : it->second;
  }

  // KHR_materials_ior, _specular, _transmission, _volume, _clearcoat, _anisotropy
  void read_extensions(const tinygltf::Material& gm, MaterialDesc* m) {
    m->ior = float(number_or(extension(gm, "KHR_materials_ior"), "ior", -1, 1.5));
    const tinygltf::Value& spec = extension(gm, "KHR_materials_specular");
    m->specular = float(number_or(spec, "specularFactor", -1, 1.0));
    for (int c = 0; c < 3; ++c) m->specular_color[c] = float(number_or(spec, "specularColorFactor", c, 1.0));
    value_slot(m, TEX_SPECULAR, spec, "specularTexture", false);
    value_slot(m, TEX_SPECULAR_COLOR, spec, "specularColorTexture", true);
    const tinygltf::Value& tr = extension(gm, "KHR_materials_transmission");
    m->transmission = float(number_or(tr, "transmissionFactor", -1, 0.0));
    value_slot(m, TEX_TRANSMISSION, tr, "transmissionTexture", false);
    const tinygltf::Value& vol = extension(gm, "KHR_materials_volume");
    m->thin_walled = !(number_or(vol, "thicknessFactor", -1, 0.0) > 0.0);
    if (vol.Has("thicknessTexture"))
      warn_.add("KHR_materials_volume thicknessTexture is not used: a path tracer traces the real thickness");
    const tinygltf::Value& cc = extension(gm, "KHR_materials_clearcoat");
    m->clearcoat = float(number_or(cc, "clearcoatFactor", -1, 0.0));
    m->clearcoat_roughness = float(number_or(cc, "clearcoatRoughnessFactor", -1, 0.0));
    value_slot(m, TEX_CLEARCOAT, cc, "clearcoatTexture", false);
    value_slot(m, TEX_CLEARCOAT_ROUGHNESS, cc, "clearcoatRoughnessTexture", false);
    if (cc.Has("clearcoatNormalTexture"))
      warn_.add("KHR_materials_clearcoat clearcoatNormalTexture is not supported yet: the coat uses the base's normal");
    const tinygltf::Value& an = extension(gm, "KHR_materials_anisotropy");
    m->anisotropy_strength = float(number_or(an, "anisotropyStrength", -1, 0.0));
    m->anisotropy_rotation = float(number_or(an, "anisotropyRotation", -1, 0.0));
    value_slot(m, TEX_ANISOTROPY, an, "anisotropyTexture", false);
  }

  // The medium inside a closed surface. KHR_materials_volume (thickness > 0, transmission):
  // absorption sigma_a = -ln(attenuationColor) / attenuationDistance, the extension's
  // definition. extras.candela.medium adds its coefficients (scattering, emission, a grid);
  // on a material without transmission it makes the surface a null boundary.
  void read_medium_of(const tinygltf::Material& gm, const std::string& name, MaterialDesc* m) {
    const tinygltf::Value& vol = extension(gm, "KHR_materials_volume");
    bool has_extra = gm.extras.Has("candela") && gm.extras.Get("candela").Has("medium");
    MediumDesc md;
    if (has_extra) md = read_medium(gm.extras.Get("candela").Get("medium"), name + " extras.candela.medium", base_dir_);
    bool solid = m->transmission > 0.0f && !m->thin_walled;
    if (solid) {
      double distance = number_or(vol, "attenuationDistance", -1, INFINITY);
      if (!(distance > 0.0)) throw Error(name + ": KHR_materials_volume attenuationDistance must be positive");
      for (int c = 0; c < 3; ++c) {
        double color = number_or(vol, "attenuationColor", c, 1.0);
        if (!(color >= 0.0 && color <= 1.0)) throw Error(name + ": KHR_materials_volume attenuationColor must lie in [0, 1]");
        if (std::isfinite(distance)) md.sigma_a[c] += float(color > 0.0 ? -std::log(color) / distance : 1e30);
      }
    } else if (has_extra && m->transmission > 0.0f) {
      warn_.add(name + ": a thin-walled material (no KHR_materials_volume thickness) has no interior: its medium is ignored");
      return;
    } else if (has_extra) {
      m->null_boundary = true;
    }
    bool empty = md.sigma_a == glm::vec3(0.0f) && md.sigma_s == glm::vec3(0.0f) && md.emission == glm::vec3(0.0f);
    if (!has_extra && empty) return;  // clear glass: vacuum inside
    m->medium = int(scene_->media.size());
    scene_->media.push_back(std::move(md));
  }

  // extras.candela.conductor: a preset name or {"eta": [r, g, b], "k": [r, g, b]}
  void read_extras(const tinygltf::Value& extras, const std::string& name, MaterialDesc* m) {
    if (!extras.Has("candela") || !extras.Get("candela").Has("conductor")) return;
    const tinygltf::Value& c = extras.Get("candela").Get("conductor");
    m->type = MATERIAL_CONDUCTOR;
    if (c.IsString()) {
      for (const auto& p : kConductors)
        if (c.Get<std::string>() == p.name) {
          m->conductor_eta = p.eta;
          m->conductor_k = p.k;
          return;
        }
      std::string names;
      for (const auto& p : kConductors) names += std::string(names.empty() ? "" : ", ") + p.name;
      throw Error(name + ": unknown conductor '" + c.Get<std::string>() + "' (known: " + names + ")");
    }
    for (int i = 0; i < 3; ++i) {
      m->conductor_eta[i] = float(number_or(c, "eta", i, -1.0));
      m->conductor_k[i] = float(number_or(c, "k", i, -1.0));
    }
  }

  static void check_ranges(const std::string& name, MaterialDesc* m) {
    auto in = [&](float v, float lo, float hi, const char* what) {
      if (!(v >= lo && v <= hi)) throw Error(name + ": " + what + " must lie in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    };
    for (int c = 0; c < 4; ++c) in(m->base_color[c], 0.0f, 1.0f, "baseColorFactor");
    in(m->metallic, 0.0f, 1.0f, "metallicFactor");
    in(m->roughness, 0.0f, 1.0f, "roughnessFactor");
    in(m->transmission, 0.0f, 1.0f, "transmissionFactor");
    in(m->specular, 0.0f, 1.0f, "specularFactor");
    in(m->clearcoat, 0.0f, 1.0f, "clearcoatFactor");
    in(m->clearcoat_roughness, 0.0f, 1.0f, "clearcoatRoughnessFactor");
    in(m->anisotropy_strength, 0.0f, 1.0f, "anisotropyStrength");
    in(m->ior, 0.0f, 10.0f, "ior");
    for (int c = 0; c < 3; ++c) {
      in(m->specular_color[c], 0.0f, 1e6f, "specularColorFactor");
      if (m->type == MATERIAL_CONDUCTOR) {
        in(m->conductor_eta[c], 0.0f, 100.0f, "conductor eta");
        in(m->conductor_k[c], 0.0f, 100.0f, "conductor k");
      }
    }
    // ior 0 stands for an infinite index (a perfect mirror); keep the kernel's arithmetic finite
    m->ior = m->ior == 0.0f ? 1e4f : std::max(m->ior, 1.0f + 1e-4f);
  }

  void warn_unsupported(const tinygltf::Material& gm) {
    if (gm.occlusionTexture.index >= 0)
      warn_.add("occlusionTexture is ignored (a path tracer computes occlusion itself)");
    for (const auto& e : gm.extensions)
      if (!kSupportedExtensions.count(e.first))
        warn_.add("glTF extension " + e.first + " is not supported yet and is ignored");
  }

  void set_slot(MaterialDesc* m, int slot, int gltf_texture, int texcoord,
                const tinygltf::ExtensionMap& extensions, bool srgb) {
    if (gltf_texture < 0) return;
    auto tt = extensions.find("KHR_texture_transform");
    m->textures[slot] = texture_ref(gltf_texture, texcoord, tt == extensions.end() ? nullptr : &tt->second, srgb);
  }

  // A textureInfo inside an extension (a plain JSON object to tinygltf)
  void value_slot(MaterialDesc* m, int slot, const tinygltf::Value& ext, const char* key, bool srgb) {
    if (!ext.Has(key)) return;
    const tinygltf::Value& info = ext.Get(key);
    int index = int(number_or(info, "index", -1, -1.0));
    if (index < 0) throw Error(std::string("glTF ") + key + " has no texture index");
    const tinygltf::Value* tt = nullptr;
    if (info.Has("extensions") && info.Get("extensions").Has("KHR_texture_transform"))
      tt = &info.Get("extensions").Get("KHR_texture_transform");
    m->textures[slot] = texture_ref(index, int(number_or(info, "texCoord", -1, 0.0)), tt, srgb);
  }

  TextureSlot texture_ref(int gltf_texture, int texcoord, const tinygltf::Value* transform, bool srgb) {
    TextureSlot ref;
    ref.index = texture_index(gltf_texture, srgb);
    ref.texcoord = texcoord;
    if (transform) read_texture_transform(*transform, &ref);
    if (ref.texcoord < 0 || ref.texcoord > 1) {
      warn_.add("textures on TEXCOORD_" + std::to_string(ref.texcoord) + " are not supported (only TEXCOORD_0 and TEXCOORD_1): the texture is ignored");
      ref.index = NO_TEXTURE;
    }
    return ref;
  }

  // Adds the glTF texture's image once, returning its index in Scene::textures (or NO_TEXTURE)
  int texture_index(int gltf_texture, bool srgb) {
    auto key = std::make_pair(gltf_texture, srgb);
    if (auto it = texture_cache_.find(key); it != texture_cache_.end()) return it->second;
    if (gltf_texture < 0 || gltf_texture >= (int)model_.textures.size())
      throw Error("glTF texture " + std::to_string(gltf_texture) + " does not exist");
    const tinygltf::Texture& tex = model_.textures[size_t(gltf_texture)];
    TextureDesc t;
    std::string why;
    int& index = texture_cache_[key];
    index = NO_TEXTURE;
    if (decode_source(tex, srgb, &t, &why)) {
      read_sampler(tex.sampler, &t);
      index = int(scene_->textures.size());
      scene_->textures.push_back(std::move(t));
    } else {
      warn_.add("glTF texture " + std::to_string(gltf_texture) + " has no image candela can decode (" + why +
                "): it is ignored, as if the material had no such texture");
    }
    return index;
  }

  // The texture's core `source`, else the image of EXT_texture_webp, KHR_texture_basisu or
  // MSFT_texture_dds if that one decodes; false with the first image's reason when none does
  bool decode_source(const tinygltf::Texture& tex, bool srgb, TextureDesc* t, std::string* why) {
    std::vector<int> sources;
    if (tex.source >= 0) sources.push_back(tex.source);
    for (const char* ext : {"EXT_texture_webp", "KHR_texture_basisu", "MSFT_texture_dds"})
      if (auto it = tex.extensions.find(ext); it != tex.extensions.end())
        if (double source = number_or(it->second, "source", -1, -1.0); source >= 0.0)
          sources.push_back(int(std::min(source, 1e9)));
    for (int source : sources) {
      if (source >= (int)model_.images.size()) throw Error("glTF image " + std::to_string(source) + " does not exist");
      std::string reason = decode_image(source, srgb, t);
      if (reason.empty()) return true;
      if (why->empty()) *why = "image " + std::to_string(source) + " " + reason;
    }
    if (why->empty()) *why = "it has no source";
    return false;
  }

  // tinygltf decodes every image to 4 channels of 8 or 16 bits: 8-bit images stay RGBA8
  // (sRGB decoded in the kernel), 16-bit ones become float texels, decoded here. Returns
  // why the image cannot be used, or "".
  std::string decode_image(int source, bool srgb, TextureDesc* out) {
    const tinygltf::Image& img = model_.images[size_t(source)];
    if (img.width <= 0 || img.height <= 0 || img.image.empty()) {
      if (auto it = image_errors_.find(source); it != image_errors_.end()) return it->second;
      return img.uri.empty() ? "could not be decoded" : "('" + img.uri + "') could not be read or decoded";
    }
    TextureDesc& t = *out;
    t = TextureDesc();
    t.width = img.width;
    t.height = img.height;
    size_t n = t.texels();
    if (img.component != 4 || (img.bits != 8 && img.bits != 16) ||
        img.image.size() < n * 4 * size_t(img.bits / 8))
      return "has an unexpected pixel layout";
    if (img.bits == 8) {
      t.srgb = srgb;
      t.rgba8.assign(img.image.begin(), img.image.begin() + ptrdiff_t(4 * n));
      return "";
    }
    t.rgbaf.resize(4 * n);
    for (size_t i = 0; i < 4 * n; ++i) {
      uint16_t v;
      std::memcpy(&v, &img.image[2 * i], 2);
      float c = v / 65535.0f;
      t.rgbaf[i] = srgb && i % 4 != 3 ? dev::srgb_to_linear(c) : c;
    }
    return "";
  }

  void read_sampler(int sampler_index, TextureDesc* t) {
    if (sampler_index < 0 || sampler_index >= (int)model_.samplers.size()) return;
    const tinygltf::Sampler& sampler = model_.samplers[size_t(sampler_index)];
    auto mode = [](int w) {
      return w == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE      ? WRAP_CLAMP
             : w == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT ? WRAP_MIRROR
                                                           : WRAP_REPEAT;
    };
    t->wrap_s = mode(sampler.wrapS);
    t->wrap_t = mode(sampler.wrapT);
    // Without mip-maps magFilter picks every lookup (nearest or bilinear); minFilter is unused
    t->nearest = sampler.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST;
  }

  const tinygltf::Model& model_;
  const std::map<int, std::string>& image_errors_;
  Scene* scene_;
  Warnings& warn_;
  std::string base_dir_;
  std::map<std::pair<int, bool>, int> texture_cache_;
};

// One primitive's vertex attributes and triangles, placed in the world
class MeshReader {
 public:
  MeshReader(const tinygltf::Model& model, Scene* scene, Warnings* warn)
      : model_(model), scene_(scene), warn_(*warn) {}

  void read(const tinygltf::Mesh& mesh, const glm::mat4& world) {
    for (const auto& prim : mesh.primitives) {
      if (!renderable(prim)) continue;
      MeshDesc m;
      m.material = prim.material >= 0 && prim.material < (int)model_.materials.size()
                       ? uint32_t(prim.material)
                       : uint32_t(model_.materials.size());  // the default material
      read_attributes(prim, world, &m);
      read_triangles(prim, world, &m);
      if (m.tangents.empty()) generate_tangents(normal_texcoord(prim), &m);
      if (m.triangles() > 0) scene_->meshes.push_back(std::move(m));
    }
  }

  size_t degenerate() const { return degenerate_; }

 private:
  bool renderable(const tinygltf::Primitive& prim) {
    if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        prim.mode != TINYGLTF_MODE_TRIANGLE_FAN && prim.mode != -1) {
      warn_.add("point and line primitives are not rendered");
      return false;
    }
    if (!prim.targets.empty()) warn_.add("morph targets are not supported yet: base geometry is rendered");
    if (prim.extensions.count("KHR_draco_mesh_compression")) {
      warn_.add("Draco-compressed primitives (KHR_draco_mesh_compression) are not supported: they are skipped");
      return false;
    }
    if (!prim.attributes.count("POSITION")) {
      warn_.add("a primitive without POSITION was skipped");
      return false;
    }
    return true;
  }

  // Attribute `name` with `comps` components per vertex (0: VEC3 or VEC4), or empty
  std::vector<float> attribute(const tinygltf::Primitive& prim, const std::string& name, int comps,
                               size_t nverts, int* got_comps = nullptr) {
    auto it = prim.attributes.find(name);
    if (it == prim.attributes.end()) return {};
    std::vector<float> v = read_accessor(model_, it->second, comps);
    int c = tinygltf::GetNumComponentsInType(model_.accessors[size_t(it->second)].type);
    if (got_comps) *got_comps = c;
    if (v.size() != nverts * size_t(c)) throw Error("glTF primitive attributes have different vertex counts");
    return v;
  }

  void read_attributes(const tinygltf::Primitive& prim, const glm::mat4& world, MeshDesc* m) {
    std::vector<float> pos = read_accessor(model_, prim.attributes.at("POSITION"), 3);
    size_t n = pos.size() / 3;
    glm::mat3 linear(world), normal_matrix = glm::transpose(glm::inverse(linear));
    for (size_t v = 0; v < n; ++v) {
      glm::vec3 p = glm::vec3(world * glm::vec4(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2], 1.0f));
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        throw Error("glTF mesh has non-finite vertex positions");
      m->positions.push_back(p);
    }
    auto unit_or_zero = [](glm::vec3 v) {
      float len = glm::length(v);
      return len > 0.0f && std::isfinite(len) ? v / len : glm::vec3(0.0f);
    };
    std::vector<float> nrm = attribute(prim, "NORMAL", 3, n);
    for (size_t v = 0; v < nrm.size() / 3; ++v)
      m->normals.push_back(unit_or_zero(normal_matrix * glm::vec3(nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2])));
    std::vector<float> tan = attribute(prim, "TANGENT", 4, n);
    for (size_t v = 0; v < tan.size() / 4; ++v)
      m->tangents.push_back(glm::vec4(unit_or_zero(linear * glm::vec3(tan[4 * v], tan[4 * v + 1], tan[4 * v + 2])),
                                      tan[4 * v + 3] < 0.0f ? -1.0f : 1.0f));
    for (int set = 0; set < 2; ++set) {
      std::vector<float> uv = attribute(prim, "TEXCOORD_" + std::to_string(set), 2, n);
      auto& out = set == 0 ? m->uv0 : m->uv1;
      for (size_t v = 0; v < uv.size() / 2; ++v) out.push_back(glm::vec2(uv[2 * v], uv[2 * v + 1]));
    }
    read_colors(prim, n, m);
  }

  // COLOR_0: RGB or RGBA (its alpha is not used, alphaMode reads the base colour's), linear, in [0, 1]
  void read_colors(const tinygltf::Primitive& prim, size_t n, MeshDesc* m) {
    int comps = 0;
    std::vector<float> col = attribute(prim, "COLOR_0", 0, n, &comps);
    if (col.empty()) return;
    if (comps != 3 && comps != 4) throw Error("glTF COLOR_0 must be VEC3 or VEC4");
    for (float c : col)
      if (!(c >= 0.0f && c <= 1.0f))
        throw Error("glTF COLOR_0 values must lie in [0, 1] (integer colors must be normalized)");
    for (size_t v = 0; v < n; ++v)
      m->colors.push_back(glm::vec3(col[comps * v], col[comps * v + 1], col[comps * v + 2]));
  }

  // The TEXCOORD set of the primitive's normal texture, -1 without one
  int normal_texcoord(const tinygltf::Primitive& prim) const {
    if (prim.material < 0 || prim.material >= (int)model_.materials.size()) return -1;
    const tinygltf::NormalTextureInfo& n = model_.materials[size_t(prim.material)].normalTexture;
    return n.index >= 0 && (n.texCoord == 0 || n.texCoord == 1) ? n.texCoord : -1;
  }

  // Per-vertex tangents for a normal-mapped mesh without TANGENT, as the glTF specification
  // asks (MikkTSpace-style, not bit-identical to it): each triangle's dp/du from the normal
  // texture's coordinates, summed at its corners weighted by the corner angle, made
  // orthogonal to the vertex normal; the bitangent sign w says whether cross(n, t) points
  // toward decreasing v (+Y of the normal texture, glTF's convention) or away (mirrored
  // UVs). Vertices without a usable tangent keep 0 (the kernel then uses dp/du).
  void generate_tangents(int texcoord, MeshDesc* m) {
    const std::vector<glm::vec2>& uv = texcoord == 1 ? m->uv1 : m->uv0;
    if (texcoord < 0 || uv.size() != m->positions.size()) return;
    size_t n = m->positions.size();
    std::vector<glm::vec3> sum(n, glm::vec3(0.0f));
    std::vector<float> handed(n, 0.0f);
    for (size_t t = 0; t < m->triangles(); ++t) {
      uint32_t idx[3] = {m->indices[3 * t], m->indices[3 * t + 1], m->indices[3 * t + 2]};
      glm::vec3 e1 = m->positions[idx[1]] - m->positions[idx[0]], e2 = m->positions[idx[2]] - m->positions[idx[0]];
      glm::vec2 d1 = uv[idx[1]] - uv[idx[0]], d2 = uv[idx[2]] - uv[idx[0]];
      float det = d1.x * d2.y - d2.x * d1.y;
      if (!(std::fabs(det) > 1e-20f)) continue;
      glm::vec3 dpdu = (d2.y * e1 - d1.y * e2) / det, dpdv = (d1.x * e2 - d2.x * e1) / det;
      float len = glm::length(dpdu);
      if (!(len > 0.0f) || !std::isfinite(len)) continue;
      dpdu /= len;
      glm::vec3 face = glm::cross(e1, e2);
      for (int k = 0; k < 3; ++k) {
        glm::vec3 a = m->positions[idx[(k + 1) % 3]] - m->positions[idx[k]];
        glm::vec3 b = m->positions[idx[(k + 2) % 3]] - m->positions[idx[k]];
        float la = glm::length(a), lb = glm::length(b);
        if (!(la > 0.0f && lb > 0.0f)) continue;
        float angle = std::acos(std::clamp(glm::dot(a, b) / (la * lb), -1.0f, 1.0f));
        glm::vec3 nv = m->normals.empty() || glm::dot(m->normals[idx[k]], m->normals[idx[k]]) == 0.0f
                           ? glm::normalize(face)
                           : m->normals[idx[k]];
        sum[idx[k]] += angle * dpdu;
        handed[idx[k]] += angle * (glm::dot(glm::cross(nv, dpdu), -dpdv) < 0.0f ? -1.0f : 1.0f);
      }
    }
    m->tangents.assign(n, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
    for (size_t v = 0; v < n; ++v) {
      glm::vec3 t = sum[v];
      if (!m->normals.empty()) t -= glm::dot(m->normals[v], t) * m->normals[v];
      float len = glm::length(t);
      if (len > 1e-12f && std::isfinite(len)) m->tangents[v] = glm::vec4(t / len, handed[v] < 0.0f ? -1.0f : 1.0f);
    }
  }

  // Triangles from TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN, zero-area ones skipped
  void read_triangles(const tinygltf::Primitive& prim, const glm::mat4& world, MeshDesc* m) {
    size_t nverts = m->positions.size();
    std::vector<uint32_t> indices;
    if (prim.indices >= 0) {
      indices = read_indices(model_, prim.indices);
    } else {
      for (uint32_t i = 0; i < nverts; ++i) indices.push_back(i);
    }
    for (uint32_t i : indices)
      if (i >= nverts) throw Error("glTF primitive index out of range");
    bool mirrored = glm::determinant(glm::mat3(world)) < 0.0f;
    auto emit = [&](uint32_t a, uint32_t b, uint32_t c) {
      if (mirrored) std::swap(b, c);  // a mirroring transform flips the winding
      double area;
      triangle_normal_area(m->positions[a], m->positions[b], m->positions[c], &area);
      if (!(area > 0.0)) {
        ++degenerate_;  // zero area: invisible, and it has no normal
        return;
      }
      m->indices.insert(m->indices.end(), {a, b, c});
    };
    int mode = prim.mode == -1 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      for (size_t i = 0; i + 2 < indices.size(); i += 3) emit(indices[i], indices[i + 1], indices[i + 2]);
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      for (size_t i = 0; i + 2 < indices.size(); ++i) {
        if (i % 2 == 0)
          emit(indices[i], indices[i + 1], indices[i + 2]);
        else
          emit(indices[i + 1], indices[i], indices[i + 2]);
      }
    } else {
      for (size_t i = 1; i + 1 < indices.size(); ++i) emit(indices[i], indices[i + 1], indices[0]);
    }
  }

  const tinygltf::Model& model_;
  Scene* scene_;
  Warnings& warn_;
  size_t degenerate_ = 0;
};

// The default scene's node trees: transforms, meshes, the first camera, scene extras
class NodeReader {
 public:
  NodeReader(const tinygltf::Model& model, Scene* scene, Warnings* warn, const std::string& base_dir)
      : model_(model), scene_(scene), warn_(*warn), base_dir_(base_dir), meshes_(model, scene, warn) {}

  void read_scene() {
    std::vector<int> roots;
    int scene_index = model_.defaultScene >= 0 ? model_.defaultScene : 0;
    if (model_.defaultScene >= (int)model_.scenes.size())
      throw Error("glTF 'scene' " + std::to_string(model_.defaultScene) + " does not exist");
    if (scene_index < (int)model_.scenes.size()) {
      const tinygltf::Scene& s = model_.scenes[size_t(scene_index)];
      roots = s.nodes;
      read_scene_extras(s.extras);
    } else {
      // No scene: render every root node
      std::vector<bool> is_child(model_.nodes.size(), false);
      for (const auto& n : model_.nodes)
        for (int c : n.children)
          if (c >= 0 && c < (int)is_child.size()) is_child[size_t(c)] = true;
      for (size_t i = 0; i < model_.nodes.size(); ++i)
        if (!is_child[i]) roots.push_back(int(i));
    }
    visited_.assign(model_.nodes.size(), false);
    for (int r : roots) visit(r, glm::mat4(1.0f));
    if (meshes_.degenerate() > 0)
      warn_.add(std::to_string(meshes_.degenerate()) + " zero-area triangles were skipped");
  }

 private:
  void read_scene_extras(const tinygltf::Value& extras) {
    if (!extras.Has("candela")) return;
    const tinygltf::Value& c = extras.Get("candela");
    if (c.Has("environment")) read_environment_extras(c.Get("environment"));
    if (c.Has("strategy")) {
      const tinygltf::Value& st = c.Get("strategy");
      if (!st.IsString() || (st.Get<std::string>() != "nee" && st.Get<std::string>() != "bsdf" && st.Get<std::string>() != "auto"))
        throw Error("scene extras candela.strategy must be \"nee\", \"bsdf\" or \"auto\"");
      scene_->strategy = st.Get<std::string>();
    }
    if (c.Has("medium")) {
      MediumDesc m = read_medium(c.Get("medium"), "scene extras candela.medium", base_dir_);
      // An infinite ray through a global medium gathers emission / sigma_t: finite only where sigma_t > 0
      for (int k = 0; k < 3; ++k)
        if (m.emission[k] > 0.0f && !m.is_grid() && !(m.sigma_a[k] + m.sigma_s[k] > 0.0f))
          throw Error("scene extras candela.medium: an emitting channel needs sigma_a + sigma_s > 0 (rays reach infinity)");
      scene_->global_medium = int(scene_->media.size());
      scene_->media.push_back(std::move(m));
    }
    if (!c.Has("background")) return;
    const tinygltf::Value& bg = c.Get("background");
    if (!bg.IsArray() || bg.ArrayLen() != 3)
      throw Error("scene extras candela.background must be an array of 3 numbers");
    for (int i = 0; i < 3; ++i) {
      if (!bg.Get(i).IsNumber()) throw Error("scene extras candela.background must hold numbers");
      scene_->background[i] = float(bg.Get(i).GetNumberAsDouble());
      if (!(scene_->background[i] >= 0.0f) || !std::isfinite(scene_->background[i]))
        throw Error("scene extras candela.background must be finite and non-negative");
    }
  }

  // extras.candela.environment = {"file": "sky.hdr", "strength": 1, "rotation": 0}: the
  // file name (relative to the glTF file) goes to EnvironmentDesc::source; load_gltf_bytes
  // reads the image
  void read_environment_extras(const tinygltf::Value& env) {
    const char* what = "scene extras candela.environment";
    if (!env.IsObject() || !env.Has("file") || !env.Get("file").IsString())
      throw Error(std::string(what) + " must be an object with a \"file\" string");
    EnvironmentDesc e;
    e.source = env.Get("file").Get<std::string>();
    auto number = [&](const char* key, float fallback) {
      if (!env.Has(key)) return fallback;
      const tinygltf::Value& v = env.Get(key);
      double x = v.IsNumber() ? v.GetNumberAsDouble() : NAN;
      if (!std::isfinite(x) || std::fabs(x) > 1e30) throw Error(std::string(what) + "." + key + " must be a finite number");
      return float(x);
    };
    e.strength = number("strength", 1.0f);
    e.rotation = number("rotation", 0.0f);
    if (e.strength < 0.0f) throw Error(std::string(what) + ".strength must not be negative");
    scene_->environment = e;
  }

  void visit(int index, const glm::mat4& parent) {
    if (index < 0 || index >= (int)model_.nodes.size())
      throw Error("glTF node " + std::to_string(index) + " does not exist");
    // glTF 3.5.2: nodes form disjoint strict trees (no node has two parents, no cycles)
    if (visited_[size_t(index)])
      throw Error("glTF node " + std::to_string(index) + " has two parents or is part of a cycle");
    visited_[size_t(index)] = true;
    const tinygltf::Node& node = model_.nodes[size_t(index)];
    glm::mat4 world = parent * local_transform(node);
    if (node.mesh >= 0) {
      if (node.mesh >= (int)model_.meshes.size())
        throw Error("glTF node " + std::to_string(index) + " refers to a missing mesh");
      meshes_.read(model_.meshes[size_t(node.mesh)], world);
      if (!node.weights.empty() || !model_.meshes[size_t(node.mesh)].weights.empty())
        warn_.add("morph targets are not supported yet: base geometry is rendered");
    }
    if (node.camera >= 0 && !scene_->camera) read_camera(node.camera, world);
    if (auto ext = node.extensions.find("KHR_lights_punctual"); ext != node.extensions.end())
      read_light(index, ext->second, world);
    for (int child : node.children) visit(child, world);
  }

  // The node's KHR_lights_punctual light at the node's world origin, pointing along its
  // world -Z axis
  void read_light(int node_index, const tinygltf::Value& ext, const glm::mat4& world) {
    const std::string where = "glTF node " + std::to_string(node_index);
    if (!ext.IsObject() || !ext.Has("light") || !ext.Get("light").IsNumber())
      throw Error(where + ": KHR_lights_punctual has no light index");
    double index = ext.Get("light").GetNumberAsDouble();
    if (!(index >= 0.0 && index < double(model_.lights.size()) && index == std::floor(index)))
      throw Error(where + " refers to a missing KHR_lights_punctual light");
    PunctualLightDesc l = read_punctual_light(model_.lights[size_t(index)], size_t(index), &warn_);
    l.position = glm::vec3(world * glm::vec4(0, 0, 0, 1));
    if (!(std::isfinite(l.position.x) && std::isfinite(l.position.y) && std::isfinite(l.position.z))) throw Error(where + ": the light's position is not finite");
    if (l.type != PunctualType::Point) {
      glm::vec3 dir = glm::vec3(world * glm::vec4(0, 0, -1, 0));
      float len = glm::length(dir);
      if (!(len > 0.0f && std::isfinite(len)))
        throw Error(where + ": the light has no direction (its node transform is degenerate or not finite)");
      l.direction = dir / len;
    }
    scene_->punctual_lights.push_back(l);
  }

  // The first camera met, perspective or orthographic; znear and zfar are ignored (rays
  // start at the camera and are never clipped)
  void read_camera(int index, const glm::mat4& world) {
    if (index >= (int)model_.cameras.size()) throw Error("glTF camera " + std::to_string(index) + " does not exist");
    const tinygltf::Camera& c = model_.cameras[size_t(index)];
    CameraDesc cam;
    if (c.type == "perspective") {
      cam.yfov = float(c.perspective.yfov);
      cam.aspect = float(c.perspective.aspectRatio);
      if (!(cam.yfov > 0.0f && cam.yfov < 3.14159f)) throw Error("glTF camera has an invalid yfov");
    } else if (c.type == "orthographic") {
      cam.projection = Projection::Orthographic;
      // The spec forbids zero and advises against negative magnifications: take |mag|
      double xmag = std::fabs(c.orthographic.xmag), ymag = std::fabs(c.orthographic.ymag);
      if (!(xmag > 0.0 && ymag > 0.0 && xmag < 1e15 && ymag < 1e15))
        throw Error("glTF orthographic camera needs finite, non-zero xmag and ymag");
      cam.ymag = float(ymag);
      cam.aspect = float(xmag / ymag);
    } else {
      warn_.add("camera type '" + c.type + "' is not supported; it is skipped");
      return;
    }
    cam.position = glm::vec3(world * glm::vec4(0, 0, 0, 1));
    cam.forward = glm::normalize(glm::vec3(world * glm::vec4(0, 0, -1, 0)));
    cam.up = glm::normalize(glm::vec3(world * glm::vec4(0, 1, 0, 0)));
    read_camera_extras(c.extras, &cam);
    scene_->camera = cam;
  }

  // Thin lens: cameras[i].extras.candela = {"aperture_radius": R, "focus_distance": D}
  void read_camera_extras(const tinygltf::Value& extras, CameraDesc* cam) {
    if (!extras.IsObject() || !extras.Has("candela")) return;
    const tinygltf::Value& c = extras.Get("candela");
    auto number = [&](const char* key) -> std::optional<double> {
      if (!c.Has(key)) return std::nullopt;
      const tinygltf::Value& v = c.Get(key);
      if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble()))
        throw Error(std::string("camera extras candela.") + key + " must be a finite number");
      return v.GetNumberAsDouble();
    };
    if (auto r = number("aperture_radius")) {
      if (*r < 0.0) throw Error("camera extras candela.aperture_radius must not be negative");
      if (*r > 0.0 && cam->projection == Projection::Orthographic)
        throw Error("camera extras candela.aperture_radius: an orthographic camera has no lens (depth of field needs a perspective camera)");
      cam->aperture_radius = float(*r);
    }
    if (auto d = number("focus_distance")) {
      if (!(*d > 0.0)) throw Error("camera extras candela.focus_distance must be positive");
      cam->focus_distance = float(*d);
    }
  }

  const tinygltf::Model& model_;
  Scene* scene_;
  Warnings& warn_;
  std::string base_dir_;
  MeshReader meshes_;
  std::vector<bool> visited_;  // nodes reached so far
};

void warn_model_wide(const tinygltf::Model& model, Warnings* warn) {
  for (const auto& ext : model.extensionsUsed)
    if (!kSupportedExtensions.count(ext)) warn->add("glTF extension " + ext + " is not supported yet and is ignored");
  for (const auto& ext : model.extensionsRequired)
    if (!kSupportedExtensions.count(ext))
      warn->add("the scene requires glTF extension " + ext + ", which candela does not support: the image may be wrong");
  if (!model.animations.empty()) warn->add("animations are ignored (the first frame is rendered)");
  if (!model.skins.empty()) warn->add("skins are ignored (meshes render in their bind pose)");
}

// tinygltf file access that finds no file: glTF from memory without a base folder
bool no_file_exists(const std::string&, void*) { return false; }
std::string no_expand_path(const std::string& path, void*) { return path; }
bool no_read(std::vector<unsigned char>*, std::string* err, const std::string& path, void*) {
  if (err) *err += "external files are not read: " + path + "\n";
  return false;
}
bool no_write(std::string*, const std::string&, const std::vector<unsigned char>&, void*) { return false; }

// glTF images are PNG or JPEG (3.8.2). Their headers give the size before anything is
// decoded, so a few bytes claiming a huge image cannot make stb_image allocate and fill
// gigabytes; other formats, which stb_image would also decode, are not glTF images.
constexpr uint64_t kMaxImageBytes = uint64_t(1) << 30;  // decoded RGBA: 16384^2 at 8 bits
// stb_image decodes a truncated JPEG as if the rest were there. Huffman coding spends at
// least a bit on each 8x8 block, so a whole JPEG has at most 512 texels a byte: allow twice.
constexpr uint64_t kMaxJpegTexelsPerByte = 1024;

uint32_t big_endian(const unsigned char* p, int bytes) {
  uint32_t v = 0;
  for (int i = 0; i < bytes; ++i) v = v << 8 | p[i];
  return v;
}

enum class ImageFormat { Other, Png, Jpeg };

// Format, width, height and bytes per channel from a PNG or JPEG header
ImageFormat image_header(const unsigned char* p, size_t n, uint64_t* w, uint64_t* h, int* channel_bytes) {
  static const unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (n >= 26 && std::memcmp(p, kPng, 8) == 0 && std::memcmp(p + 12, "IHDR", 4) == 0) {
    *w = big_endian(p + 16, 4);
    *h = big_endian(p + 20, 4);
    *channel_bytes = p[24] == 16 ? 2 : 1;
    return ImageFormat::Png;
  }
  if (n < 4 || p[0] != 0xFF || p[1] != 0xD8) return ImageFormat::Other;
  // JPEG: marker segments up to the frame header (SOF0-SOF15 but DHT, JPG and DAC)
  for (size_t i = 2; i + 4 <= n;) {
    unsigned char m = p[i + 1];
    if (p[i] != 0xFF) return ImageFormat::Other;
    if (m == 0xFF) {
      ++i;  // fill byte
    } else if (m == 0x01 || (m >= 0xD0 && m <= 0xD7)) {
      i += 2;  // no length
    } else if (m >= 0xC0 && m <= 0xCF && m != 0xC4 && m != 0xC8 && m != 0xCC) {
      if (i + 9 > n) return ImageFormat::Other;
      *h = big_endian(p + i + 5, 2);
      *w = big_endian(p + i + 7, 2);
      *channel_bytes = 1;
      return ImageFormat::Jpeg;
    } else if (m == 0xDA || m == 0xD9) {
      return ImageFormat::Other;  // a scan or the end before any frame
    } else {
      i += 2 + big_endian(p + i + 2, 2);
    }
  }
  return ImageFormat::Other;
}

// tinygltf's image decoding (to RGBA) behind those checks. An image that fails them or
// does not decode is left empty, never an error: `errors` (std::map<int, std::string>,
// the user data) records why, and a texture using it falls back or is dropped.
bool load_checked_image(tinygltf::Image* image, const int index, std::string*, std::string* warn,
                        int req_width, int req_height, const unsigned char* bytes, int size, void* errors) {
  std::string why;
  uint64_t w = 0, h = 0;
  int channel_bytes = 1;
  ImageFormat format = size > 0 ? image_header(bytes, size_t(size), &w, &h, &channel_bytes) : ImageFormat::Other;
  std::string dims = std::to_string(w) + " x " + std::to_string(h);
  if (format == ImageFormat::Other) {
    why = "is neither PNG nor JPEG";
  } else if (w > kMaxImageBytes || h > kMaxImageBytes || w * h * 4 * uint64_t(channel_bytes) > kMaxImageBytes) {
    why = "is " + dims + ": too large (over 1 GiB decoded)";
  } else if (format == ImageFormat::Jpeg && w * h > kMaxJpegTexelsPerByte * uint64_t(size)) {
    why = "is a JPEG of " + dims + " in only " + std::to_string(size) + " bytes: it is truncated";
  } else {
    std::string decode_err;
    if (tinygltf::LoadImageData(image, index, &decode_err, warn, req_width, req_height, bytes, size, nullptr))
      return true;
    while (!decode_err.empty() && (decode_err.back() == '\n' || decode_err.back() == ' ')) decode_err.pop_back();
    why = "could not be decoded: " + decode_err;
  }
  (*static_cast<std::map<int, std::string>*>(errors))[index] = why;
  image->image.clear();
  image->width = image->height = 0;
  return true;
}

// Deepest array and object nesting of JSON text, counted up to `limit` + 1. tinygltf
// converts extras and extensions recursively: deep nesting would overflow the stack.
size_t json_depth(const char* p, size_t n, size_t limit) {
  size_t depth = 0, deepest = 0;
  bool in_string = false;
  for (size_t i = 0; i < n && deepest <= limit; ++i) {
    if (in_string) {
      if (p[i] == '\\')
        ++i;
      else if (p[i] == '"')
        in_string = false;
    } else if (p[i] == '"') {
      in_string = true;
    } else if (p[i] == '[' || p[i] == '{') {
      deepest = std::max(deepest, ++depth);
    } else if ((p[i] == ']' || p[i] == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}
constexpr size_t kMaxJsonDepth = 64;

void append_u32le(std::string* out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out->push_back(char((v >> (8 * i)) & 0xffu));
}

// KHR_lights_punctual lets a spot light leave out its `spot` object (the cone then takes
// its defaults), but tinygltf 2.7 rejects the file. Gives each such light an empty one:
// *out gets the patched file (JSON text, or GLB with its JSON chunk replaced) and the
// result is true; false, and no copy, when the JSON needs nothing (or does not parse:
// tinygltf then reports it).
bool add_missing_spot_objects(const std::string& data, size_t json_begin, size_t json_size, bool binary,
                              std::string* out) {
  if (binary && json_begin != 20) return false;  // too short for a GLB: tinygltf reports it
  std::string_view text(data.data() + json_begin, json_size);
  if (text.find("KHR_lights_punctual") == std::string_view::npos) return false;
  nlohmann::json j = nlohmann::json::parse(text.begin(), text.end(), nullptr, false);
  if (j.is_discarded() || !j.is_object()) return false;
  auto ext = j.find("extensions");
  if (ext == j.end() || !ext->is_object()) return false;
  auto khr = ext->find("KHR_lights_punctual");
  if (khr == ext->end() || !khr->is_object()) return false;
  auto lights = khr->find("lights");
  if (lights == khr->end() || !lights->is_array()) return false;
  bool changed = false;
  for (nlohmann::json& l : *lights) {
    if (!l.is_object() || l.contains("spot")) continue;
    auto type = l.find("type");
    if (type != l.end() && type->is_string() && type->get<std::string>() == "spot") {
      l["spot"] = nlohmann::json::object();
      changed = true;
    }
  }
  if (!changed) return false;
  std::string patched = j.dump();
  if (!binary) {
    *out = std::move(patched);
    return true;
  }
  // GLB: header, the new JSON chunk (padded with spaces to 4 bytes), the chunks after it
  while (patched.size() % 4) patched.push_back(' ');
  std::string rest = data.substr(json_begin + json_size);
  if (12 + 8 + patched.size() + rest.size() > UINT32_MAX) return false;
  out->assign(data, 0, 8);  // magic and version
  append_u32le(out, uint32_t(12 + 8 + patched.size() + rest.size()));
  append_u32le(out, uint32_t(patched.size()));
  out->append(data, 16, 4);  // chunk type JSON
  *out += patched;
  *out += rest;
  return true;
}  // glTF itself needs under 10

// Parses glTF JSON or GLB bytes and builds the scene; `name` labels error messages.
// External URIs resolve against `base_dir`; with an empty one, only data: URIs load.
Scene load_gltf_bytes(const std::string& data, const std::string& base_dir, const std::string& name) {
  if (data.empty()) throw Error("cannot load glTF scene " + name + ": the file is empty");
  if (data.size() > UINT32_MAX) throw Error("cannot load glTF scene " + name + ": larger than 4 GiB");
  tinygltf::TinyGLTF gltf;
  if (base_dir.empty()) {
    tinygltf::FsCallbacks fs = {};
    fs.FileExists = no_file_exists;
    fs.ExpandFilePath = no_expand_path;
    fs.ReadWholeFile = no_read;
    fs.WriteWholeFile = no_write;
    gltf.SetFsCallbacks(fs);
  }
  std::map<int, std::string> image_errors;  // filled by load_checked_image
  gltf.SetImageLoader(load_checked_image, &image_errors);
  tinygltf::Model model;
  std::string err, warn;
  // Binary glTF starts with the magic "glTF", whatever the file is called
  bool binary = data.compare(0, 4, "glTF") == 0;
  size_t json_begin = 0, json_size = data.size();  // a GLB's JSON is its first chunk
  if (binary && data.size() >= 20) {
    uint32_t length = 0;  // little-endian, at byte 12
    for (int i = 15; i >= 12; --i) length = length << 8 | uint8_t(data[size_t(i)]);
    json_begin = 20;
    json_size = std::min<size_t>(length, data.size() - 20);
  }
  if (json_depth(data.data() + json_begin, json_size, kMaxJsonDepth) > kMaxJsonDepth)
    throw Error("cannot load glTF scene " + name + ": JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
  std::string patched;  // the file with defaults tinygltf needs written in, if any
  const std::string& bytes = add_missing_spot_objects(data, json_begin, json_size, binary, &patched) ? patched : data;
  bool ok = binary ? gltf.LoadBinaryFromMemory(&model, &err, &warn,
                                               reinterpret_cast<const unsigned char*>(bytes.data()),
                                               unsigned(bytes.size()), base_dir)
                   : gltf.LoadASCIIFromString(&model, &err, &warn, bytes.data(), unsigned(bytes.size()), base_dir);
  if (!ok) {
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    throw Error("cannot load glTF scene " + name + ": " + (err.empty() ? "malformed file" : err));
  }
  Scene scene;
  if (!warn.empty()) {
    while (!warn.empty() && warn.back() == '\n') warn.pop_back();
    scene.warnings.push_back("glTF loader: " + warn);
  }
  Warnings warnings(&scene.warnings);
  warn_model_wide(model, &warnings);
  MaterialReader(model, image_errors, &scene, &warnings, base_dir).read_all();
  NodeReader(model, &scene, &warnings, base_dir).read_scene();
  if (scene.meshes.empty()) throw Error("the scene has no triangles to render");
  if (scene.environment) {
    // The environment map's file, beside the glTF file; none is read from memory alone
    EnvironmentDesc& env = *scene.environment;
    if (base_dir.empty()) {
      warnings.add("the environment map " + env.source + " is not loaded: the scene was read without a folder");
      scene.environment.reset();
    } else {
      std::string path = (std::filesystem::path(base_dir) / env.source).string();
      scene.environment = load_environment(path, env.strength, env.rotation);
    }
  }
  return scene;
}

}  // namespace

Scene load_gltf(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error("scene file not found: " + path);
  if (fs::is_directory(path, ec)) throw Error("scene path is a directory, not a glTF file: " + path);
  std::string data;
  std::ifstream in(path, std::ios::binary);
  uintmax_t size = fs::file_size(path, ec);
  if (in && !ec) {
    data.resize(size_t(size));
    in.read(data.data(), std::streamsize(size));
  }
  if (!in || ec) throw Error("cannot read scene file " + path);
  std::string dir = fs::path(path).parent_path().string();
  return load_gltf_bytes(data, dir.empty() ? "." : dir, path);
}

Scene load_gltf_from_memory(const std::string& data, const std::string& base_dir) {
  return load_gltf_bytes(data, base_dir, "(from memory)");
}

}  // namespace candela
