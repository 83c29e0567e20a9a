// The glTF material's parameters and texture slots, one list each; included by device_types.h
// (host and device). What is generated from them:
//   GLTF_TEXTURES  the TEX_* slot ids of Material.textures (in the order the loader reads
//                  them), their names (candela info), and the loader's reading of each
//                  extension's textureInfo (host/gltf/materials.cpp)
//   GLTF_PARAMS    GltfMaterial (below) and its layout asserts (CD_LAYOUT), MaterialDesc's
//                  fields with the specification's defaults (host/scene/scene.hpp), the
//                  loader's reading and range checks, the host copy (scene_compiler.cpp), the
//                  scene features and the Lambertian short cut (host/scene/scene.cpp), the
//                  per-hit values of GltfBsdf and the kernel's load of them
//                  (cl/bsdf/bsdf_common.cl, bsdf_gltf.cl)
//
// GLTF_TEXTURES(T): T(SLOT, name, extension, key, srgb). extension CORE: read by hand (the core
// material's textures); else the textureInfo `key` of `extension`, sRGB-encoded if srgb.
// One entry each, wrapped after its extension where long:
// clang-format off
#define GLTF_TEXTURES(T)                                                                                               \
  T(TEX_BASE_COLOR, "base colour", CORE, baseColorTexture, 1)                                                          \
  T(TEX_METALLIC_ROUGHNESS, "metallic-roughness", CORE, metallicRoughnessTexture, 0) /* B metallic, G roughness */     \
  T(TEX_NORMAL, "normal", CORE, normalTexture, 0)                                                                      \
  T(TEX_EMISSION, "emission", CORE, emissiveTexture, 1)                                                                \
  T(TEX_SPECULAR, "specular", KHR_materials_specular, specularTexture, 0)                                    /* A */   \
  T(TEX_SPECULAR_COLOR, "specular colour", KHR_materials_specular, specularColorTexture, 1)                /* RGB */   \
  T(TEX_TRANSMISSION, "transmission", KHR_materials_transmission, transmissionTexture, 0)                    /* R */   \
  T(TEX_CLEARCOAT, "clearcoat", KHR_materials_clearcoat, clearcoatTexture, 0)                                /* R */   \
  T(TEX_CLEARCOAT_ROUGHNESS, "clearcoat roughness", KHR_materials_clearcoat, clearcoatRoughnessTexture, 0)   /* G */   \
  T(TEX_CLEARCOAT_NORMAL, "clearcoat normal", KHR_materials_clearcoat, clearcoatNormalTexture, 0)                      \
  T(TEX_ANISOTROPY, "anisotropy", KHR_materials_anisotropy, anisotropyTexture, 0) /* RG direction, B strength */       \
  T(TEX_SHEEN_COLOR, "sheen colour", KHR_materials_sheen, sheenColorTexture, 1)                            /* RGB */   \
  T(TEX_SHEEN_ROUGHNESS, "sheen roughness", KHR_materials_sheen, sheenRoughnessTexture, 0)                   /* A */   \
  T(TEX_DIFFUSE_TRANSMISSION, "diffuse transmission", KHR_materials_diffuse_transmission,                              \
    diffuseTransmissionTexture, 0) /* A */                                                                             \
  T(TEX_DIFFUSE_TRANSMISSION_COLOR, "diffuse transmission colour", KHR_materials_diffuse_transmission,                 \
    diffuseTransmissionColorTexture, 1) /* RGB */                                                                      \
  T(TEX_IRIDESCENCE, "iridescence", KHR_materials_iridescence, iridescenceTexture, 0)                        /* R */   \
  T(TEX_IRIDESCENCE_THICKNESS, "iridescence thickness", KHR_materials_iridescence,                                     \
    iridescenceThicknessTexture, 0) /* G */                                                                            \
  T(TEX_DIFFUSE_ROUGHNESS, "diffuse roughness", KHR_materials_diffuse_roughness, diffuseRoughnessTexture, 0) /* R */
// clang-format on

// GLTF_PARAMS(P): P(_, name, n, default, lo, hi, extension, key, slot, load, feature, role), a
// factor of n floats (1 or 3, a colour); `_` passes GLTF_PARAM_LIST(P, X)'s X through:
//   name, n, default   GltfMaterial.name (float, or float[3]) and MaterialDesc.name (float or
//                      glm::vec3), default the glTF specification's
//   lo, hi             its valid range, checked by the loader (each channel)
//   extension, key     read from the material's `extension` object, member `key`; CORE: read
//                      by hand (host/gltf/materials.cpp)
//   slot, load         the kernel's per-hit value: GltfBsdf.name = factor x
//                      bsdf_texture(slot).load for load x, y, z, w (a float) or xyz (a float3),
//                      the factor alone for load factor (slot _); load _: no per-hit value,
//                      what uses the factor reads it from GltfMaterial
//   feature            the CD_FEATURE_* macro the per-hit value is compiled in with (1: always)
//   role               LOBE: nonzero adds a component beyond the Lambertian base (a material
//                      whose LOBE factors are all 0 shades as MATERIAL_DIFFUSE) and turns
//                      `feature` on; MODIFIER: nonzero turns `feature` on; PLAIN: neither
// GltfMaterial lays the list out in order, a float per word, padded to 16 bytes.
// One entry each, wrapped after its range where long:
// clang-format off
#define GLTF_PARAM_LIST(P, X)                                                                                          \
  P(X, ior, 1, 1.5f, 0.0f, 10.0f, KHR_materials_ior, ior, _, _, 1, PLAIN)                                              \
  P(X, metallic, 1, 1.0f, 0.0f, 1.0f, CORE, metallicFactor, TEX_METALLIC_ROUGHNESS, z, 1, LOBE)                        \
  P(X, roughness, 1, 1.0f, 0.0f, 1.0f, CORE, roughnessFactor, _, _, 1, PLAIN)                                          \
  P(X, transmission, 1, 0.0f, 0.0f, 1.0f,                                                                              \
    KHR_materials_transmission, transmissionFactor, TEX_TRANSMISSION, x, 1, LOBE)                                      \
  P(X, specular_color, 3, 1.0f, 0.0f, 1e6f, KHR_materials_specular, specularColorFactor, _, _, 1, PLAIN)               \
  P(X, specular, 1, 1.0f, 0.0f, 1.0f, KHR_materials_specular, specularFactor, _, _, 1, LOBE)                           \
  P(X, clearcoat, 1, 0.0f, 0.0f, 1.0f, KHR_materials_clearcoat, clearcoatFactor, TEX_CLEARCOAT, x, 1, LOBE)            \
  P(X, clearcoat_roughness, 1, 0.0f, 0.0f, 1.0f, KHR_materials_clearcoat, clearcoatRoughnessFactor, _, _, 1, PLAIN)    \
  P(X, anisotropy_strength, 1, 0.0f, 0.0f, 1.0f,                                                                       \
    KHR_materials_anisotropy, anisotropyStrength, _, _, CD_FEATURE_ANISOTROPY, MODIFIER)                               \
  P(X, anisotropy_rotation, 1, 0.0f, -INFINITY, INFINITY,                                                              \
    KHR_materials_anisotropy, anisotropyRotation, _, _, 1, PLAIN)                                                      \
  P(X, sheen_color, 3, 0.0f, 0.0f, 1.0f,                                                                               \
    KHR_materials_sheen, sheenColorFactor, TEX_SHEEN_COLOR, xyz, CD_FEATURE_SHEEN, LOBE)                               \
  P(X, sheen_roughness, 1, 0.0f, 0.0f, 1.0f,                                                                           \
    KHR_materials_sheen, sheenRoughnessFactor, TEX_SHEEN_ROUGHNESS, w, CD_FEATURE_SHEEN, PLAIN)                        \
  P(X, diffuse_transmission_color, 3, 1.0f, 0.0f, 1.0f,                                                                \
    KHR_materials_diffuse_transmission, diffuseTransmissionColorFactor,                                                \
    TEX_DIFFUSE_TRANSMISSION_COLOR, xyz, CD_FEATURE_DIFFUSE_TRANSMISSION, PLAIN)                                       \
  P(X, diffuse_transmission, 1, 0.0f, 0.0f, 1.0f,                                                                      \
    KHR_materials_diffuse_transmission, diffuseTransmissionFactor,                                                     \
    TEX_DIFFUSE_TRANSMISSION, w, CD_FEATURE_DIFFUSE_TRANSMISSION, LOBE)                                                \
  P(X, clearcoat_normal_scale, 1, 1.0f, -INFINITY, INFINITY, CORE, scale, _, _, 1, PLAIN)                              \
  P(X, dispersion, 1, 0.0f, 0.0f, 1e6f, KHR_materials_dispersion, dispersion, _, _, CD_FEATURE_DISPERSION, MODIFIER)   \
  P(X, diffuse_roughness, 1, 0.0f, 0.0f, 1.0f,                                                                         \
    KHR_materials_diffuse_roughness, diffuseRoughnessFactor,                                                           \
    TEX_DIFFUSE_ROUGHNESS, x, CD_FEATURE_DIFFUSE_ROUGHNESS, LOBE)                                                      \
  P(X, iridescence, 1, 0.0f, 0.0f, 1.0f,                                                                               \
    KHR_materials_iridescence, iridescenceFactor, TEX_IRIDESCENCE, x, CD_FEATURE_IRIDESCENCE, MODIFIER)                \
  P(X, iridescence_ior, 1, 1.3f, 1.0f, 10.0f,                                                                          \
    KHR_materials_iridescence, iridescenceIor, _, factor, CD_FEATURE_IRIDESCENCE, PLAIN)                               \
  P(X, iridescence_thickness_min, 1, 100.0f, 0.0f, 1e5f,                                                               \
    KHR_materials_iridescence, iridescenceThicknessMinimum, _, _, 1, PLAIN)                                            \
  P(X, iridescence_thickness_max, 1, 400.0f, 0.0f, 1e5f,                                                               \
    KHR_materials_iridescence, iridescenceThicknessMaximum, _, _, 1, PLAIN)
// clang-format on
#define GLTF_PARAMS(P) GLTF_PARAM_LIST(P, _)

// Texture slots of a material (Material.textures), TEX_SLOTS of them
#define GLTF_TEXTURE_ID(slot, name, extension, key, srgb) slot,
enum { GLTF_TEXTURES(GLTF_TEXTURE_ID) TEX_SLOTS };
#undef GLTF_TEXTURE_ID

// Each parameter's first word in GltfMaterial (GLTF_WORD_name), and the words they take
#define GLTF_PARAM_WORD(_, name, n, value, lo, hi, extension, key, slot, load, feature, role) \
  GLTF_WORD_##name, GLTF_LAST_WORD_##name = GLTF_WORD_##name + (n)-1,
enum { GLTF_PARAMS(GLTF_PARAM_WORD) GLTF_PARAM_WORDS };
#undef GLTF_PARAM_WORD
#define GLTF_MATERIAL_BYTES (4 * (GLTF_PARAM_WORDS + 4 - GLTF_PARAM_WORDS % 4))

// Parameters of a MATERIAL_GLTF material: GLTF_PARAMS in order; factors multiply their
// texture slots
#define GLTF_DECLARE_1(name) float name;
#define GLTF_DECLARE_3(name) float name[3];
#define GLTF_DECLARE_PARAM(_, name, n, value, lo, hi, extension, key, slot, load, feature, role) GLTF_DECLARE_##n(name)
typedef struct {
  GLTF_PARAMS(GLTF_DECLARE_PARAM)
  float pad[4 - GLTF_PARAM_WORDS % 4];
} GltfMaterial;
#undef GLTF_DECLARE_PARAM

// Its layout asserts (CD_LAYOUT): its size and each parameter's offset
#define GLTF_LAYOUT_FIELD(FIELD, name, n, value, lo, hi, extension, key, slot, load, feature, role) \
  FIELD(GltfMaterial, name, 4 * GLTF_WORD_##name)
#define GLTF_MATERIAL_LAYOUT(SIZE, FIELD) \
  SIZE(GltfMaterial, GLTF_MATERIAL_BYTES) GLTF_PARAM_LIST(GLTF_LAYOUT_FIELD, FIELD)

// CD_IF(flag)(text): text where flag (a macro defined as 0 or 1) is 1
#define CD_IF(flag) CD_IF_(flag)
#define CD_IF_(flag) CD_IF_##flag
#define CD_IF_0(text)
#define CD_IF_1(text) text
