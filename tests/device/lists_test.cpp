// The extension lists of cl/shared/device_types.h (CD_SCENE_FEATURES, CD_MATERIALS,
// CD_LIGHTS) and what the host generates from them agree: name tables, build options, the
// kernel's feature defaults, the feature each type needs, the compile step and light power
// of every type. tests/lint/kernel_lint_test.py checks the kernel side of the same lists.
#include <gtest/gtest.h>

#include <set>

#include "base/device_types.hpp"
#include "base/error.hpp"
#include "device/kernel_sources.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

struct ListEntry {
  unsigned id;
  std::string name, feature;
};

#define CD_LIST_ENTRY(id, name, feature) {id, #name, #feature},
const std::vector<ListEntry> kMaterials = {CD_MATERIALS(CD_LIST_ENTRY)};
const std::vector<ListEntry> kLights = {CD_LIGHTS(CD_LIST_ENTRY)};
#undef CD_LIST_ENTRY

struct FeatureEntry {
  bool SceneFeatures::*flag;
  std::string name, macro, fallback;
};

#define CD_FEATURE_ENTRY(name, macro, fallback, needs) {&SceneFeatures::name, #name, #macro, #fallback},
const std::vector<FeatureEntry> kFeatures = {CD_SCENE_FEATURES(CD_FEATURE_ENTRY)};
#undef CD_FEATURE_ENTRY

// A scene of one triangle with one material of `type`
Scene one_triangle(uint32_t type) {
  Scene s;
  MaterialDesc m;
  m.type = type;
  m.metallic = 1.0f;  // a glTF material the kernel shades as such
  s.materials.push_back(m);
  MeshDesc mesh;
  mesh.positions = {glm::vec3(0.0f), glm::vec3(1.0f, 0.0f, 0.0f), glm::vec3(0.0f, 1.0f, 0.0f)};
  mesh.indices = {0, 1, 2};
  s.meshes.push_back(mesh);
  return s;
}

}  // namespace

TEST(Lists, NameTablesFollowTheLists) {
  ASSERT_EQ(kMaterials.size(), dev::kMaterialTypeCount);
  ASSERT_EQ(kLights.size(), dev::kLightTypeCount);
  std::set<std::string> names;
  for (const ListEntry& e : kMaterials) {
    EXPECT_STREQ(dev::material_type_name(e.id), e.name.c_str());
    EXPECT_TRUE(names.insert(e.name).second) << "material type " << e.name << " listed twice";
  }
  EXPECT_EQ(dev::material_type_name(dev::kMaterialTypeCount), nullptr);
  names.clear();
  for (const ListEntry& e : kLights) {
    EXPECT_STREQ(dev::light_type_name(e.id), e.name.c_str());
    EXPECT_TRUE(names.insert(e.name).second) << "light type " << e.name << " listed twice";
  }
  EXPECT_EQ(dev::light_type_name(dev::kLightTypeCount), nullptr);
  ASSERT_EQ(std::size(dev::kSceneFeatureNames), kFeatures.size());
  EXPECT_EQ(SceneFeatures::all().names(),
            std::vector<std::string>(std::begin(dev::kSceneFeatureNames), std::end(dev::kSceneFeatureNames)));
  EXPECT_TRUE(SceneFeatures().names().empty());
}

// Each feature is one build option, one flag of covers() and one name, and nothing else
TEST(Lists, EachFeatureIsOneOptionAndOneFlag) {
  const SceneFeatures none, all = SceneFeatures::all();
  std::string off;
  for (const FeatureEntry& f : kFeatures) off += (off.empty() ? "-D" : " -D") + f.macro + "=0";
  EXPECT_EQ(none.build_options(), off);
  for (const FeatureEntry& f : kFeatures) {
    SCOPED_TRACE(f.name);
    SceneFeatures one;
    one.*f.flag = true;
    std::string want = off;
    want.replace(want.find(f.macro + "=0"), f.macro.size() + 2, f.macro + "=1");
    EXPECT_EQ(one.build_options(), want);
    EXPECT_EQ(one.names(), std::vector<std::string>{f.name});
    EXPECT_FALSE(none.covers(one));
    EXPECT_TRUE(one.covers(one) && all.covers(one) && one.covers(none));
    EXPECT_EQ(SceneFeatures::flag(f.macro), f.flag);
    EXPECT_TRUE(all.*f.flag);
  }
  EXPECT_EQ(SceneFeatures::flag("1"), nullptr);
}

// The program starts with the kernel's default of every feature, from the list
TEST(Lists, ProgramDefaultsEveryFeature) {
  for (const std::string& src : {renderer_program_source(), test_program_source()}) {
    std::string head = src.substr(0, src.find("#line 1"));
    for (const FeatureEntry& f : kFeatures)
      EXPECT_NE(head.find("#ifndef " + f.macro + "\n#define " + f.macro + " " + f.fallback + "\n#endif\n"),
                std::string::npos)
          << f.macro;
  }
}

// Every type's feature column names a feature (or 1, always compiled in), and a scene with a
// material of the type needs it
TEST(Lists, EachTypeNeedsItsFeature) {
  for (const auto* list : {&kMaterials, &kLights})
    for (const ListEntry& e : *list)
      EXPECT_TRUE(e.feature == "1" || SceneFeatures::flag(e.feature)) << e.name << ": " << e.feature;
  for (const ListEntry& e : kMaterials) {
    SCOPED_TRACE(e.name);
    Scene s = one_triangle(e.id);
    ASSERT_EQ(s.materials[0].kernel_type(), e.id);
    SceneFeatures want;
    if (e.feature != "1") want.*SceneFeatures::flag(e.feature) = true;
    EXPECT_EQ(s.features().build_options(), want.build_options());
    // The compile step keeps the type and refuses a kernel without its feature
    CompiledScene c = compile_scene(s);
    EXPECT_EQ(c.buffers.materials.at(0).type, e.id);
    if (e.feature != "1") {
      EXPECT_THROW(compile_scene(s, SceneFeatures()), Error);
    }
  }
}

// light_power has a case for every listed light type, and none for another
TEST(Lists, LightPowerHasEveryType) {
  Scene s = one_triangle(MATERIAL_DIFFUSE);
  s.materials[0].emission = glm::vec3(1.0f);
  CompiledScene c = compile_scene(s);
  ASSERT_EQ(c.buffers.lights.size(), 1u);
  for (const ListEntry& e : kLights) {
    dev::Light l = c.buffers.lights[0];
    l.type = e.id;
    for (float& r : l.radiance) r = 1.0f;
    l.params.spot.cone_scale = 1.0f;  // a spot's cone
    EXPECT_GT(light_power(l, c.buffers, 1.0, 1.0), 0.0) << e.name;
  }
  dev::Light unknown = c.buffers.lights[0];
  unknown.type = dev::kLightTypeCount;
  EXPECT_THROW(light_power(unknown, c.buffers, 1.0, 1.0), Error);
}

// Each device sees the defaults of the program (test_lists.cl): every feature on, NanoVDB
// where candela has PNanoVDB, but for those the shared test program's options turn off
// (kTestProgramOptions)
class ListsOnDevice : public DeviceTest {};

TEST_P(ListsOnDevice, FeatureDefaultsReachTheKernel) {
  auto out = rig().output<cl_uint>(kFeatures.size());
  rig().run("test_feature_defaults", 1, out);
  std::vector<cl_uint> got = out.read();
  bool pnanovdb = test_program_source().rfind("#define CD_PNANOVDB_AVAILABLE 1\n", 0) == 0;
  const std::string options = kTestProgramOptions;
  for (size_t i = 0; i < kFeatures.size(); ++i) {
    bool off = options.find("-D" + kFeatures[i].macro + "=0") != std::string::npos;
    EXPECT_EQ(got[i], off ? 0u : kFeatures[i].fallback == "1" ? 1u : cl_uint(pnanovdb)) << kFeatures[i].macro;
  }
}

INSTANTIATE_TEST_SUITE_P(Devices, ListsOnDevice, kernel_devices(), DeviceParamName());

}  // namespace candela::test
