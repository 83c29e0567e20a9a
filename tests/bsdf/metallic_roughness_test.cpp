// glTF metallic-roughness (MATERIAL_GLTF: metal, plastic, clearcoat, anisotropy, and a
// mixture with transmission, the EON diffuse base of KHR_materials_diffuse_roughness) in the
// BSDF harness (bsdf_checks.hpp), against GltfReference,
// and its smooth variants' mirrors.
#include <gtest/gtest.h>

#include "bsdf/bsdf_checks.hpp"

namespace candela::test {

LobeFamily metallic_roughness_family() {
  const glm::dvec3 orange(0.8, 0.5, 0.2), brass(0.95, 0.64, 0.54), white(1.0);
  dev::Material metal_aniso = gltf(brass, 1.0, 0.4);
  metal_aniso.params.gltf.anisotropy_strength = 0.7f;
  metal_aniso.params.gltf.anisotropy_rotation = 0.6f;
  dev::Material coat = gltf(orange, 0.0, 0.6);
  coat.params.gltf.clearcoat = 1.0f;
  coat.params.gltf.clearcoat_roughness = 0.2f;
  dev::Material smooth_coat = gltf(brass, 1.0, 0.5);
  smooth_coat.params.gltf.clearcoat = 1.0f;
  // KHR_materials_diffuse_roughness: the EON base alone (specular factor 0, so its albedo is
  // known exactly), and under the specular layer
  auto rough_diffuse = [=](glm::dvec3 base, double r, double specular) {
    dev::Material m = gltf(base, 0.0, 0.5);
    m.params.gltf.specular = float(specular);
    m.params.gltf.diffuse_roughness = float(r);
    return m;
  };
  const dev::Material eon = rough_diffuse(orange, 0.7, 0.0);
  const MaterialCase eon_case{
      "rough_diffuse",    eon, true, [=](double cos_o) { return eon_albedo(orange, 0.7, cos_o); },
      GltfReference(eon), {},  {}};
  auto white_coat = [=](double r) {
    dev::Material m = gltf(white, 0.0, r);
    m.params.gltf.clearcoat = 1.0f;
    m.params.gltf.clearcoat_roughness = float(r);
    return m;
  };
  return {
      {
          gltf_case("metal_r05", gltf(brass, 1.0, 0.5), kGlossy),
          gltf_case("metal_aniso", metal_aniso, kGlossy),
          gltf_case("plastic_r03", gltf(orange, 0.0, 0.3), kNarrow),
          gltf_case("plastic_r1", gltf(orange, 0.0, 1.0), {}),
          gltf_case("coat_plastic", coat, kNarrow),
          gltf_case("mixture", gltf({0.9, 0.7, 0.5}, 0.5, 0.4, 0.5), {40, 40, 0.8, Focus::Mirror, Focus::Refraction}),
          gltf_case("smooth_plastic", gltf(orange, 0.0, 0.0), {}),
          gltf_case("smooth_coat_metal", smooth_coat, kGlossy),
          eon_case,
          gltf_case("rough_diffuse_plastic", rough_diffuse(orange, 1.0, 1.0), {}),
      },
      {
          {"metal_white", [=](double r) { return gltf(white, 1.0, r); }, false, ""},
          {"plastic_white", [=](double r) { return gltf(white, 0.0, r); }, false, ""},
          {"coat_plastic_white", white_coat, false, ""},
          {"smooth_coat_metal_white",
           [=](double r) {
             dev::Material m = white_coat(r);
             m.params.gltf.metallic = 1.0f;
             m.params.gltf.clearcoat_roughness = 0.0f;
             return m;
           },
           false, ""},
          {"mixture_white", [=](double r) { return gltf(white, 0.5, r, 0.5); }, false, ""},
          {"rough_diffuse_white", [=](double r) { return rough_diffuse(white, r, 0.0); }, false, ""},
      }};
}

INSTANTIATE_TEST_SUITE_P(Lobes, BsdfTest,
                         ::testing::Combine(kernel_devices(),
                                            ::testing::ValuesIn(metallic_roughness_family().materials)),
                         BsdfTestName());

// glTF mirrors: metal of weight Schlick(base, 1); plastic and a coat over a rough metal,
// whose delta lobe is chosen by a heuristic, contribute Schlick(F0, 1) on average; a
// smooth mixture of metal, plastic and glass sums its components' mirrors and refracts (1 - m) t (1 - R)
TEST_P(BsdfDelta, SmoothGltf) {
  const glm::dvec3 base(0.9, 0.6, 0.3);
  for (double theta : {0.0, 60.0, 85.0}) {
    SCOPED_TRACE("theta " + std::to_string(theta));
    Geometry g = flat(theta, false);
    double c = g.wo.z;
    glm::dvec3 wr = mirror(g.wo, g.ns), metal = schlick(base, glm::dvec3(1.0), c);
    {
      SCOPED_TRACE("metal");
      check_delta(sample(gltf(base, 1.0, 0.0), g), {{"mirror", wr, true, 1.0, metal, 1.0, metal}}, true);
    }
    {
      SCOPED_TRACE("plastic");
      glm::dvec3 spec = schlick(glm::dvec3(0.04), glm::dvec3(1.0), c);
      check_delta(sample(gltf(base, 0.0, 0.0), g), {{"mirror", wr, true, 1.0, {}, {}, spec}}, false);
    }
    {
      SCOPED_TRACE("coat over rough metal");
      dev::Material m = gltf(base, 1.0, 0.5);
      m.params.gltf.clearcoat = 1.0f;
      glm::dvec3 coat(0.04 + 0.96 * schlick_weight(c));
      check_delta(sample(m, g), {{"mirror", wr, true, 1.0, {}, {}, coat}}, false);
    }
    {
      // m = 0.5, t = 0.5: metal 1/2, plastic (1 - m)(1 - t) = 1/4, glass (1 - m) t = 1/4
      SCOPED_TRACE("metal, plastic and glass");
      double fr = fresnel_dielectric(c, 1.5);
      glm::dvec3 t = refract(g.wo, g.ns, 1.5).value(), spec = schlick(glm::dvec3(0.04), glm::dvec3(1.0), c);
      check_delta(sample(gltf(base, 0.5, 0.0, 0.5), g),
                  {{"mirror", wr, true, 1.0, {}, {}, 0.5 * metal + 0.25 * spec + 0.25 * fr},
                   {"refraction", t, false, 1.5, {}, {}, 0.25 * base * (1.0 - fr) / 2.25}},
                  false);
    }
  }
}

}  // namespace candela::test
