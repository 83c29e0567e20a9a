// KHR_materials_unlit: a surface whose radiance is its base colour (factor x vertex colour)
// whatever the lighting, and which reflects nothing, on PoCL and rusticl; the scene needs the
// unlit feature and no glTF BSDF.
#include <gtest/gtest.h>

#include "gltf/gltf_loader.hpp"
#include "render/renderer.hpp"
#include "support/gltf_builder.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

using nlohmann::json;

// A quad filling the view, of base colour factor (0.2, 0.5, 0.8) and vertex colour
// (128, 255, 64) / 255, under a uniform background of 3; unlit or not
Scene quad_scene(bool unlit, const std::string& file) {
  GltfBuilder g;
  json material = {{"pbrMetallicRoughness", {{"baseColorFactor", {0.2, 0.5, 0.8, 1.0}}, {"metallicFactor", 0.0}}}};
  if (unlit) material["extensions"] = {{"KHR_materials_unlit", json::object()}};
  int m = g.add("materials", material);
  GltfBuilder::Primitive quad = quad_primitive({{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, m);
  quad.colors.assign(4, glm::u8vec4(128, 255, 64, 255));
  g.add_node({{"mesh", g.add_mesh({quad})}});
  g.add_camera(glm::vec3(0.0f, 0.0f, 3.0f), glm::vec3(0.0f), 0.5f);
  g.set_background(glm::vec3(3.0f));
  std::string path = ::testing::TempDir() + file;
  g.write(path);
  return load_gltf(path);
}

class Unlit : public ::testing::TestWithParam<const char*> {};

TEST_P(Unlit, ShowsItsBaseColourWhateverTheLighting) {
  DeviceEntry device;
  CANDELA_DEVICE_OR_SKIP(GetParam(), device);
  Scene s = quad_scene(true, std::string("unlit-") + GetParam() + ".gltf");
  EXPECT_TRUE(s.features().unlit);
  EXPECT_FALSE(s.features().gltf_bsdf);
  RenderSettings settings;
  settings.width = settings.height = 8;
  settings.max_depth = 4;
  for (Strategy strategy : {Strategy::Nee, Strategy::Bsdf}) {
    settings.strategy = strategy;
    Film f = scene_renderer(device, s, settings).render(0, 8).film;
    glm::vec3 want = glm::vec3(0.2f, 0.5f, 0.8f) * glm::vec3(128.0f / 255.0f, 1.0f, 64.0f / 255.0f);
    for (size_t i = 0; i < 64; ++i)
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(f.pixel(i)[c], want[c], 1e-6) << "pixel " << i << ", channel " << c;
  }
  // The same quad lit: Lambert under the background of 3 shows 3 x albedo
  Scene lit = quad_scene(false, std::string("lit-") + GetParam() + ".gltf");
  EXPECT_FALSE(lit.features().unlit);
  Film f = scene_renderer(device, lit, settings).render(0, 16).film;
  double mean = 0.0;
  for (size_t i = 0; i < 64; ++i) mean += f.pixel(i).y / 64.0;
  EXPECT_NEAR(mean, 3.0 * 0.5, 0.05);
}

INSTANTIATE_TEST_SUITE_P(Devices, Unlit, ::testing::Values("pocl", "rusticl"),
                         [](const auto& info) { return std::string(info.param); });

}  // namespace
}  // namespace candela::test
