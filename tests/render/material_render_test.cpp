// Whole renders of the materials with known answers: white furnaces (an energy-conserving
// closed object under a uniform background of 1 is invisible) and specular objects that
// show an area light under next-event estimation, where both strategies must agree.
#include <gtest/gtest.h>

#include <cmath>

#include "render/renderer.hpp"
#include "support/gltf_builder.hpp"
#include "support/scenes.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

using nlohmann::json;

// A sphere of `material` filling most of the view under a uniform background of 1
Scene furnace_scene(const json& material, const std::string& file) {
  return load_scene(furnace_sphere(material), file);
}

json glass(double roughness, bool volume) {
  json ext = {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}}};
  if (volume) ext["KHR_materials_volume"] = {{"thicknessFactor", 1.0}};
  return {{"pbrMetallicRoughness",
           {{"baseColorFactor", {1, 1, 1, 1}}, {"metallicFactor", 0.0}, {"roughnessFactor", roughness}}},
          {"extensions", ext}};
}

struct FurnaceCase {
  const char* label;
  json material;
  double tolerance;        // allowed deficit beyond 4 standard errors
  bool bsdf_only = false;  // nee is heavy-tailed here (light sampling of a near-delta lobe)
};

class MaterialFurnace : public ::testing::TestWithParam<std::tuple<int, Strategy>> {};

const std::vector<FurnaceCase>& furnace_cases() {
  static const std::vector<FurnaceCase> cases = {
      {"white_lambert",
       {{"pbrMetallicRoughness", {{"metallicFactor", 0.0}}},
        {"extensions", {{"KHR_materials_specular", {{"specularFactor", 0.0}}}}}},
       1e-6},
      {"smooth_glass", glass(0.0, true), 1e-5},
      // glTF plastic (ior 1.5): the diffuse base gets exactly what the specular layer does not
      // reflect (cl/bsdf/gltf/mixture.cl's layering), within the albedo table's accuracy
      {"white_plastic_r05", {{"pbrMetallicRoughness", {{"metallicFactor", 0.0}, {"roughnessFactor", 0.5}}}}, 3e-3},
      {"white_smooth_plastic", {{"pbrMetallicRoughness", {{"metallicFactor", 0.0}, {"roughnessFactor", 0.0}}}}, 1e-4},
      {"smooth_thin_glass", glass(0.0, false), 1e-5},
      // Rough dielectrics, with the multiple-scattering compensation of
      // cl/bsdf/energy_dielectric.cl (without it they lose about 0.7 % here)
      {"rough_glass", glass(0.2, true), 0.012, true},
      {"rough_thin_glass", glass(0.2, false), 0.012, true},
  };
  return cases;
}

}  // namespace

// Closed white objects that neither absorb nor emit are invisible under a uniform
// background: every pixel is 1 (pbrt-v4's and Mitsuba's furnace test)
TEST_P(MaterialFurnace, InvisibleUnderUniformBackground) {
  const FurnaceCase& c = furnace_cases()[size_t(std::get<0>(GetParam()))];
  Strategy s = std::get<1>(GetParam());
  if (c.bsdf_only && s == Strategy::Nee) GTEST_SKIP() << "nee is heavy-tailed on near-delta glass";
  Scene scene = furnace_scene(c.material, std::string("furnace-") + c.label + ".gltf");
  Film f = render_film(scene, s, 16, 16, 256, 1000, 7);
  Estimate e = image_mean(f);
  EXPECT_LT(e.standard_error, 0.01) << "too noisy to test anything";
  EXPECT_LE(e.mean, 1.0 + 4.0 * e.standard_error + 1e-5) << c.label << " " << strategy_name(s) << " creates energy";
  EXPECT_NEAR(e.mean, 1.0, 4.0 * e.standard_error + c.tolerance)
      << c.label << " " << strategy_name(s) << " SE " << e.standard_error;
  for (int by = 0; by < 16; by += 4)
    for (int bx = 0; bx < 16; bx += 4) {
      Estimate b = region_mean(f, 1, bx, bx + 4, by, by + 4);
      EXPECT_NEAR(b.mean, 1.0, 5.0 * b.standard_error + c.tolerance + 1e-5) << c.label << " block " << bx << "," << by;
    }
  EXPECT_EQ(f.dropped_samples(), 0u);
}

INSTANTIATE_TEST_SUITE_P(Materials, MaterialFurnace,
                         ::testing::Combine(::testing::Range(0, int(furnace_cases().size())),
                                            ::testing::Values(Strategy::Nee, Strategy::Bsdf)),
                         [](const auto& info) {
                           return std::string(furnace_cases()[size_t(std::get<0>(info.param))].label) + "_" +
                                  strategy_name(std::get<1>(info.param));
                         });

// A mirror sphere and a glass sphere under a small area light over a dark floor: under
// nee the light is seen in the mirror (emission after a delta bounce) and through the
// glass, and nee and bsdf agree block by block
class SpecularShowsLight : public ::testing::TestWithParam<std::string> {};

TEST_P(SpecularShowsLight, NeeSeesTheLightAndStrategiesAgree) {
  GltfBuilder g;
  json object = GetParam() == "mirror"
                    ? json{{"pbrMetallicRoughness", {{"metallicFactor", 1.0}, {"roughnessFactor", 0.0}}},
                           {"extras", {{"candela", {{"conductor", "silver"}}}}}}
                    : glass(0.0, true);
  int obj = g.add("materials", object);
  int floor = g.add("materials", lambert_material(0.5));
  int light = g.add("materials", emissive_material(glm::vec3(20.0f)));
  const float l = 0.3f, h = 1.5f;
  g.add_node({{"mesh", g.add_mesh({sphere_primitive(glm::vec3(0.0f, 0.5f, 0.0f), 0.5f, 3, obj),
                                   quad_facing_up(3.0f, 0.0f, floor), quad_facing_down_rotated(l, h, light)})}});
  g.add_camera(glm::vec3(0.0f, 0.9f, 2.2f), glm::vec3(0.0f, 0.5f, 0.0f), 0.7f);
  Scene scene = load_scene(g, "specular-" + GetParam() + ".gltf");
  const int size = 24;
  Film nee = render_film(scene, Strategy::Nee, size, size, 256, 12, 3);
  Film bsdf = render_film(scene, Strategy::Bsdf, size, size, 2048, 12, 4);
  // The light, seen via the sphere, makes the brightest pixels of the nee image
  float brightest = 0.0f;
  for (size_t i = 0; i < nee.pixels(); ++i) brightest = std::max(brightest, nee.pixel(i).y);
  EXPECT_GT(brightest, 2.0f) << "the light is not visible in the " << GetParam() << " under nee";
  double chi2 = 0.0;
  int blocks = 0;
  for (int by = 0; by < size; by += 6)
    for (int bx = 0; bx < size; bx += 6) {
      Estimate a = region_mean(nee, 1, bx, bx + 6, by, by + 6), b = region_mean(bsdf, 1, bx, bx + 6, by, by + 6);
      double se = std::sqrt(a.standard_error * a.standard_error + b.standard_error * b.standard_error);
      if (se == 0.0) {  // both exact (a black corner): they must agree exactly
        EXPECT_EQ(a.mean, b.mean) << GetParam() << " block " << bx << "," << by;
        continue;
      }
      double z = (a.mean - b.mean) / se;
      chi2 += z * z;
      ++blocks;
      EXPECT_LT(std::fabs(z), 4.5) << GetParam() << " block " << bx << "," << by << ": nee " << a.mean << " bsdf "
                                   << b.mean;
    }
  EXPECT_LT(chi2, blocks + 5.0 * std::sqrt(2.0 * blocks));
}

INSTANTIATE_TEST_SUITE_P(Materials, SpecularShowsLight, ::testing::Values("mirror", "glass"),
                         [](const auto& info) { return std::string(info.param); });

}  // namespace candela::test

namespace candela::test {

// Smooth vertex normals on a coarse mesh tilt the shading normal up to ~20 degrees from
// the geometric one, so near the silhouette the camera sees faces whose shading normal
// points away from it (wo below the shading hemisphere, above the geometric one). A
// white Lambertian sphere of 80 such faces under a uniform background of 1 must still
// look white there, not black (cl/bsdf/bsdf.cl bsdf_face_wo), for diffuse, metal and plastic.
class ShadingNormals : public ::testing::TestWithParam<int> {};

TEST_P(ShadingNormals, NoBlackFringesAtSilhouettesOfSmoothedCoarseMeshes) {
  const json materials[] = {
      {{"pbrMetallicRoughness", {{"metallicFactor", 0.0}}},
       {"extensions", {{"KHR_materials_specular", {{"specularFactor", 0.0}}}}}},
      {{"pbrMetallicRoughness", {{"metallicFactor", 1.0}, {"roughnessFactor", 0.3}}}},
      {{"pbrMetallicRoughness", {{"metallicFactor", 0.0}, {"roughnessFactor", 0.3}}}},
  };
  GltfBuilder g;
  int m = g.add("materials", materials[GetParam()]);
  GltfBuilder::Primitive sphere = sphere_primitive(glm::vec3(0.0f), 0.5f, 1, m);
  for (const glm::vec3& p : sphere.positions) sphere.normals.push_back(glm::normalize(p));
  g.add_node({{"mesh", g.add_mesh({sphere})}});
  g.add_camera(glm::vec3(0.0f, 0.0f, 2.0f), glm::vec3(0.0f), 0.6f);
  g.set_background(glm::vec3(1.0f));
  Scene scene = load_scene(g, "fringe-sphere.gltf");
  for (Strategy s : {Strategy::Nee, Strategy::Bsdf}) {
    Film f = render_film(scene, s, 64, 64, 64, 8, 3);
    // Dark pixels: the BSDF-sampled furnace is nearly noise-free (every path ends in the
    // background with weight about 1); light sampling of glossy lobes is too noisy per pixel
    size_t dark = 0;
    for (size_t i = 0; i < f.pixels() && s == Strategy::Bsdf; ++i)
      if (f.pixel(i).x < 0.6f) ++dark;
    Estimate e = image_mean(f);
    std::printf("material %d %s: %zu of %zu pixels below 0.6, image mean %.4f +- %.4f\n", GetParam(), strategy_name(s),
                dark, f.pixels(), e.mean, e.standard_error);
    EXPECT_EQ(dark, 0u) << strategy_name(s);
    EXPECT_NEAR(e.mean, 1.0, 4.0 * e.standard_error + 0.01) << strategy_name(s);
  }
}
INSTANTIATE_TEST_SUITE_P(WhiteMaterials, ShadingNormals, ::testing::Values(0, 1, 2));

}  // namespace candela::test
