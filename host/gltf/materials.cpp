// glTF materials: the core metallic-roughness material, one reader per KHR_materials_*
// extension, candela's conductor extras, and the medium a closed surface holds.
#include <algorithm>
#include <cmath>

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

void read_ior(const tinygltf::Material& gm, MaterialDesc* m) {
  m->ior = float(number_or(extension(gm, "KHR_materials_ior"), "ior", -1, 1.5));
}

void read_specular(ReadContext& ctx, const tinygltf::Material& gm, MaterialDesc* m) {
  const tinygltf::Value& spec = extension(gm, "KHR_materials_specular");
  m->specular = float(number_or(spec, "specularFactor", -1, 1.0));
  for (int c = 0; c < 3; ++c) m->specular_color[c] = float(number_or(spec, "specularColorFactor", c, 1.0));
  set_texture_slot(ctx, m, TEX_SPECULAR, spec, "specularTexture", false);
  set_texture_slot(ctx, m, TEX_SPECULAR_COLOR, spec, "specularColorTexture", true);
}

void read_transmission(ReadContext& ctx, const tinygltf::Material& gm, MaterialDesc* m) {
  const tinygltf::Value& tr = extension(gm, "KHR_materials_transmission");
  m->transmission = float(number_or(tr, "transmissionFactor", -1, 0.0));
  set_texture_slot(ctx, m, TEX_TRANSMISSION, tr, "transmissionTexture", false);
}

// KHR_materials_volume's thickness: a solid or a thin sheet (its attenuation: read_interior)
void read_volume(ReadContext& ctx, const tinygltf::Material& gm, MaterialDesc* m) {
  const tinygltf::Value& vol = extension(gm, "KHR_materials_volume");
  m->thin_walled = !(number_or(vol, "thicknessFactor", -1, 0.0) > 0.0);
  if (vol.Has("thicknessTexture"))
    ctx.warn.add("KHR_materials_volume thicknessTexture is not used: a path tracer traces the real thickness");
}

void read_clearcoat(ReadContext& ctx, const tinygltf::Material& gm, MaterialDesc* m) {
  const tinygltf::Value& cc = extension(gm, "KHR_materials_clearcoat");
  m->clearcoat = float(number_or(cc, "clearcoatFactor", -1, 0.0));
  m->clearcoat_roughness = float(number_or(cc, "clearcoatRoughnessFactor", -1, 0.0));
  set_texture_slot(ctx, m, TEX_CLEARCOAT, cc, "clearcoatTexture", false);
  set_texture_slot(ctx, m, TEX_CLEARCOAT_ROUGHNESS, cc, "clearcoatRoughnessTexture", false);
  // The coat's own normal map (normalTextureInfo: texCoord, scale, KHR_texture_transform);
  // without it the coat has the unmapped normal, whatever the base's normalTexture
  set_texture_slot(ctx, m, TEX_CLEARCOAT_NORMAL, cc, "clearcoatNormalTexture", false);
  if (cc.Has("clearcoatNormalTexture"))
    m->clearcoat_normal_scale = float(number_or(cc.Get("clearcoatNormalTexture"), "scale", -1, 1.0));
}

void read_anisotropy(ReadContext& ctx, const tinygltf::Material& gm, MaterialDesc* m) {
  const tinygltf::Value& an = extension(gm, "KHR_materials_anisotropy");
  m->anisotropy_strength = float(number_or(an, "anisotropyStrength", -1, 0.0));
  m->anisotropy_rotation = float(number_or(an, "anisotropyRotation", -1, 0.0));
  set_texture_slot(ctx, m, TEX_ANISOTROPY, an, "anisotropyTexture", false);
}

// KHR_materials_sheen: colour (sRGB texture RGB) and roughness (texture A)
void read_sheen(ReadContext& ctx, const tinygltf::Material& gm, MaterialDesc* m) {
  const tinygltf::Value& sh = extension(gm, "KHR_materials_sheen");
  for (int c = 0; c < 3; ++c) m->sheen_color[c] = float(number_or(sh, "sheenColorFactor", c, 0.0));
  m->sheen_roughness = float(number_or(sh, "sheenRoughnessFactor", -1, 0.0));
  set_texture_slot(ctx, m, TEX_SHEEN_COLOR, sh, "sheenColorTexture", true);
  set_texture_slot(ctx, m, TEX_SHEEN_ROUGHNESS, sh, "sheenRoughnessTexture", false);
}

// KHR_materials_dispersion: 20 / Abbe number, acting on the volume's refraction
void read_dispersion(const tinygltf::Material& gm, MaterialDesc* m) {
  m->dispersion = float(number_or(extension(gm, "KHR_materials_dispersion"), "dispersion", -1, 0.0));
}

// KHR_materials_diffuse_transmission: the factor (texture A) and the colour (sRGB texture RGB)
void read_diffuse_transmission(ReadContext& ctx, const tinygltf::Material& gm, MaterialDesc* m) {
  const tinygltf::Value& dt = extension(gm, "KHR_materials_diffuse_transmission");
  m->diffuse_transmission = float(number_or(dt, "diffuseTransmissionFactor", -1, 0.0));
  for (int c = 0; c < 3; ++c)
    m->diffuse_transmission_color[c] = float(number_or(dt, "diffuseTransmissionColorFactor", c, 1.0));
  set_texture_slot(ctx, m, TEX_DIFFUSE_TRANSMISSION, dt, "diffuseTransmissionTexture", false);
  set_texture_slot(ctx, m, TEX_DIFFUSE_TRANSMISSION_COLOR, dt, "diffuseTransmissionColorTexture", true);
}

// KHR_materials_iridescence: the film's factor (texture R), index, and thickness from minimum
// to maximum (texture G; without it the maximum)
void read_iridescence(ReadContext& ctx, const tinygltf::Material& gm, MaterialDesc* m) {
  const tinygltf::Value& ir = extension(gm, "KHR_materials_iridescence");
  m->iridescence = float(number_or(ir, "iridescenceFactor", -1, 0.0));
  m->iridescence_ior = float(number_or(ir, "iridescenceIor", -1, 1.3));
  m->iridescence_thickness_min = float(number_or(ir, "iridescenceThicknessMinimum", -1, 100.0));
  m->iridescence_thickness_max = float(number_or(ir, "iridescenceThicknessMaximum", -1, 400.0));
  set_texture_slot(ctx, m, TEX_IRIDESCENCE, ir, "iridescenceTexture", false);
  set_texture_slot(ctx, m, TEX_IRIDESCENCE_THICKNESS, ir, "iridescenceThicknessTexture", false);
}

// KHR_materials_diffuse_roughness: the diffuse base's roughness (texture R), shaded by the
// energy-preserving Oren-Nayar lobe (EON) of OpenPBR
void read_diffuse_roughness(ReadContext& ctx, const tinygltf::Material& gm, MaterialDesc* m) {
  const tinygltf::Value& dr = extension(gm, "KHR_materials_diffuse_roughness");
  m->diffuse_roughness = float(number_or(dr, "diffuseRoughnessFactor", -1, 0.0));
  set_texture_slot(ctx, m, TEX_DIFFUSE_ROUGHNESS, dr, "diffuseRoughnessTexture", false);
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

void check_ranges(const std::string& name, MaterialDesc* m) {
  auto in = [&](float v, float lo, float hi, const char* what) {
    if (!(v >= lo && v <= hi))
      throw Error(name + ": " + what + " must lie in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  };
  for (int c = 0; c < 4; ++c) in(m->base_color[c], 0.0f, 1.0f, "baseColorFactor");
  in(m->metallic, 0.0f, 1.0f, "metallicFactor");
  in(m->roughness, 0.0f, 1.0f, "roughnessFactor");
  in(m->transmission, 0.0f, 1.0f, "transmissionFactor");
  in(m->specular, 0.0f, 1.0f, "specularFactor");
  in(m->clearcoat, 0.0f, 1.0f, "clearcoatFactor");
  in(m->clearcoat_roughness, 0.0f, 1.0f, "clearcoatRoughnessFactor");
  in(m->anisotropy_strength, 0.0f, 1.0f, "anisotropyStrength");
  in(m->sheen_roughness, 0.0f, 1.0f, "sheenRoughnessFactor");
  in(m->diffuse_transmission, 0.0f, 1.0f, "diffuseTransmissionFactor");
  in(m->diffuse_roughness, 0.0f, 1.0f, "diffuseRoughnessFactor");
  in(m->iridescence, 0.0f, 1.0f, "iridescenceFactor");
  in(m->iridescence_ior, 1.0f, 10.0f, "iridescenceIor");
  in(m->iridescence_thickness_min, 0.0f, 1e5f, "iridescenceThicknessMinimum");
  in(m->iridescence_thickness_max, 0.0f, 1e5f, "iridescenceThicknessMaximum");
  in(m->ior, 0.0f, 10.0f, "ior");
  in(m->dispersion, 0.0f, 1e6f, "dispersion");
  for (int c = 0; c < 3; ++c) {
    in(m->specular_color[c], 0.0f, 1e6f, "specularColorFactor");
    in(m->sheen_color[c], 0.0f, 1.0f, "sheenColorFactor");
    in(m->diffuse_transmission_color[c], 0.0f, 1.0f, "diffuseTransmissionColorFactor");
    if (m->type == MATERIAL_CONDUCTOR) {
      in(m->conductor_eta[c], 0.0f, 100.0f, "conductor eta");
      in(m->conductor_k[c], 0.0f, 100.0f, "conductor k");
    }
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
  read_ior(gm, &m);
  read_specular(ctx, gm, &m);
  read_transmission(ctx, gm, &m);
  read_volume(ctx, gm, &m);
  read_clearcoat(ctx, gm, &m);
  read_anisotropy(ctx, gm, &m);
  read_sheen(ctx, gm, &m);
  read_diffuse_transmission(ctx, gm, &m);
  read_dispersion(gm, &m);
  read_iridescence(ctx, gm, &m);
  read_diffuse_roughness(ctx, gm, &m);
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
