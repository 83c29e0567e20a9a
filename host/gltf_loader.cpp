#include "gltf_loader.hpp"

#include <tiny_gltf.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <map>
#include <optional>
#include <set>

#include "error.hpp"

namespace candela {
namespace {

// Extensions this loader implements fully; any other one is named in a warning
const std::set<std::string> kSupportedExtensions = {
    "KHR_materials_emissive_strength", "KHR_texture_transform", "KHR_mesh_quantization"};

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

// Limit on the elements of one accessor without a bufferView (zero-filled)
constexpr size_t kMaxZeroFilledElements = size_t(1) << 28;

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
    if (acc.count > kMaxZeroFilledElements)
      throw Error("glTF accessor " + std::to_string(index) + " is too large");
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

// Which TEXCOORD_n a material's texture reads, and its KHR_texture_transform
struct UvSet {
  int texcoord = 0;
  glm::mat3 transform{1.0f};  // uv' = transform * (u, v, 1)
  bool operator==(const UvSet& o) const { return texcoord == o.texcoord && transform == o.transform; }
};

double number_or(const tinygltf::Value& obj, const char* key, int index, double fallback) {
  if (!obj.Has(key)) return fallback;
  const tinygltf::Value& v = obj.Get(key);
  if (index >= 0) {
    if (!v.IsArray() || int(v.ArrayLen()) <= index || !v.Get(index).IsNumber()) return fallback;
    return v.Get(index).GetNumberAsDouble();
  }
  return v.IsNumber() ? v.GetNumberAsDouble() : fallback;
}

// KHR_texture_transform: uv' = T(offset) * R(rotation) * S(scale) * uv
void read_texture_transform(const tinygltf::Value& ext, UvSet* set) {
  float ox = float(number_or(ext, "offset", 0, 0.0)), oy = float(number_or(ext, "offset", 1, 0.0));
  float r = float(number_or(ext, "rotation", -1, 0.0));
  float sx = float(number_or(ext, "scale", 0, 1.0)), sy = float(number_or(ext, "scale", 1, 1.0));
  float c = std::cos(r), s = std::sin(r);
  // Column-major: columns are the images of (1,0,0), (0,1,0), (0,0,1)
  set->transform = glm::mat3(glm::vec3(c * sx, -s * sx, 0.0f), glm::vec3(s * sy, c * sy, 0.0f),
                             glm::vec3(ox, oy, 1.0f));
  if (ext.Has("texCoord")) set->texcoord = int(number_or(ext, "texCoord", -1, set->texcoord));
}

UvSet uv_set_of(int texcoord, const tinygltf::ExtensionMap& extensions) {
  UvSet set;
  set.texcoord = texcoord;
  auto tt = extensions.find("KHR_texture_transform");
  if (tt != extensions.end()) read_texture_transform(tt->second, &set);
  return set;
}

class Loader {
 public:
  Loader(const tinygltf::Model& model, Scene* scene)
      : model_(model), scene_(scene), warn_(&scene->warnings) {}

  void load() {
    for (const auto& ext : model_.extensionsUsed)
      if (!kSupportedExtensions.count(ext)) warn_.add("glTF extension " + ext + " is not supported yet and is ignored");
    for (const auto& ext : model_.extensionsRequired)
      if (!kSupportedExtensions.count(ext))
        warn_.add("the scene requires glTF extension " + ext + ", which candela does not support: the image may be wrong");
    if (!model_.animations.empty()) warn_.add("animations are ignored (the first frame is rendered)");
    if (!model_.skins.empty()) warn_.add("skins are ignored (meshes render in their bind pose)");
    load_materials();
    load_scene_roots();
    if (degenerate_ > 0)
      warn_.add(std::to_string(degenerate_) + " zero-area triangles were skipped");
    if (scene_->triangles.empty()) throw Error("the scene has no triangles to render");
  }

 private:
  void load_materials() {
    for (size_t i = 0; i < model_.materials.size(); ++i) {
      const tinygltf::Material& gm = model_.materials[i];
      std::string name = "material '" + (gm.name.empty() ? std::to_string(i) : gm.name) + "'";
      const auto& pbr = gm.pbrMetallicRoughness;
      dev::Material m = default_material();
      for (int c = 0; c < 4; ++c) m.base_color[c] = float(pbr.baseColorFactor[c]);
      // One UV set per material: the base color texture's, else the emissive texture's
      std::optional<UvSet> uv_set;
      if (pbr.baseColorTexture.index >= 0) {
        m.base_color_texture = texture_index(pbr.baseColorTexture.index, true);
        uv_set = uv_set_of(pbr.baseColorTexture.texCoord, pbr.baseColorTexture.extensions);
      }
      if (gm.emissiveTexture.index >= 0) {
        m.emission_texture = texture_index(gm.emissiveTexture.index, true);
        UvSet emissive_uv = uv_set_of(gm.emissiveTexture.texCoord, gm.emissiveTexture.extensions);
        if (!uv_set)
          uv_set = emissive_uv;
        else if (!(*uv_set == emissive_uv))
          warn_.add("emissiveTexture with other texture coordinates than baseColorTexture is not supported yet: it uses the base color's");
      }
      uv_sets_.push_back(uv_set.value_or(UvSet()));
      float strength = 1.0f;
      auto ext = gm.extensions.find("KHR_materials_emissive_strength");
      if (ext != gm.extensions.end() && ext->second.Has("emissiveStrength"))
        strength = float(ext->second.Get("emissiveStrength").GetNumberAsDouble());
      for (int c = 0; c < 3; ++c) {
        m.emission[c] = float(gm.emissiveFactor[c]) * strength;
        if (!(m.emission[c] >= 0.0f) || !std::isfinite(m.emission[c]))
          throw Error(name + " has a negative or non-finite emission (emissiveFactor x emissiveStrength)");
      }
      m.double_sided = gm.doubleSided ? 1u : 0u;

      if (pbr.metallicFactor > 0.0)
        warn_.add("metallic materials are not supported yet: rendered as diffuse with their base color (" + name + ", metallicFactor " + std::to_string(pbr.metallicFactor) + ")");
      if (pbr.metallicRoughnessTexture.index >= 0)
        warn_.add("metallicRoughnessTexture is not supported yet and is ignored");
      if (gm.normalTexture.index >= 0) warn_.add("normalTexture is not supported yet and is ignored");
      if (gm.occlusionTexture.index >= 0)
        warn_.add("occlusionTexture is ignored (a path tracer computes occlusion itself)");
      if (gm.alphaMode != "OPAQUE" && !gm.alphaMode.empty())
        warn_.add("alphaMode " + gm.alphaMode + " is not supported yet: surfaces are opaque");
      for (const auto& e : gm.extensions)
        if (!kSupportedExtensions.count(e.first))
          warn_.add("glTF extension " + e.first + " is not supported yet and is ignored");
      scene_->materials.push_back(m);
    }
    // Default material (glTF: white, metallic 1, roughness 1) for primitives without one
    default_material_index_ = uint32_t(scene_->materials.size());
    scene_->materials.push_back(default_material());
    uv_sets_.push_back(UvSet());
  }

  static dev::Material default_material() {
    dev::Material m{};
    m.type = MATERIAL_DIFFUSE;
    m.base_color_texture = NO_TEXTURE;
    m.emission_texture = NO_TEXTURE;
    for (int c = 0; c < 4; ++c) m.base_color[c] = 1.0f;
    return m;
  }

  // Adds the glTF texture's image once, returning its TextureInfo index (or NO_TEXTURE)
  int texture_index(int gltf_texture, bool srgb) {
    auto key = std::make_pair(gltf_texture, srgb);
    if (auto it = texture_cache_.find(key); it != texture_cache_.end()) return it->second;
    if (gltf_texture < 0 || gltf_texture >= (int)model_.textures.size())
      throw Error("glTF texture " + std::to_string(gltf_texture) + " does not exist");
    const tinygltf::Texture& tex = model_.textures[gltf_texture];
    if (tex.source < 0 || tex.source >= (int)model_.images.size()) {
      warn_.add("glTF texture " + std::to_string(gltf_texture) +
                " has no PNG or JPEG source (e.g. only KHR_texture_basisu): it is ignored");
      return NO_TEXTURE;
    }
    const tinygltf::Image& img = model_.images[tex.source];
    if (img.width <= 0 || img.height <= 0 || img.image.empty())
      throw Error("glTF image " + std::to_string(tex.source) + " ('" + img.uri + "') could not be decoded");

    size_t n = size_t(img.width) * img.height;
    if (scene_->texels.size() / 4 + n > size_t(UINT32_MAX))
      throw Error("the scene's textures hold more than 2^32 texels");
    dev::TextureInfo info{};
    info.offset = uint32_t(scene_->texels.size() / 4);
    info.width = uint32_t(img.width);
    info.height = uint32_t(img.height);
    uint32_t wrap_s = WRAP_REPEAT, wrap_t = WRAP_REPEAT;
    if (tex.sampler >= 0 && tex.sampler < (int)model_.samplers.size()) {
      const tinygltf::Sampler& sampler = model_.samplers[tex.sampler];
      auto mode = [](int w) {
        return w == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE ? WRAP_CLAMP
               : w == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT ? WRAP_MIRROR
                                                            : WRAP_REPEAT;
      };
      wrap_s = mode(sampler.wrapS);
      wrap_t = mode(sampler.wrapT);
      if (sampler.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST)
        warn_.add("texture filter NEAREST is not supported yet: textures are filtered bilinearly");
    }
    info.flags = wrap_s | (wrap_t << 8) | (srgb ? TEXTURE_SRGB : 0u);

    // tinygltf decodes every image to 4 channels of 8 or 16 bits; keep 8 bits
    if (img.component != 4 || (img.bits != 8 && img.bits != 16) ||
        img.image.size() < n * 4 * size_t(img.bits / 8))
      throw Error("glTF image " + std::to_string(tex.source) + " has an unexpected pixel layout");
    size_t first = scene_->texels.size();
    scene_->texels.resize(first + 4 * n);
    for (size_t i = 0; i < 4 * n; ++i)
      scene_->texels[first + i] = img.bits == 8 ? img.image[i] : img.image[2 * i + 1];  // high byte (little-endian)
    int index = int(scene_->textures.size());
    scene_->textures.push_back(info);
    texture_cache_[key] = index;
    return index;
  }

  void load_scene_roots() {
    std::vector<int> roots;
    int scene_index = model_.defaultScene >= 0 ? model_.defaultScene : 0;
    if (model_.defaultScene >= (int)model_.scenes.size())
      throw Error("glTF 'scene' " + std::to_string(model_.defaultScene) + " does not exist");
    if (scene_index < (int)model_.scenes.size()) {
      const tinygltf::Scene& s = model_.scenes[scene_index];
      roots = s.nodes;
      read_scene_extras(s.extras);
    } else {
      // No scene: render every root node
      std::vector<bool> is_child(model_.nodes.size(), false);
      for (const auto& n : model_.nodes)
        for (int c : n.children)
          if (c >= 0 && c < (int)is_child.size()) is_child[c] = true;
      for (size_t i = 0; i < model_.nodes.size(); ++i)
        if (!is_child[i]) roots.push_back(int(i));
    }
    visited_.assign(model_.nodes.size(), false);
    for (int r : roots) visit_node(r, glm::mat4(1.0f));
  }

  void read_scene_extras(const tinygltf::Value& extras) {
    if (!extras.Has("candela")) return;
    const tinygltf::Value& c = extras.Get("candela");
    if (c.Has("background")) {
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
  }

  void visit_node(int index, const glm::mat4& parent) {
    if (index < 0 || index >= (int)model_.nodes.size())
      throw Error("glTF node " + std::to_string(index) + " does not exist");
    // glTF 3.5.2: nodes form disjoint strict trees (no node has two parents, no cycles)
    if (visited_[index])
      throw Error("glTF node " + std::to_string(index) + " has two parents or is part of a cycle");
    visited_[index] = true;
    const tinygltf::Node& node = model_.nodes[index];
    glm::mat4 world = parent * local_transform(node);
    if (node.mesh >= 0) {
      if (node.mesh >= (int)model_.meshes.size())
        throw Error("glTF node " + std::to_string(index) + " refers to a missing mesh");
      load_mesh(model_.meshes[node.mesh], world);
      if (!node.weights.empty() || !model_.meshes[node.mesh].weights.empty())
        warn_.add("morph targets are not supported yet: base geometry is rendered");
    }
    if (node.camera >= 0 && !scene_->camera) load_camera(node.camera, world);
    if (node.extensions.count("KHR_lights_punctual"))
      warn_.add("KHR_lights_punctual lights are not supported yet and are ignored");
    for (int child : node.children) visit_node(child, world);
  }

  void load_camera(int index, const glm::mat4& world) {
    if (index >= (int)model_.cameras.size()) throw Error("glTF camera " + std::to_string(index) + " does not exist");
    const tinygltf::Camera& c = model_.cameras[index];
    if (c.type != "perspective") {
      warn_.add("camera type '" + c.type + "' is not supported yet; it is skipped");
      return;
    }
    CameraDesc cam;
    cam.position = glm::vec3(world * glm::vec4(0, 0, 0, 1));
    cam.forward = glm::normalize(glm::vec3(world * glm::vec4(0, 0, -1, 0)));
    cam.up = glm::normalize(glm::vec3(world * glm::vec4(0, 1, 0, 0)));
    cam.yfov = float(c.perspective.yfov);
    cam.aspect = float(c.perspective.aspectRatio);
    if (!(cam.yfov > 0.0f && cam.yfov < 3.14159f)) throw Error("glTF camera has an invalid yfov");
    scene_->camera = cam;
  }

  void load_mesh(const tinygltf::Mesh& mesh, const glm::mat4& world) {
    glm::mat3 normal_matrix = glm::transpose(glm::inverse(glm::mat3(world)));
    bool mirrored = glm::determinant(glm::mat3(world)) < 0.0f;
    for (const auto& prim : mesh.primitives) {
      if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
          prim.mode != TINYGLTF_MODE_TRIANGLE_FAN && prim.mode != -1) {
        warn_.add("point and line primitives are not rendered");
        continue;
      }
      if (!prim.targets.empty()) warn_.add("morph targets are not supported yet: base geometry is rendered");
      if (prim.extensions.count("KHR_draco_mesh_compression")) {
        warn_.add("Draco-compressed primitives (KHR_draco_mesh_compression) are not supported: they are skipped");
        continue;
      }
      auto pos_it = prim.attributes.find("POSITION");
      if (pos_it == prim.attributes.end()) {
        warn_.add("a primitive without POSITION was skipped");
        continue;
      }
      uint32_t material = prim.material >= 0 && prim.material < (int)model_.materials.size()
                              ? uint32_t(prim.material)
                              : default_material_index_;
      std::vector<float> pos = read_accessor(model_, pos_it->second, 3);
      size_t nverts = pos.size() / 3;
      std::vector<float> nrm, uv;
      if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end())
        nrm = read_accessor(model_, it->second, 3);
      const UvSet& uv_set = uv_sets_[material];
      std::string uv_name = "TEXCOORD_" + std::to_string(uv_set.texcoord);
      if (auto it = prim.attributes.find(uv_name); it != prim.attributes.end())
        uv = read_accessor(model_, it->second, 2);
      // COLOR_0: RGB or RGBA (alpha unused while surfaces are opaque), linear
      std::vector<float> col;
      int col_comps = 0;
      if (auto it = prim.attributes.find("COLOR_0"); it != prim.attributes.end()) {
        col = read_accessor(model_, it->second, 0);
        int type = model_.accessors[it->second].type;
        if (type != TINYGLTF_TYPE_VEC3 && type != TINYGLTF_TYPE_VEC4)
          throw Error("glTF COLOR_0 must be VEC3 or VEC4");
        col_comps = tinygltf::GetNumComponentsInType(type);
        for (float c : col)
          if (!(c >= 0.0f && c <= 1.0f))
            throw Error("glTF COLOR_0 values must lie in [0, 1] (integer colors must be normalized)");
        if (col.size() / col_comps != nverts)
          throw Error("glTF primitive attributes have different vertex counts");
      }
      if ((!nrm.empty() && nrm.size() != pos.size()) || (!uv.empty() && uv.size() / 2 != nverts))
        throw Error("glTF primitive attributes have different vertex counts");

      std::vector<uint32_t> indices;
      if (prim.indices >= 0) {
        indices = read_indices(model_, prim.indices);
      } else {
        for (uint32_t i = 0; i < nverts; ++i) indices.push_back(i);
      }
      for (uint32_t i : indices)
        if (i >= nverts) throw Error("glTF primitive index out of range");

      auto emit = [&](uint32_t a, uint32_t b, uint32_t c) {
        if (mirrored) std::swap(b, c);  // a mirroring transform flips the winding
        SceneTriangle t;
        uint32_t idx[3] = {a, b, c};
        for (int k = 0; k < 3; ++k) {
          uint32_t v = idx[k];
          t.p[k] = glm::vec3(world * glm::vec4(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2], 1.0f));
          t.n[k] = nrm.empty() ? glm::vec3(0.0f)
                               : normal_matrix * glm::vec3(nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2]);
          float nl = glm::length(t.n[k]);
          t.n[k] = nl > 0.0f && std::isfinite(nl) ? t.n[k] / nl : glm::vec3(0.0f);
          if (!col.empty()) {
            t.color[k] = glm::vec3(col[col_comps * v], col[col_comps * v + 1], col[col_comps * v + 2]);
            if (t.color[k] != glm::vec3(1.0f)) scene_->has_vertex_colors = true;
          }
          t.uv[k] = uv.empty() ? glm::vec2(0.0f)
                               : glm::vec2(uv_set.transform * glm::vec3(uv[2 * v], uv[2 * v + 1], 1.0f));
        }
        t.material = material;
        for (const auto& p : t.p)
          if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            throw Error("glTF mesh has non-finite vertex positions");
        if (!(glm::length(glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0])) > 0.0f)) {
          ++degenerate_;  // zero area: invisible, and it has no normal
          return;
        }
        scene_->triangles.push_back(t);
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
  }

  const tinygltf::Model& model_;
  Scene* scene_;
  Warnings warn_;
  std::map<std::pair<int, bool>, int> texture_cache_;
  std::vector<UvSet> uv_sets_;  // per material: the UVs of its base color texture
  uint32_t default_material_index_ = 0;
  size_t degenerate_ = 0;
  std::vector<bool> visited_;  // nodes reached so far
};

}  // namespace

Scene load_gltf(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error("scene file not found: " + path);
  if (fs::is_directory(path, ec)) throw Error("scene path is a directory, not a glTF file: " + path);

  tinygltf::TinyGLTF gltf;
  tinygltf::Model model;
  std::string err, warn;
  // Binary glTF starts with the magic "glTF", whatever the file is called
  char magic[4] = {};
  std::ifstream(path, std::ios::binary).read(magic, 4);
  bool binary = std::memcmp(magic, "glTF", 4) == 0;
  bool ok = binary ? gltf.LoadBinaryFromFile(&model, &err, &warn, path)
                   : gltf.LoadASCIIFromFile(&model, &err, &warn, path);
  if (!ok) {
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    throw Error("cannot load glTF scene " + path + ": " + (err.empty() ? "malformed file" : err));
  }
  Scene scene;
  if (!warn.empty()) {
    while (!warn.empty() && warn.back() == '\n') warn.pop_back();
    scene.warnings.push_back("glTF loader: " + warn);
  }
  Loader(model, &scene).load();
  return scene;
}

}  // namespace candela
