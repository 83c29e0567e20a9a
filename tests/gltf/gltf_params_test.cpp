// The glTF material's lists (cl/shared/gltf_params.h) agree with what the host generates from
// them: every factor of GLTF_PARAMS is read from its extension's key, range-checked, and
// copied into its own words of GltfMaterial; every texture slot of GLTF_TEXTURES is read from
// its key with its encoding; every LOBE factor alone makes a material the glTF BSDF instead of
// the Lambertian short cut, and every LOBE or MODIFIER factor turns its kernel feature on. The
// device's layout of GltfMaterial is checked by tests/device/layout_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>

#include "base/error.hpp"
#include "compile/scene_compiler.hpp"
#include "gltf/gltf_loader.hpp"
#include "support/gltf_builder.hpp"

using nlohmann::json;

namespace candela::test {
namespace {

struct Param {
  const char *name, *extension, *key, *feature, *role;
  int n, word;
  float lo, hi;
};
#define CD_PARAM_ENTRY(_, name, n, value, lo, hi, ext, key, slot, load, feature, role) \
  {#name, #ext, #key, #feature, #role, n, GLTF_WORD_##name, lo, hi},
const Param kParams[] = {GLTF_PARAMS(CD_PARAM_ENTRY)};
#undef CD_PARAM_ENTRY

struct Slot {
  int slot;
  const char *extension, *key;
  bool srgb;
};
#define CD_SLOT_ENTRY(slot, name, ext, key, srgb) {slot, #ext, #key, srgb != 0},
const Slot kSlots[] = {GLTF_TEXTURES(CD_SLOT_ENTRY)};
#undef CD_SLOT_ENTRY

bool core(const char* extension) { return std::strcmp(extension, "CORE") == 0; }

// A value for parameter k, channel c: distinct for every word, inside the parameter's range
float test_value(const Param& p, int k, int c) {
  float v = (p.hi <= 1.0f ? 0.05f : 1.1f) + 0.03f * float(k) + 0.01f * float(c);
  EXPECT_TRUE(v >= p.lo && v <= p.hi) << p.name;
  return v;
}

// The quad of one material, `extensions` its extensions, a solid (a KHR_materials_volume
// thickness) so that its dispersion refracts
json quad_with(const json& extensions) {
  GltfBuilder g;
  json material = {{"extensions", extensions}};
  material["extensions"]["KHR_materials_volume"] = {{"thicknessFactor", 1.0}};
  g.add("materials", material);
  g.add_node({{"mesh", g.add_mesh({quad_primitive({{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, 0)})}});
  return g.document();
}

Scene load(const json& j) { return load_gltf_from_memory(j.dump(), ""); }

// A field of MaterialDesc by its GLTF_PARAMS name: its channels, set or read
float* field(MaterialDesc& m, const std::string& name) {
#define CD_PARAM_FIELD(_, param, ...) \
  if (name == #param) return reinterpret_cast<float*>(&m.param);
  GLTF_PARAMS(CD_PARAM_FIELD)
#undef CD_PARAM_FIELD
  return nullptr;
}

TEST(GltfParams, EveryFactorIsReadCheckedAndCopiedToItsWords) {
  json ext = json::object();
  for (int k = 0; k < int(std::size(kParams)); ++k) {
    const Param& p = kParams[k];
    if (core(p.extension)) continue;
    json value = p.n == 1 ? json(test_value(p, k, 0)) : json::array();
    for (int c = 0; p.n > 1 && c < p.n; ++c) value.push_back(test_value(p, k, c));
    ext[p.extension][p.key] = value;
  }
  Scene s = load(quad_with(ext));
  MaterialDesc& m = s.materials.at(0);
  ASSERT_EQ(m.kernel_type(), MATERIAL_GLTF);
  CompiledScene compiled = compile_scene(s);
  const dev::GltfMaterial& g = compiled.buffers.materials.at(0).params.gltf;
  const float* words = reinterpret_cast<const float*>(&g);
  EXPECT_EQ(sizeof(g) % 16, 0u);
  EXPECT_GE(sizeof(g), 4 * size_t(GLTF_PARAM_WORDS));
  for (int k = 0; k < int(std::size(kParams)); ++k) {
    const Param& p = kParams[k];
    SCOPED_TRACE(p.name);
    const float* read = field(m, p.name);
    ASSERT_NE(read, nullptr);
    for (int c = 0; c < p.n; ++c) {
      if (!core(p.extension)) {
        EXPECT_FLOAT_EQ(read[c], test_value(p, k, c)) << "read from " << p.key;
      }
      EXPECT_EQ(words[p.word + c], read[c]) << "copied to GltfMaterial word " << p.word + c;
    }
    // Out of range: one error naming the key
    if (core(p.extension) || !std::isfinite(p.lo)) continue;
    json bad = ext;
    bad[p.extension][p.key] = p.n == 1 ? json(p.lo - 1.0f) : json({p.lo - 1.0f, p.lo, p.lo});
    try {
      load(quad_with(bad));
      ADD_FAILURE() << "out of range accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(p.key), std::string::npos) << e.what();
    }
  }
}

TEST(GltfParams, EveryTextureSlotIsReadWithItsEncoding) {
  json ext = json::object();
  for (const Slot& t : kSlots)
    if (!core(t.extension)) ext[t.extension][t.key] = {{"index", 0}};
  json j = quad_with(ext);
  j["images"] = {
      {{"uri",
        "data:image/png;base64,"
        "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8BQDwAEhQGAhKmMIQAAAABJRU5ErkJggg=="}}};
  j["textures"] = {{{"source", 0}}};
  Scene s = load(j);
  const MaterialDesc& m = s.materials.at(0);
  for (const Slot& t : kSlots) {
    SCOPED_TRACE(t.key);
    if (core(t.extension)) {
      EXPECT_EQ(m.texture(t.slot).index, NO_TEXTURE);
      continue;
    }
    ASSERT_NE(m.texture(t.slot).index, NO_TEXTURE);
    EXPECT_EQ(s.textures.at(size_t(m.texture(t.slot).index)).srgb, t.srgb);
  }
}

// Each LOBE factor alone makes a material glTF-shaded; each LOBE or MODIFIER factor with a
// feature turns it on, for that material and its scene
TEST(GltfParams, LobesAndModifiersTurnOnTheirFeatures) {
  MaterialDesc lambert;
  lambert.metallic = 0.0f;
  lambert.specular = 0.0f;
  ASSERT_EQ(lambert.kernel_type(), MATERIAL_DIFFUSE);
  int lobes = 0, features = 0;
  for (const Param& p : kParams) {
    SCOPED_TRACE(p.name);
    std::string role = p.role;
    ASSERT_TRUE(role == "LOBE" || role == "MODIFIER" || role == "PLAIN");
    bool has_feature = std::strcmp(p.feature, "1") != 0;
    if (has_feature) {
      ASSERT_NE(SceneFeatures::flag(p.feature), nullptr) << "not a CD_SCENE_FEATURES macro";
    }
    MaterialDesc m = lambert;
    float* f = field(m, p.name);
    float zero[3] = {0.0f, 0.0f, 0.0f};
    std::copy(zero, zero + p.n, f);
    if (role == "LOBE") {
      EXPECT_EQ(m.kernel_type(), MATERIAL_DIFFUSE);
      f[0] = 0.5f;
      EXPECT_EQ(m.kernel_type(), MATERIAL_GLTF) << "a LOBE factor adds a component";
      ++lobes;
    }
    if (!has_feature || role == "PLAIN") continue;
    m = lambert;
    m.metallic = 1.0f;      // glTF-shaded
    m.transmission = 1.0f;  // refracting,
    m.thin_walled = false;  // through a volume (dispersion)
    f = field(m, p.name);
    std::copy(zero, zero + p.n, f);
    EXPECT_FALSE(m.needs(p.feature));
    f[0] = 0.5f;
    EXPECT_TRUE(m.needs(p.feature));
    Scene s;
    s.materials.push_back(m);
    MeshDesc mesh;
    mesh.positions = {glm::vec3(0.0f), glm::vec3(1.0f, 0.0f, 0.0f), glm::vec3(0.0f, 1.0f, 0.0f)};
    mesh.indices = {0, 1, 2};
    s.meshes.push_back(mesh);
    EXPECT_TRUE(s.features().*SceneFeatures::flag(p.feature));
    ++features;
  }
  EXPECT_GE(lobes, 7);
  EXPECT_GE(features, 6);
}

}  // namespace
}  // namespace candela::test
