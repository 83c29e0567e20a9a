// Conductors (MATERIAL_CONDUCTOR: measured complex index, GGX, anisotropy) in the BSDF
// harness (bsdf_checks.hpp), and the smooth conductor's mirror.
#include <gtest/gtest.h>

#include "bsdf/bsdf_checks.hpp"

namespace candela::test {
namespace {

// Measured conductor: D G F / (4 cos cos) with the exact complex-index Fresnel term
ReferenceLobe conductor_reference(GgxReference g, glm::dvec3 eta, glm::dvec3 k) {
  return [=](glm::dvec3 wo, glm::dvec3 wi, bool reflection, bool) {
    if (!reflection || wo.z <= 0.0 || wi.z <= 0.0) return kNothing;
    double c = glm::dot(wo, glm::normalize(wo + wi));
    auto [f, pdf] = g.reflection(wo, wi);
    return Reference{f * fresnel_conductor(c, eta, k), pdf};
  };
}

// Microfacet lobes lose the samples reflected below the horizon: their pdf integrates to less than 1
MaterialCase conductor_case(std::string name, dev::Material m, CellSpec cells) {
  GgxReference g = GgxReference::from(m.params.conductor.roughness, m.params.conductor.anisotropy_strength);
  return {name, m, false, {}, conductor_reference(g, gold_eta(), gold_k()), cells, {}};
}

}  // namespace

LobeFamily conductor_family() {
  auto gold_mirror = [](double c) { return glm::dvec3(fresnel_conductor(c, gold_eta(), gold_k())); };
  return {{
              conductor_case("conductor_r02", gold(0.2), kNarrow),
              conductor_case("conductor_r06", gold(0.6), kGlossy),
              conductor_case("conductor_r1", gold(1.0), {}),
              conductor_case("conductor_aniso", gold(0.5, 0.8), kGlossy),
              delta_case("smooth_conductor", gold(0.0), gold_mirror),
          },
          {
              {"conductor_gold", [](double r) { return gold(r); }, false, ""},
          }};
}

INSTANTIATE_TEST_SUITE_P(Lobes, BsdfTest,
                         ::testing::Combine(kernel_devices(), ::testing::ValuesIn(conductor_family().materials)),
                         BsdfTestName());

// A smooth conductor is a mirror of weight F(cos theta), the exact complex Fresnel term
TEST_P(BsdfDelta, SmoothConductor) {
  for (double theta : {0.0, 45.0, 80.0}) {
    SCOPED_TRACE("theta " + std::to_string(theta));
    Geometry g = flat(theta, false);
    glm::dvec3 f = fresnel_conductor(g.wo.z, gold_eta(), gold_k());
    check_delta(sample(gold(0.0), g), {{"mirror", mirror(g.wo, g.ns), true, 1.0, f, 1.0, f}}, true);
  }
}

}  // namespace candela::test
