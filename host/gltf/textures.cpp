// glTF textures: a material slot's texture, its image decoded once per colour space, its
// sampler (wrap modes, magFilter) and KHR_texture_transform.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "base/error.hpp"
#include "gltf/reader.hpp"

namespace candela::gltf {
namespace {

// KHR_texture_transform: uv' = T(offset) * R(rotation) * S(scale) * uv, and its texCoord
void read_texture_transform(const tinygltf::Value& ext, TextureSlot* ref) {
  float ox = float(number_or(ext, "offset", 0, 0.0)), oy = float(number_or(ext, "offset", 1, 0.0));
  float r = float(number_or(ext, "rotation", -1, 0.0));
  float sx = float(number_or(ext, "scale", 0, 1.0)), sy = float(number_or(ext, "scale", 1, 1.0));
  float c = std::cos(r), s = std::sin(r);
  // Column-major: columns are the images of (1,0,0), (0,1,0), (0,0,1)
  ref->transform =
      glm::mat3(glm::vec3(c * sx, -s * sx, 0.0f), glm::vec3(s * sy, c * sy, 0.0f), glm::vec3(ox, oy, 1.0f));
  if (ext.Has("texCoord")) ref->texcoord = int(number_or(ext, "texCoord", -1, ref->texcoord));
}

void read_sampler(const tinygltf::Model& model, int sampler_index, TextureDesc* t) {
  if (sampler_index < 0 || sampler_index >= (int)model.samplers.size()) return;
  const tinygltf::Sampler& sampler = model.samplers[size_t(sampler_index)];
  auto mode = [](int w) {
    return w == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE     ? WRAP_CLAMP
           : w == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT ? WRAP_MIRROR
                                                        : WRAP_REPEAT;
  };
  t->wrap_s = mode(sampler.wrapS);
  t->wrap_t = mode(sampler.wrapT);
  // Without mip-maps magFilter picks every lookup (nearest or bilinear); minFilter is unused
  t->nearest = sampler.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST;
}

// tinygltf decodes every image to 4 channels of 8 or 16 bits: 8-bit images stay RGBA8
// (sRGB decoded in the kernel), 16-bit ones become float texels, decoded here. Returns
// why the image cannot be used, or "".
std::string decode_image(const ReadContext& ctx, int source, bool srgb, TextureDesc* out) {
  const tinygltf::Image& img = ctx.model.images[size_t(source)];
  if (img.width <= 0 || img.height <= 0 || img.image.empty()) {
    if (auto it = ctx.image_errors.find(source); it != ctx.image_errors.end()) return it->second;
    return img.uri.empty() ? "could not be decoded" : "('" + img.uri + "') could not be read or decoded";
  }
  TextureDesc& t = *out;
  t = TextureDesc();
  t.width = img.width;
  t.height = img.height;
  size_t n = t.texels();
  if (img.component != 4 || (img.bits != 8 && img.bits != 16) || img.image.size() < n * 4 * size_t(img.bits / 8))
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

// The image of EXT_texture_webp (which a client that reads WebP prefers), else the core
// `source`, else the image of KHR_texture_basisu or MSFT_texture_dds, the first that
// decodes; false with the first image's reason when none does
bool decode_source(const ReadContext& ctx, const tinygltf::Texture& tex, bool srgb, TextureDesc* t, std::string* why) {
  std::vector<int> sources;
  auto add_extension_source = [&](const char* ext) {
    if (auto it = tex.extensions.find(ext); it != tex.extensions.end())
      if (double source = number_or(it->second, "source", -1, -1.0); source >= 0.0)
        sources.push_back(int(std::min(source, 1e9)));
  };
  add_extension_source("EXT_texture_webp");
  if (tex.source >= 0) sources.push_back(tex.source);
  for (const char* ext : {"KHR_texture_basisu", "MSFT_texture_dds"}) add_extension_source(ext);
  for (int source : sources) {
    if (source >= (int)ctx.model.images.size()) throw Error("glTF image " + std::to_string(source) + " does not exist");
    std::string reason = decode_image(ctx, source, srgb, t);
    if (reason.empty()) return true;
    if (why->empty()) *why = "image " + std::to_string(source) + " " + reason;
  }
  if (why->empty()) *why = "it has no source";
  return false;
}

}  // namespace

bool decode_texture(ReadContext& ctx, int gltf_texture, bool srgb, TextureDesc* t) {
  if (gltf_texture < 0 || gltf_texture >= (int)ctx.model.textures.size())
    throw Error("glTF texture " + std::to_string(gltf_texture) + " does not exist");
  const tinygltf::Texture& tex = ctx.model.textures[size_t(gltf_texture)];
  std::string why;
  if (decode_source(ctx, tex, srgb, t, &why)) {
    read_sampler(ctx.model, tex.sampler, t);
    return true;
  }
  ctx.warn.add("glTF texture " + std::to_string(gltf_texture) + " has no image candela can decode (" + why +
               "): it is ignored, as if the material had no such texture");
  return false;
}

namespace {

// Adds the glTF texture's image once, returning its index in Scene::textures (or NO_TEXTURE)
int texture_index(ReadContext& ctx, int gltf_texture, bool srgb) {
  auto key = std::make_pair(gltf_texture, srgb);
  if (auto it = ctx.textures.find(key); it != ctx.textures.end()) return it->second;
  TextureDesc t;
  bool decoded = decode_texture(ctx, gltf_texture, srgb, &t);
  int& index = ctx.textures[key];
  index = NO_TEXTURE;
  if (decoded) {
    index = int(ctx.scene.textures.size());
    ctx.scene.textures.push_back(std::move(t));
  }
  return index;
}

TextureSlot texture_ref(ReadContext& ctx, int gltf_texture, int texcoord, const tinygltf::Value* transform, bool srgb) {
  TextureSlot ref;
  ref.index = texture_index(ctx, gltf_texture, srgb);
  ref.texcoord = texcoord;
  if (transform) read_texture_transform(*transform, &ref);
  if (ref.texcoord < 0 || ref.texcoord > 1) {
    ctx.warn.add("textures on TEXCOORD_" + std::to_string(ref.texcoord) +
                 " are not supported (only TEXCOORD_0 and TEXCOORD_1): the texture is ignored");
    ref.index = NO_TEXTURE;
  }
  return ref;
}

}  // namespace

void set_texture_slot(ReadContext& ctx, MaterialDesc* m, int slot, int gltf_texture, int texcoord,
                      const tinygltf::ExtensionMap& extensions, bool srgb) {
  if (gltf_texture < 0) return;
  auto tt = extensions.find("KHR_texture_transform");
  m->textures[slot] = texture_ref(ctx, gltf_texture, texcoord, tt == extensions.end() ? nullptr : &tt->second, srgb);
}

TextureSlot texture_info(const tinygltf::Value& ext, const char* key) {
  TextureSlot ref;
  ref.index = -1;
  if (!ext.Has(key)) return ref;
  const tinygltf::Value& info = ext.Get(key);
  ref.index = int(std::clamp(number_or(info, "index", -1, -1.0), -1.0, 1e9));
  if (ref.index < 0) throw Error(std::string("glTF ") + key + " has no texture index");
  ref.texcoord = int(std::clamp(number_or(info, "texCoord", -1, 0.0), -1.0, 1e9));
  if (info.Has("extensions") && info.Get("extensions").Has("KHR_texture_transform"))
    read_texture_transform(info.Get("extensions").Get("KHR_texture_transform"), &ref);
  return ref;
}

void set_texture_slot(ReadContext& ctx, MaterialDesc* m, int slot, const tinygltf::Value& ext, const char* key,
                      bool srgb) {
  if (!ext.Has(key)) return;
  const tinygltf::Value& info = ext.Get(key);
  int index = int(number_or(info, "index", -1, -1.0));
  if (index < 0) throw Error(std::string("glTF ") + key + " has no texture index");
  const tinygltf::Value* tt = nullptr;
  if (info.Has("extensions") && info.Get("extensions").Has("KHR_texture_transform"))
    tt = &info.Get("extensions").Get("KHR_texture_transform");
  m->textures[slot] = texture_ref(ctx, index, int(number_or(info, "texCoord", -1, 0.0)), tt, srgb);
}

}  // namespace candela::gltf
