// Dielectrics (glTF KHR_materials_transmission, KHR_materials_ior): rough and smooth glass,
// thin-walled sheets, glass under a clearcoat, in the BSDF harness (bsdf_checks.hpp); the
// smooth ones' Fresnel-weighted reflection and refraction, a thin sheet seen from both
// sides, and no jump in the energy split as the roughness crosses the delta threshold.
#include <gtest/gtest.h>

#include <random>

#include "bsdf/bsdf_checks.hpp"

namespace candela::test {

LobeFamily dielectric_family() {
  const glm::dvec3 white(1.0);
  auto one = [](double) { return glm::dvec3(1.0); };  // R + T (eta^2-weighted)
  CellSpec straight = kNarrow;
  straight.transmission = Focus::Straight;
  dev::Material coat_glass = gltf(white, 0.0, 0.3, 1.0);
  coat_glass.params.gltf.clearcoat = 1.0f;
  coat_glass.params.gltf.clearcoat_roughness = 0.3f;
  return {{
              gltf_case("glass_r03", gltf(white, 0.0, 0.3, 1.0), kNarrow),
              gltf_case("thin_glass_r03", gltf(white, 0.0, 0.3, 1.0, true), straight),
              gltf_case("coat_glass", coat_glass, kNarrow),
              delta_case("smooth_glass", gltf(white, 0.0, 0.0, 1.0), one),
              delta_case("smooth_thin_glass", gltf(white, 0.0, 0.0, 1.0, true), one),
          },
          {
              {"glass_outside", [=](double r) { return gltf(white, 0.0, r, 1.0); }, false, ""},
              {"glass_inside", [=](double r) { return gltf(white, 0.0, r, 1.0); }, true, ""},
              {"thin_glass", [=](double r) { return gltf(white, 0.0, r, 1.0, true); }, false, ""},
          }};
}

INSTANTIATE_TEST_SUITE_P(Lobes, BsdfTest,
                         ::testing::Combine(kernel_devices(), ::testing::ValuesIn(dielectric_family().materials)),
                         BsdfTestName());

namespace {

// Smooth glass seen from wo: reflection with probability R and weight 1, refraction with
// 1 - R and weight 1 / eta^2 (radiance), or a thin sheet's straight transmission with
// R' = 2R / (1 + R) (inter-reflections in the sheet) and weight 1
std::vector<DeltaLobe> glass_lobes(const Geometry& g, double ior, bool thin, glm::dvec3 tint) {
  Oriented o = orient(g);
  double eta = o.front || thin ? ior : 1.0 / ior, c = glm::dot(g.wo, o.ns), r = fresnel_dielectric(c, eta);
  if (thin) r = 2.0 * r / (1.0 + r);
  std::vector<DeltaLobe> lobes = {{"reflection", mirror(g.wo, o.ns), true, 1.0, glm::dvec3(1.0), r, glm::dvec3(r)}};
  if (thin) {
    lobes.push_back({"straight", -g.wo, false, 1.0, tint, 1.0 - r, tint * (1.0 - r)});
  } else if (auto t = refract(g.wo, o.ns, eta)) {
    lobes.push_back({"refraction", *t, false, eta, tint / (eta * eta), 1.0 - r, tint * (1.0 - r) / (eta * eta)});
  }
  return lobes;
}

}  // namespace

// Smooth glass from outside and from inside, below and beyond the critical angle (total
// internal reflection: all reflected, weight 1)
TEST_P(BsdfDelta, SmoothGlass) {
  dev::Material glass = gltf(glm::dvec3(1.0), 0.0, 0.0, 1.0);
  for (auto [theta, back] : std::vector<std::pair<double, bool>>{
           {0, false}, {45, false}, {80, false}, {20, true}, {40, true}, {60, true}, {80, true}}) {
    SCOPED_TRACE("theta " + std::to_string(theta) + (back ? " inside" : " outside"));
    Geometry g = flat(theta, back);
    check_delta(sample(glass, g), glass_lobes(g, 1.5, false, glm::dvec3(1.0)), true);
  }
}

// A thin sheet: straight through with the tint, or reflected, R' = 2R / (1 + R)
TEST_P(BsdfDelta, SmoothThinSheet) {
  glm::dvec3 tint(0.9, 0.6, 0.3);
  dev::Material sheet = gltf(tint, 0.0, 0.0, 1.0, true);
  for (double theta : {0.0, 60.0}) {
    SCOPED_TRACE("theta " + std::to_string(theta));
    Geometry g = flat(theta, false);
    check_delta(sample(sheet, g), glass_lobes(g, 1.5, true, tint), true);
  }
}

// A thin-walled sheet has air on both sides: seen from behind it reflects and transmits as
// from the front (no total internal reflection), smooth or rough
TEST_P(BsdfDelta, ThinSheetLooksTheSameFromBothSides) {
  glm::dvec3 tint(0.9, 0.6, 0.3);
  for (double theta : {30.0, 60.0}) {
    SCOPED_TRACE("theta " + std::to_string(theta));
    Geometry g = flat(theta, true);
    check_delta(sample(gltf(tint, 0.0, 0.0, 1.0, true), g), glass_lobes(g, 1.5, true, tint), true);
    // Rough: f(wo, wi) from behind equals f of the mirrored pair in front
    dev::Material rough = gltf(tint, 0.0, 0.3, 1.0, true);
    auto flip = [](glm::dvec3 w) { return glm::dvec3(w.x, w.y, -w.z); };  // through the sheet
    Geometry front = seen_from(g, flip(g.wo));
    BsdfRun back_run(rig(), rough, g), front_run(rig(), rough, front);
    std::mt19937_64 gen(5);
    std::normal_distribution<double> normal;
    std::vector<std::pair<glm::dvec3, glm::dvec3>> back_pairs, front_pairs;
    for (int i = 0; i < 1024; ++i) {
      glm::dvec3 wi = glm::normalize(glm::dvec3(normal(gen), normal(gen), normal(gen)));
      if (std::fabs(wi.z) < 0.01) continue;
      back_pairs.emplace_back(g.wo, wi);
      front_pairs.emplace_back(front.wo, flip(wi));
    }
    std::vector<cl_float4> b = back_run.eval(back_pairs), f = front_run.eval(front_pairs);
    size_t bad = 0;
    for (size_t i = 0; i < b.size(); ++i)
      if (!near_vec(d3(b[i]), d3(f[i]), 1e-3) && ++bad <= 5)
        ADD_FAILURE() << "pair " << i << ": behind " << b[i].s[0] << ", in front " << f[i].s[0];
    EXPECT_EQ(bad, 0u);
  }
}

namespace {

// Energy reflected and transmitted (eta^2-weighted) by `m` from wo, by sampling
std::pair<SampleMean, SampleMean> split_energy(const KernelRig& r, const dev::Material& m, const Geometry& g,
                                               cl_uint seed) {
  Samples s = BsdfRun(r, m, g).sample(seed, 1 << 16);
  std::vector<glm::dvec3> w = energy_weights(s, g.ns), reflected(w.size(), glm::dvec3(0.0)), transmitted = reflected;
  for (size_t i = 0; i < w.size(); ++i) (s.returned(i) && s.reflection(i) ? reflected : transmitted)[i] = w[i];
  return {estimate(reflected), estimate(transmitted)};
}

// A rough dielectric just above GGX_DELTA_ALPHA (roughness 0.035, alpha 0.0012) splits
// energy as the smooth one just below it: no jump at the threshold
void check_continuity(const KernelRig& r, cl_uint seed, bool thin) {
  const double z = bsdf_z();
  for (auto [theta, back] : std::vector<std::pair<double, bool>>{{0, false}, {45, false}, {30, true}}) {
    if (thin && back) continue;
    SCOPED_TRACE("theta " + std::to_string(theta) + (back ? " inside" : " outside"));
    Geometry g = flat(theta, back);
    auto [rough_r, rough_t] = split_energy(r, gltf(glm::dvec3(1.0), 0.0, 0.035, 1.0, thin), g, seed);
    auto [smooth_r, smooth_t] = split_energy(r, gltf(glm::dvec3(1.0), 0.0, 0.0, 1.0, thin), g, seed);
    EXPECT_NEAR(rough_r.mean.x, smooth_r.mean.x, 0.01 * smooth_r.mean.x + z * (rough_r.se.x + smooth_r.se.x))
        << "reflected";
    EXPECT_NEAR(rough_t.mean.x, smooth_t.mean.x, 0.01 * smooth_t.mean.x + z * (rough_t.se.x + smooth_t.se.x))
        << "transmitted";
  }
}

}  // namespace

TEST_P(BsdfDelta, RoughGlassApproachesSmooth) { check_continuity(rig(), seed_on(GetParam(), 5), false); }

// A thin sheet's reflectance, 2R / (1 + R) with inter-reflections, does not jump as its
// roughness crosses GGX_DELTA_ALPHA (rough and smooth sheets agree)
TEST_P(BsdfDelta, RoughThinSheetApproachesSmooth) { check_continuity(rig(), seed_on(GetParam(), 5), true); }

}  // namespace candela::test
