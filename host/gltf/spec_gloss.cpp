// KHR_materials_pbrSpecularGlossiness converted to the metallic-roughness material with
// Khronos' published formulas (the extension's "convert-between-workflows" example): metallic
// solves for the dielectric F0 of 0.04 from the perceived brightness of diffuse and specular,
// base colour blends the colours both imply by metallic², roughness = 1 − glossiness.
// Textures are converted texel by texel into new base-colour and metallic-roughness textures.
#include <algorithm>
#include <cmath>

#include "base/error.hpp"
#include "gltf/reader.hpp"

namespace candela::gltf {
namespace {

constexpr const char* kExtension = "KHR_materials_pbrSpecularGlossiness";
constexpr float kDielectricF0 = 0.04f;
constexpr float kEpsilon = 1e-6f;

struct MetalRough {
  glm::vec3 base;
  float metallic;
};

float perceived_brightness(const glm::vec3& c) {
  return std::sqrt(0.299f * c.r * c.r + 0.587f * c.g * c.g + 0.114f * c.b * c.b);
}

// The metallic for which the metal-rough material reflects `specular` over a dielectric F0
// of 0.04: a root of a·m² + b·m + c
float solve_metallic(float diffuse, float specular, float one_minus_specular_strength) {
  if (specular < kDielectricF0) return 0.0f;
  float a = kDielectricF0;
  float b = diffuse * one_minus_specular_strength / (1.0f - kDielectricF0) + specular - 2.0f * kDielectricF0;
  float c = kDielectricF0 - specular;
  float d = std::max(b * b - 4.0f * a * c, 0.0f);
  return std::clamp((-b + std::sqrt(d)) / (2.0f * a), 0.0f, 1.0f);
}

MetalRough convert(const glm::vec3& diffuse, const glm::vec3& specular) {
  float one_minus_strength = 1.0f - std::max({specular.r, specular.g, specular.b});
  float metallic = solve_metallic(perceived_brightness(diffuse), perceived_brightness(specular), one_minus_strength);
  glm::vec3 from_diffuse =
      diffuse * (one_minus_strength / (1.0f - kDielectricF0) / std::max(1.0f - metallic, kEpsilon));
  glm::vec3 from_specular = (specular - glm::vec3(kDielectricF0 * (1.0f - metallic))) / std::max(metallic, kEpsilon);
  glm::vec3 base = glm::mix(from_diffuse, from_specular, metallic * metallic);
  return {glm::clamp(base, 0.0f, 1.0f), metallic};
}

// Texel (x, y) as linear RGBA (sRGB colour decoded; alpha is linear)
glm::vec4 texel(const TextureDesc& t, int x, int y) {
  size_t i = 4 * (size_t(y) * size_t(t.width) + size_t(x));
  if (!t.rgba8.empty()) {
    glm::vec4 c(t.rgba8[i] / 255.0f, t.rgba8[i + 1] / 255.0f, t.rgba8[i + 2] / 255.0f, t.rgba8[i + 3] / 255.0f);
    if (t.srgb)
      for (int k = 0; k < 3; ++k) c[k] = dev::srgb_to_linear(c[k]);
    return c;
  }
  return glm::vec4(t.rgbaf[i], t.rgbaf[i + 1], t.rgbaf[i + 2], t.rgbaf[i + 3]);
}

// The texel nearest to (u, v) in [0, 1]² of the image, or `fallback` without one
glm::vec4 lookup(const TextureDesc* t, float u, float v, glm::vec4 fallback) {
  if (!t) return fallback;
  int x = std::min(int(u * float(t->width)), t->width - 1), y = std::min(int(v * float(t->height)), t->height - 1);
  return texel(*t, x, y);
}

uint8_t unorm8(float v) { return uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

float linear_to_srgb(float c) { return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f; }

// The extension's two textures, decoded (either may be missing)
struct SpecGlossTextures {
  TextureSlot diffuse_slot, specular_slot;  // index: the glTF texture, or -1
  TextureDesc diffuse, specular;
  bool has_diffuse = false, has_specular = false;
};

bool usable_slot(ReadContext& ctx, const TextureSlot& slot) {
  if (slot.index < 0) return false;
  if (slot.texcoord == 0 || slot.texcoord == 1) return true;
  ctx.warn.add("textures on TEXCOORD_" + std::to_string(slot.texcoord) +
               " are not supported (only TEXCOORD_0 and TEXCOORD_1): the texture is ignored");
  return false;
}

SpecGlossTextures read_textures(ReadContext& ctx, const tinygltf::Value& ext) {
  SpecGlossTextures t;
  t.diffuse_slot = texture_info(ext, "diffuseTexture");
  t.specular_slot = texture_info(ext, "specularGlossinessTexture");
  t.has_diffuse = usable_slot(ctx, t.diffuse_slot) && decode_texture(ctx, t.diffuse_slot.index, true, &t.diffuse);
  t.has_specular = usable_slot(ctx, t.specular_slot) && decode_texture(ctx, t.specular_slot.index, true, &t.specular);
  return t;
}

// New base-colour (sRGB) and metallic-roughness textures on the texels of the larger of the
// two textures: each converts the diffuse and specular-glossiness texels at its centre, times
// the factors. When the two use different texture coordinates only the diffuse texture is
// converted (the specular-glossiness one's factors alone count).
void bake(ReadContext& ctx, const SpecGlossTextures& t, const glm::vec4& diffuse_factor,
          const glm::vec3& specular_factor, float glossiness_factor, MaterialDesc* m) {
  bool use_diffuse = t.has_diffuse, use_specular = t.has_specular;
  if (use_diffuse && use_specular &&
      !(t.diffuse_slot.texcoord == t.specular_slot.texcoord && t.diffuse_slot.transform == t.specular_slot.transform)) {
    ctx.warn.add(
        "KHR_materials_pbrSpecularGlossiness: diffuseTexture and specularGlossinessTexture use different texture "
        "coordinates; the specular-glossiness texture is left out of the conversion");
    use_specular = false;
  }
  bool grid_is_diffuse = use_diffuse && !(use_specular && t.specular.texels() > t.diffuse.texels());
  const TextureDesc& grid = grid_is_diffuse ? t.diffuse : t.specular;
  const TextureSlot& slot = grid_is_diffuse ? t.diffuse_slot : t.specular_slot;
  const TextureDesc* diffuse = use_diffuse ? &t.diffuse : nullptr;
  const TextureDesc* specular = use_specular ? &t.specular : nullptr;
  TextureDesc base, mr;
  for (TextureDesc* out : {&base, &mr}) {
    out->width = grid.width;
    out->height = grid.height;
    out->wrap_s = grid.wrap_s;
    out->wrap_t = grid.wrap_t;
    out->nearest = grid.nearest;
    out->rgba8.resize(4 * grid.texels());
  }
  base.srgb = true;
  for (int y = 0; y < grid.height; ++y)
    for (int x = 0; x < grid.width; ++x) {
      float u = (float(x) + 0.5f) / float(grid.width), v = (float(y) + 0.5f) / float(grid.height);
      glm::vec4 d = diffuse_factor * lookup(diffuse, u, v, glm::vec4(1.0f));
      glm::vec4 sg = lookup(specular, u, v, glm::vec4(1.0f));
      MetalRough c = convert(glm::vec3(d), specular_factor * glm::vec3(sg));
      size_t i = 4 * (size_t(y) * size_t(grid.width) + size_t(x));
      for (int k = 0; k < 3; ++k) base.rgba8[i + size_t(k)] = unorm8(linear_to_srgb(c.base[k]));
      base.rgba8[i + 3] = unorm8(d.a);
      mr.rgba8[i] = 0;
      mr.rgba8[i + 1] = unorm8(1.0f - glossiness_factor * sg.a);
      mr.rgba8[i + 2] = unorm8(c.metallic);
      mr.rgba8[i + 3] = 255;
    }
  m->base_color = glm::vec4(1.0f);
  m->metallic = m->roughness = 1.0f;
  for (auto [slot_index, desc] : {std::make_pair(TEX_BASE_COLOR, &base), std::make_pair(TEX_METALLIC_ROUGHNESS, &mr)}) {
    m->textures[slot_index] = slot;
    m->textures[slot_index].index = int(ctx.scene.textures.size());
    ctx.scene.textures.push_back(std::move(*desc));
  }
}

}  // namespace

bool read_specular_glossiness(ReadContext& ctx, const tinygltf::Material& gm, MaterialDesc* m) {
  auto it = gm.extensions.find(kExtension);
  if (it == gm.extensions.end()) return false;
  const tinygltf::Value& ext = it->second;
  glm::vec4 diffuse_factor;
  glm::vec3 specular_factor;
  for (int c = 0; c < 4; ++c) diffuse_factor[c] = float(number_or(ext, "diffuseFactor", c, 1.0));
  for (int c = 0; c < 3; ++c) specular_factor[c] = float(number_or(ext, "specularFactor", c, 1.0));
  float glossiness = float(number_or(ext, "glossinessFactor", -1, 1.0));
  auto in_unit = [](float v) { return v >= 0.0f && v <= 1.0f; };
  bool ok = in_unit(glossiness);
  for (int c = 0; c < 4; ++c) ok = ok && in_unit(diffuse_factor[c]) && (c == 3 || in_unit(specular_factor[c]));
  if (!ok) throw Error(std::string(kExtension) + ": factors must lie in [0, 1]");
  SpecGlossTextures t = read_textures(ctx, ext);
  if (t.has_diffuse || t.has_specular) {
    bake(ctx, t, diffuse_factor, specular_factor, glossiness, m);
    return true;
  }
  MetalRough c = convert(glm::vec3(diffuse_factor), specular_factor);
  m->base_color = glm::vec4(c.base, diffuse_factor.a);
  m->metallic = c.metallic;
  m->roughness = 1.0f - glossiness;
  return true;
}

}  // namespace candela::gltf
