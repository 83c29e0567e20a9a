// The diffuse lobe (MATERIAL_DIFFUSE) in the BSDF harness (bsdf_checks.hpp): Lambert.
#include <gtest/gtest.h>

#include "bsdf/bsdf_checks.hpp"

namespace candela::test {
namespace {

// Lambert: f = albedo / pi, pdf = cos theta / pi
ReferenceLobe lambert_reference(glm::dvec3 albedo) {
  return [albedo](glm::dvec3, glm::dvec3 wi, bool reflection, bool) {
    return reflection && wi.z > 0.0 ? Reference{albedo / kPi, cosine_hemisphere_pdf(wi.z)} : kNothing;
  };
}

MaterialCase diffuse(glm::dvec3 albedo) {
  return {"diffuse",
          make_material(MATERIAL_DIFFUSE, albedo),
          true,
          [albedo](double) { return albedo; },
          lambert_reference(albedo),
          {},
          {}};
}

}  // namespace

LobeFamily diffuse_family() { return {{diffuse({0.8, 0.5, 0.2})}, {}}; }

INSTANTIATE_TEST_SUITE_P(Lobes, BsdfTest,
                         ::testing::Combine(kernel_devices(), ::testing::ValuesIn(diffuse_family().materials)),
                         BsdfTestName());

}  // namespace candela::test
