// glTF materials: the core metallic-roughness material, one reader per KHR_materials_*
// extension, candela's conductor extras, and the medium a closed surface holds.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "base/error.hpp"
#include "gltf/reader.hpp"

namespace candela::gltf {
namespace {

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

const tinygltf::Value& extension(const tinygltf::Material& gm, const char* name) {
  static const tinygltf::Value none;
  auto it = gm.extensions.find(name);
  return it == gm.extensions.end() ? none : it->second;
}

// pbrMetallicRoughness: base colour, metallic and roughness factors and textures
void read_metallic_roughness(ReadContext& ctx, const tinygltf::Material& gm, MaterialDesc* m) {
  const auto& pbr = gm.pbrMetallicRoughness;
  for (int c = 0; c < 4; ++c) m->base_color[c] = float(pbr.baseColorFactor[c]);
  m->metallic = float(pbr.metallicFactor);
  m->roughness = float(pbr.roughnessFactor);
  set_texture_slot(ctx, m, TEX_BASE_COLOR, pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                   pbr.baseColorTexture.extensions, true);
  set_texture_slot(ctx, m, TEX_METALLIC_ROUGHNESS, pbr.metallicRoughnessTexture.index,
                   pbr.metallicRoughnessTexture.texCoord, pbr.metallicRoughnessTexture.extensions, false);
}

void read_normal_texture(ReadContext& ctx, const tinygltf::Material& gm, MaterialDesc* m) {
  set_texture_slot(ctx, m, TEX_NORMAL, gm.normalTexture.index, gm.normalTexture.texCoord, gm.normalTexture.extensions,
                   false);
  m->normal_scale = float(gm.normalTexture.scale);
}

// emissiveTexture, emissiveFactor x KHR_materials_emissive_strength
void read_emission(ReadContext& ctx, const tinygltf::Material& gm, const std::string& name, MaterialDesc* m) {
  set_texture_slot(ctx, m, TEX_EMISSION, gm.emissiveTexture.index, gm.emissiveTexture.texCoord,
                   gm.emissiveTexture.extensions, true);
  float strength = float(number_or(extension(gm, "KHR_materials_emissive_strength"), "emissiveStrength", -1, 1.0));
  for (int c = 0; c < 3; ++c) {
    m->emission[c] = float(gm.emissiveFactor[c]) * strength;
    if (!(m->emission[c] >= 0.0f) || !std::isfinite(m->emission[c]))
      throw Error(name + " has a negative or non-finite emission (emissiveFactor x emissiveStrength)");
  }
}

void read_alpha(const tinygltf::Material& gm, MaterialDesc* m) {
  m->alpha_mode = gm.alphaMode == "MASK"    ? AlphaMode::Mask
                  : gm.alphaMode == "BLEND" ? AlphaMode::Blend
                                            : AlphaMode::Opaque;
  m->alpha_cutoff = float(gm.alphaCutoff);
}

// The factors and textures of the KHR_materials_* extensions listed in GLTF_PARAMS and
// GLTF_TEXTURES (cl/shared/gltf_params.h), in the lists' order; the CORE ones are read by hand
bool core(const char* extension) { return std::strcmp(extension, "CORE") == 0; }

void read_factor(const tinygltf::Value& ext, const char* key, float fallback, float* to) {
  *to = float(number_or(ext, key, -1, fallback));
}
void read_factor(const tinygltf::Value& ext, const char* key, float fallback, glm::vec3* to) {
  for (int c = 0; c < 3; ++c) (*to)[c] = float(number_or(ext, key, c, fallback));
}

void read_extensions(ReadContext& ctx, const tinygltf::Material& gm, MaterialDesc* m) {
#define CD_READ_PARAM(_, name, n, value, lo, hi, ext, key, ...) \
  if (!core(#ext)) read_factor(extension(gm, #ext), #key, value, &m->name);
  GLTF_PARAMS(CD_READ_PARAM)
#undef CD_READ_PARAM
#define CD_READ_TEXTURE(slot, name, ext, key, srgb) \
  if (!core(#ext)) set_texture_slot(ctx, m, slot, extension(gm, #ext), #key, srgb);
  GLTF_TEXTURES(CD_READ_TEXTURE)
#undef CD_READ_TEXTURE
  // The coat's own normal map's scale (normalTextureInfo); without the map the coat has the
  // unmapped normal, whatever the base's normalTexture
  const tinygltf::Value& cc = extension(gm, "KHR_materials_clearcoat");
  if (cc.Has("clearcoatNormalTexture"))
    m->clearcoat_normal_scale = float(number_or(cc.Get("clearcoatNormalTexture"), "scale", -1, 1.0));
}

// KHR_materials_volume's thickness: a solid or a thin sheet (its attenuation: read_interior)
void read_volume(ReadContext& ctx, const tinygltf::Material& gm, MaterialDesc* m) {
  const tinygltf::Value& vol = extension(gm, "KHR_materials_volume");
  m->thin_walled = !(number_or(vol, "thicknessFactor", -1, 0.0) > 0.0);
  if (vol.Has("thicknessTexture"))
    ctx.warn.add("KHR_materials_volume thicknessTexture is not used: a path tracer traces the real thickness");
  // KHR_materials_dispersion acts on a volume's refraction only
  if (!(m->transmission > 0.0f && !m->thin_walled)) m->dispersion = 0.0f;
}

// KHR_materials_unlit: the base colour (factor, texture, vertex colour) is the radiance seen
void read_unlit(const tinygltf::Material& gm, MaterialDesc* m) {
  m->unlit = gm.extensions.count("KHR_materials_unlit") > 0;
}

// extras.candela.conductor: a preset name or {"eta": [r, g, b], "k": [r, g, b]}
void read_conductor(const tinygltf::Value& extras, const std::string& name, MaterialDesc* m) {
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

// KHR_materials_volume's attenuation: sigma_a = -ln(attenuationColor) / attenuationDistance,
// the extension's definition, added to *md
void add_volume_absorption(const tinygltf::Material& gm, const std::string& name, MediumDesc* md) {
  const tinygltf::Value& vol = extension(gm, "KHR_materials_volume");
  double distance = number_or(vol, "attenuationDistance", -1, INFINITY);
  if (!(distance > 0.0)) throw Error(name + ": KHR_materials_volume attenuationDistance must be positive");
  for (int c = 0; c < 3; ++c) {
    double color = number_or(vol, "attenuationColor", c, 1.0);
    if (!(color >= 0.0 && color <= 1.0))
      throw Error(name + ": KHR_materials_volume attenuationColor must lie in [0, 1]");
    if (std::isfinite(distance)) md->sigma_a[c] += float(color > 0.0 ? -std::log(color) / distance : 1e30);
  }
}

// The medium inside a closed surface: KHR_materials_volume (thickness > 0, transmission)
// absorbs; extras.candela.medium adds its coefficients (scattering, emission, a grid), and
// on a material without transmission makes the surface a null boundary
void read_interior(ReadContext& ctx, const tinygltf::Material& gm, const std::string& name, MaterialDesc* m) {
  bool has_extra = gm.extras.Has("candela") && gm.extras.Get("candela").Has("medium");
  MediumDesc md;
  if (has_extra) md = read_medium(gm.extras.Get("candela").Get("medium"), name + " extras.candela.medium", ctx.folder);
  bool solid = m->transmission > 0.0f && !m->thin_walled;
  if (solid) {
    add_volume_absorption(gm, name, &md);
  } else if (has_extra && m->transmission > 0.0f) {
    ctx.warn.add(name +
                 ": a thin-walled material (no KHR_materials_volume thickness) has no interior: its medium is ignored");
    return;
  } else if (has_extra) {
    m->null_boundary = true;
  }
  bool empty = md.sigma_a == glm::vec3(0.0f) && md.sigma_s == glm::vec3(0.0f) && md.emission == glm::vec3(0.0f);
  if (!has_extra && empty) return;  // clear glass: vacuum inside
  m->medium = int(ctx.scene.media.size());
  ctx.scene.media.push_back(std::move(md));
}

bool within(float v, float lo, float hi) { return v >= lo && v <= hi; }
bool within(const glm::vec3& v, float lo, float hi) {
  return within(v.x, lo, hi) && within(v.y, lo, hi) && within(v.z, lo, hi);
}

void check_ranges(const std::string& name, MaterialDesc* m) {
  auto in = [&](const auto& v, float lo, float hi, const char* what) {
    if (!within(v, lo, hi))
      throw Error(name + ": " + what + " must lie in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  };
  for (int c = 0; c < 4; ++c) in(m->base_color[c], 0.0f, 1.0f, "baseColorFactor");
#define CD_CHECK_PARAM(_, name, n, value, lo, hi, ext, key, ...) in(m->name, lo, hi, #key);
  GLTF_PARAMS(CD_CHECK_PARAM)
#undef CD_CHECK_PARAM
  if (m->type == MATERIAL_CONDUCTOR) {
    in(m->conductor_eta, 0.0f, 100.0f, "conductor eta");
    in(m->conductor_k, 0.0f, 100.0f, "conductor k");
  }
  // ior 0 stands for an infinite index (a perfect mirror); keep the kernel's arithmetic finite
  m->ior = m->ior == 0.0f ? 1e4f : std::max(m->ior, 1.0f + 1e-4f);
}

void warn_unsupported(ReadContext& ctx, const tinygltf::Material& gm) {
  if (gm.occlusionTexture.index >= 0)
    ctx.warn.add("occlusionTexture is ignored (a path tracer computes occlusion itself)");
  for (const auto& e : gm.extensions)
    if (!supported_extension(e.first))
      ctx.warn.add("glTF extension " + e.first + " is not supported yet and is ignored");
}

// Textures are added to the scene in the order their slots are read here
MaterialDesc read_material(ReadContext& ctx, int index) {
  const tinygltf::Material& gm = ctx.model.materials[size_t(index)];
  std::string name = "material '" + (gm.name.empty() ? std::to_string(index) : gm.name) + "'";
  MaterialDesc m;
  m.name = gm.name;
  if (!read_specular_glossiness(ctx, gm, &m)) read_metallic_roughness(ctx, gm, &m);
  read_normal_texture(ctx, gm, &m);
  read_emission(ctx, gm, name, &m);
  m.double_sided = gm.doubleSided;
  read_alpha(gm, &m);
  read_extensions(ctx, gm, &m);
  read_volume(ctx, gm, &m);
  read_unlit(gm, &m);
  read_conductor(gm.extras, name, &m);
  read_interior(ctx, gm, name, &m);
  check_ranges(name, &m);
  warn_unsupported(ctx, gm);
  return m;
}

}  // namespace

void read_materials(ReadContext& ctx) {
  for (size_t i = 0; i < ctx.model.materials.size(); ++i) ctx.scene.materials.push_back(read_material(ctx, int(i)));
  ctx.scene.materials.push_back(MaterialDesc());  // glTF default: white, for primitives without one
}

}  // namespace candela::gltf
