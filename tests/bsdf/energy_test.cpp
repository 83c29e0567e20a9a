// Multiple-scattering energy compensation of the GGX lobes (cl/bsdf/energy.cl, Kulla & Conty
// 2017), on PoCL (the furnace on rusticl too): the device-computed albedo table against an
// independent Monte Carlo estimate; the albedo of compensated lobes through bsdf_sample
// weights (white rough metal keeps >= 98 %, white lobes stay at 1 and nothing exceeds it);
// the BSDF harness's checks for compensated lobes, whose sampling gains a cosine component
// (tests/bsdf/bsdf_test.cpp sees the lobes without the table); and a white furnace: a white
// rough metal sphere under a background of 1 renders as 1.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <glm/glm.hpp>
#include <memory>
#include <random>

#include "device/energy.hpp"
#include "device/kernel_sources.hpp"
#include "device/program_cache.hpp"
#include "render/renderer.hpp"
#include "support/reference.hpp"
#include "support/scenes.hpp"
#include "support/stats.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

constexpr size_t kSamples = 1 << 20;

// How far the table may be from the converged integral: quadrature (2e-4) and bilinear
// interpolation (5e-4 away from the last 0.1 degree before grazing), with a margin
const double kTableTolerance = 1e-3;
// E5 (nodes uniform in mu): linear interpolation of (1 - mu)^5 between nodes 1/31 apart
// errs by up to h^2 / 8 max|d2/dmu2| = 2.6e-3 for smooth lobes
const double kTable5Tolerance = 3e-3;

// Direction at polar angle theta (degrees) from +z in the xz-plane
glm::dvec3 at_angle(double theta_deg) {
  double t = theta_deg * kPi / 180.0;
  return {std::sin(t), 0.0, std::cos(t)};
}

struct Mean {
  double mean = 0.0, se = 0.0;
};

dev::Material material(unsigned type, glm::dvec3 base, double roughness) {
  dev::Material m{};
  m.type = type;
  for (int c = 0; c < 3; ++c) m.base_color[c] = float(base[c]);
  m.base_color[3] = 1.0f;
  if (type == MATERIAL_GLTF) {
    for (int c = 0; c < 3; ++c) m.params.gltf.specular_color[c] = float(base[c]);
    m.params.gltf.specular = 1.0f;
    m.params.gltf.ior = 1.5f;
    m.params.gltf.roughness = float(roughness);
  } else {
    m.params.conductor.roughness = float(roughness);
  }
  for (dev::TextureRef& t : m.textures) {
    t.index = NO_TEXTURE;
    t.m[0] = t.m[4] = 1.0f;
  }
  return m;
}

// glTF metal (metallic 1) of base colour `base`
dev::Material metal(glm::dvec3 base, double roughness, double anisotropy = 0.0) {
  dev::Material m = material(MATERIAL_GLTF, base, roughness);
  m.params.gltf.metallic = 1.0f;
  m.params.gltf.anisotropy_strength = float(anisotropy);
  return m;
}

// glTF dielectric (metallic 0, ior 1.5, specular 1) of base colour `base`
dev::Material plastic(glm::dvec3 base, double roughness) {
  dev::Material m = material(MATERIAL_GLTF, base, roughness);
  for (int c = 0; c < 3; ++c) m.params.gltf.specular_color[c] = 1.0f;
  return m;
}

dev::Material conductor(glm::dvec3 eta, glm::dvec3 k, double roughness) {
  dev::Material m = material(MATERIAL_CONDUCTOR, glm::dvec3(1.0), roughness);
  for (int c = 0; c < 3; ++c) {
    m.params.conductor.eta[c] = float(eta[c]);
    m.params.conductor.k[c] = float(k[c]);
  }
  return m;
}

// A PoCL test program and its albedo tables, from the kernel cache (computed by the first
// test process; EnergyDielectric.TableMatchesConvergedQuadrature checks a fresh computation)
struct EnergyRig {
  const KernelRig& rig;
  GgxAlbedoTable table;
  EnergyRig(const KernelRig& r, AnisotropicAlbedo anisotropic)
      : rig(r), table(ggx_albedo_table(r.context, r.queue, r.program, r.program_cache_file, anisotropic)) {}

  // (E(mu), E_avg, E5(mu), E5_avg) as the lobes look them up, for (mu, roughness) queries
  std::vector<cl_float4> lookup(const std::vector<cl_float2>& q) {
    auto out = rig.output<cl_float4>(q.size());
    rig.run("test_energy_lookup", q.size(), table.buffer, rig.input(q), out);
    return out.read();
  }

  // E(mu) by the table's quadrature with n x n points, anywhere
  std::vector<float> quadrature(const std::vector<cl_float2>& q, cl_uint n) {
    auto out = rig.output<float>(q.size());
    rig.run("test_energy_quadrature", q.size(), rig.input(q), n, out);
    return out.read();
  }

  // Independent Monte Carlo estimate of E(mu, roughness), or of E5 with `fresnel5`, from
  // kSamples weights
  Mean albedo_mc(float mu, float roughness, cl_uint seed, bool fresnel5 = false) {
    const cl_uint per_item = 64;
    const size_t items = kSamples / per_item;
    auto out = rig.output<cl_float2>(items);
    rig.run("test_energy_albedo_mc", items, mu, roughness, cl_uint(fresnel5), seed, per_item, out);
    double sum = 0.0, sum2 = 0.0;
    for (const cl_float2& s : out.read()) {
      sum += s.s[0];
      sum2 += s.s[1];
    }
    double mean = sum / kSamples;
    return {mean, std::sqrt(std::max(sum2 / kSamples - mean * mean, 0.0) / kSamples)};
  }

  // One work-item per sample of a kernel (material, table, with_table, wo, seed, out) that
  // writes `per_item` float4 per work-item
  std::vector<cl_float4> per_sample(const char* kernel, const dev::Material& m, bool with_table, glm::dvec3 wo,
                                    cl_uint seed, size_t n, size_t per_item) {
    auto out = rig.output<cl_float4>(per_item * n);
    rig.run(kernel, n, rig.input(std::vector<dev::Material>{m}), table.buffer, cl_uint(with_table), f4(wo), seed, out);
    return out.read();
  }

  // kSamples of bsdf_sample: per sample (wi, pdf), (f, flags), (bsdf_eval, bsdf_pdf)
  std::vector<cl_float4> sample(const dev::Material& m, bool with_table, glm::dvec3 wo, cl_uint seed) {
    return per_sample("test_energy_sample", m, with_table, wo, seed, kSamples, 3);
  }

  // (bsdf_eval, bsdf_pdf) for pairs (wo, wi)
  std::vector<cl_float4> eval(const dev::Material& m, const std::vector<std::pair<glm::dvec3, glm::dvec3>>& pairs) {
    std::vector<cl_float4> in;
    for (const auto& [wo, wi] : pairs) {
      in.push_back(f4(wo));
      in.push_back(f4(wi));
    }
    auto out = rig.output<cl_float4>(pairs.size());
    rig.run("test_energy_eval", pairs.size(), rig.input(std::vector<dev::Material>{m}), table.buffer, cl_uint(1),
            rig.input(in), out);
    return out.read();
  }

  // Mean sample weight f cos / pdf per channel (0 for a failed sample): the albedo
  std::array<Mean, 3> albedo(const dev::Material& m, bool with_table, glm::dvec3 wo, cl_uint seed,
                             size_t n = kSamples) {
    std::vector<cl_float4> w = per_sample("test_energy_albedo", m, with_table, wo, seed, n, 1);
    std::array<Mean, 3> a;
    for (int c = 0; c < 3; ++c) {
      Estimate e = sample_mean(w, c);
      a[c] = {e.mean, e.standard_error};
    }
    return a;
  }
};

// The shared test program (without CD_FEATURE_ANISOTROPY: anisotropic lobes approximated)
EnergyRig& energy_rig() {
  static EnergyRig r(kernel_rig("pocl"), AnisotropicAlbedo::none);
  return r;
}

// The test program with CD_FEATURE_ANISOTROPY and the exact anisotropic table
EnergyRig& anisotropic_energy_rig() {
  static EnergyRig r(anisotropic_kernel_rig(), AnisotropicAlbedo::exact);
  return r;
}

}  // namespace

// The table (as the lobes look it up, between its nodes) agrees with an independent Monte
// Carlo estimate of E(mu, alpha) = integral of f cos_i with F = 1, and of E5 (the same with
// F = (1 - wo.h)^5)
TEST(Energy, TableMatchesIndependentMonteCarlo) {
  EnergyRig& r = energy_rig();
  std::printf("GGX albedo table computed in %.3f s\n", r.table.seconds);
  std::vector<cl_float2> q;
  for (float roughness : {0.1f, 0.3f, 0.55f, 0.8f, 1.0f})
    for (float mu : {0.07f, 0.2f, 0.45f, 0.75f, 1.0f}) q.push_back({{mu, roughness}});
  std::vector<cl_float4> looked = r.lookup(q);
  for (size_t k = 0; k < q.size(); ++k) {
    Mean mc = r.albedo_mc(q[k].s[0], q[k].s[1], cl_uint(100 + k));
    Mean mc5 = r.albedo_mc(q[k].s[0], q[k].s[1], cl_uint(500 + k), true);
    EXPECT_NEAR(looked[k].s[0], mc.mean, 4.0 * mc.se + kTableTolerance)
        << "mu " << q[k].s[0] << " roughness " << q[k].s[1] << " SE " << mc.se;
    // E5 has nodes uniform in mu: its interpolation error is larger for smooth lobes
    EXPECT_NEAR(looked[k].s[2], mc5.mean, 4.0 * mc5.se + kTable5Tolerance)
        << "E5: mu " << q[k].s[0] << " roughness " << q[k].s[1] << " SE " << mc5.se;
    std::printf("  mu %.2f roughness %.2f: table E %.5f, Monte Carlo %.5f +- %.5f; E5 %.5f, %.5f +- %.5f\n", q[k].s[0],
                q[k].s[1], looked[k].s[0], mc.mean, mc.se, looked[k].s[2], mc5.mean, mc5.se);
  }
  // Alpha = 1 at normal incidence has a closed form: D = 1 / pi, E = 1 - ln 2
  EXPECT_NEAR(r.lookup({{{1.0f, 1.0f}}})[0].s[0], 1.0 - std::log(2.0), 2e-4);
}

// The table's quadrature has converged, and bilinear lookups between its nodes stay close
// to the integral there (away from the last 0.1 degree before grazing)
TEST(Energy, TableQuadratureAndInterpolationAreAccurate) {
  EnergyRig& r = energy_rig();
  auto node = [](int i) { return float(i) / float(GGX_ALBEDO_N - 1); };
  auto table_mu = [](float y, float roughness) {  // energy_mu of cl/bsdf/energy.cl
    float c = 4.0f * roughness * roughness;
    return y * y * c / (1.0f + c - y * y);
  };
  // Cell centres in (y, roughness), beyond the first roughness cell (delta lobes there)
  std::vector<cl_float2> centres;
  for (int j = 1; j + 1 < GGX_ALBEDO_N; j += 2)
    for (int i = 1; i + 1 < GGX_ALBEDO_N; i += 2) {
      float roughness = 0.5f * (node(j) + node(j + 1));
      centres.push_back({{table_mu(0.5f * (node(i) + node(i + 1)), roughness), roughness}});
    }
  std::vector<cl_float4> looked = r.lookup(centres);
  std::vector<float> table_quadrature = r.quadrature(centres, 64), converged = r.quadrature(centres, 256);
  double worst_quadrature = 0.0, worst_lookup = 0.0;
  for (size_t k = 0; k < centres.size(); ++k) {
    worst_quadrature = std::max(worst_quadrature, std::fabs(double(table_quadrature[k]) - converged[k]));
    worst_lookup = std::max(worst_lookup, std::fabs(double(looked[k].s[0]) - converged[k]));
  }
  std::printf("quadrature error %.2e, lookup error %.2e (max over %zu cell centres)\n", worst_quadrature, worst_lookup,
              centres.size());
  EXPECT_LT(worst_quadrature, 3e-4);
  EXPECT_LT(worst_lookup, kTableTolerance);
}

// White rough metal (glTF metallic 1, base colour 1, roughness 1: alpha = 1) at normal
// incidence: 1 - ln 2 = 0.307 of the light without compensation, >= 98 % with it
TEST(Energy, WhiteRoughMetalKeepsItsAlbedo) {
  EnergyRig& r = energy_rig();
  dev::Material m = metal(glm::dvec3(1.0), 1.0);
  auto with = r.albedo(m, true, {0, 0, 1}, 1), without = r.albedo(m, false, {0, 0, 1}, 1);
  std::printf("white metal, alpha 1, normal incidence: albedo %.5f +- %.5f compensated, %.5f +- %.5f not\n",
              with[1].mean, with[1].se, without[1].mean, without[1].se);
  for (int c = 0; c < 3; ++c) {
    EXPECT_GE(with[c].mean, 0.98);
    EXPECT_LE(with[c].mean, 1.0 + 4.0 * with[c].se);
    EXPECT_NEAR(without[c].mean, 1.0 - std::log(2.0), 4.0 * without[c].se);
  }
}

// Over roughness and angle: compensated lobes reflect at most 1 (within 4 standard errors),
// and lobes with F = 1 (white metal, a conductor of index 0) exactly 1 up to the table's
// accuracy, which needs E_avg to agree with the E that is looked up. Anisotropic lobes use
// the isotropic table at sqrt(ax ay), an approximation: within a few percent of 1.
TEST(Energy, CompensatedAlbedoIsOneForWhiteAndAtMostOneForAll) {
  EnergyRig& r = energy_rig();
  struct Case {
    std::string name;
    dev::Material (*make)(double);
    bool white;
    double tolerance;  // beyond 4 standard errors
  };
  const Case cases[] = {
      {"white metal", [](double a) { return metal(glm::dvec3(1.0), a); }, true, kTableTolerance},
      {"white conductor", [](double a) { return conductor(glm::dvec3(0.0), glm::dvec3(0.0), a); }, true,
       kTableTolerance},
      {"gold metal",
       [](double a) {
         return metal({1.0, 0.78, 0.34}, a);
       },
       false, 0.0},
      {"gold conductor", [](double a) { return conductor(gold_eta(), gold_k(), a); }, false, 0.0},
      {"anisotropic metal", [](double a) { return metal(glm::dvec3(1.0), a, 0.7); }, false, 0.03},
  };
  cl_uint seed = 10;
  for (const Case& c : cases)
    for (double roughness : {0.3, 0.6, 1.0})
      for (double theta : {0.0, 60.0, 85.0}) {
        auto a = r.albedo(c.make(roughness), true, at_angle(theta), seed++, kSamples / 2);
        std::printf("  %-17s roughness %.1f theta %2.0f: albedo %.5f %.5f %.5f (SE %.5f)\n", c.name.c_str(), roughness,
                    theta, a[0].mean, a[1].mean, a[2].mean, a[1].se);
        for (int k = 0; k < 3; ++k) {
          EXPECT_LE(a[k].mean, 1.0 + 4.0 * a[k].se + c.tolerance)
              << c.name << " roughness " << roughness << " theta " << theta;
          if (c.white) {
            EXPECT_NEAR(a[k].mean, 1.0, 4.0 * a[k].se + c.tolerance)
                << c.name << " roughness " << roughness << " theta " << theta;
          }
        }
      }
}

// Anisotropic lobes have an albedo that depends on the azimuth of wo, and a table of their
// own (cl/bsdf/energy.cl): white anisotropic metal (KHR_materials_anisotropy: ax = mix(alpha,
// 1, strength^2), ay = alpha) reflects 1 at every strength, roughness, elevation and azimuth
// (0: along the stretched tangent, 90: along the bitangent), up to the table's accuracy;
// without the table it loses up to about half of the light. Plastic with an anisotropic
// specular layer (its diffuse base weighted by the layer's directional albedo) reflects 1 too.
TEST(Energy, WhiteAnisotropicLobesKeepTheirAlbedoAtEveryAzimuth) {
  EnergyRig& r = anisotropic_energy_rig();
  const double kAnisoTolerance = 5e-3;  // the four-dimensional table's quadrature and interpolation
  cl_uint seed = 400;
  double lowest = 1.0, lowest_without = 1.0;
  for (double strength : {0.3, 0.7, 1.0})
    for (double roughness : {0.1, 0.3, 0.6})
      for (double theta : {0.0, 60.0, 85.0})
        for (double phi : {0.0, 45.0, 90.0}) {
          if (theta == 0.0 && phi > 0.0) continue;
          double t = theta * kPi / 180.0, p = phi * kPi / 180.0;
          glm::dvec3 wo(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t));
          dev::Material m = metal(glm::dvec3(1.0), roughness, strength);
          dev::Material pl = plastic(glm::dvec3(1.0), roughness);
          pl.params.gltf.anisotropy_strength = float(strength);
          auto with = r.albedo(m, true, wo, seed++, kSamples / 4);
          auto plastic_with = r.albedo(pl, true, wo, seed++, kSamples / 4);
          auto without = r.albedo(m, false, wo, seed++, kSamples / 8);
          std::printf(
              "  strength %.1f roughness %.1f theta %2.0f phi %2.0f: metal %.5f (SE %.5f), plastic %.5f (SE %.5f); "
              "metal without table %.4f\n",
              strength, roughness, theta, phi, with[1].mean, with[1].se, plastic_with[1].mean, plastic_with[1].se,
              without[1].mean);
          lowest = std::min({lowest, with[1].mean, plastic_with[1].mean});
          lowest_without = std::min(lowest_without, without[1].mean);
          for (const auto& a : {with[1], plastic_with[1]})
            EXPECT_NEAR(a.mean, 1.0, 4.0 * a.se + kAnisoTolerance)
                << "strength " << strength << " roughness " << roughness << " theta " << theta << " phi " << phi;
        }
  std::printf("lowest albedo %.4f with the table, %.4f without\n", lowest, lowest_without);
  EXPECT_LT(lowest_without, 0.9);  // the cases are ones where compensation matters
}

// CD_FEATURE_ANISOTROPY changes nothing for isotropic lobes: the kernel with it and the one
// without (a scene without anisotropy) give the same sample weights for the same random
// numbers, for metal, plastic, a clear-coated plastic and a conductor, while an anisotropic
// metal differs (the exact table against the isotropic one at sqrt(ax ay))
TEST(Energy, AnisotropyFeatureLeavesIsotropicLobesAsTheyWere) {
  EnergyRig& with = anisotropic_energy_rig();
  EnergyRig& without = energy_rig();
  const glm::dvec3 wo(std::sin(1.0) * std::cos(0.5), std::sin(1.0) * std::sin(0.5), std::cos(1.0));
  dev::Material coated = plastic(glm::dvec3(0.8, 0.4, 0.2), 0.5);
  coated.params.gltf.clearcoat = 1.0f;
  coated.params.gltf.clearcoat_roughness = 0.2f;
  const std::vector<std::pair<const char*, dev::Material>> lobes = {
      {"metal", metal(glm::dvec3(0.9, 0.6, 0.3), 0.4)},
      {"plastic", plastic(glm::dvec3(0.5), 0.7)},
      {"coated plastic", coated},
      {"conductor", conductor(glm::dvec3(0.2, 0.4, 1.4), glm::dvec3(3.6, 2.6, 2.3), 0.6)}};
  for (const auto& [name, m] : lobes) {
    auto a = with.albedo(m, true, wo, 500, kSamples / 16), b = without.albedo(m, true, wo, 500, kSamples / 16);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c].mean, b[c].mean, 1e-5 * b[c].mean) << name << " channel " << c;
  }
  dev::Material brushed = metal(glm::dvec3(1.0), 0.3, 0.8);
  auto exact = with.albedo(brushed, true, wo, 501, kSamples / 4),
       approx = without.albedo(brushed, true, wo, 501, kSamples / 4);
  std::printf("white anisotropic metal: %.5f (SE %.5f) with the feature, %.5f without\n", exact[1].mean, exact[1].se,
              approx[1].mean);
  EXPECT_GT(std::abs(exact[1].mean - approx[1].mean), 4.0 * (exact[1].se + approx[1].se));
}

// The plastic's layering (cl/bsdf/gltf/mixture.cl): with the table, the diffuse base gets exactly
// the light its specular layer does not reflect, so white plastic reflects 1 at every angle
// and roughness (smooth included), up to the table's accuracy; coloured and tinted plastic
// reflect at most 1. Without the table (no compensation) nothing exceeds 1 either.
TEST(Energy, WhitePlasticReflectsOneAtEveryAngle) {
  EnergyRig& r = energy_rig();
  cl_uint seed = 200;
  for (double roughness : {0.0, 0.3, 0.6, 1.0})
    for (double theta : {0.0, 45.0, 75.0, 88.0}) {
      dev::Material white = plastic(glm::dvec3(1.0), roughness);
      dev::Material tinted = white;
      tinted.params.gltf.specular_color[0] = 3.0f;  // f0 = 0.12 in red: A is the largest channel's
      tinted.base_color[2] = 0.3f;
      auto with = r.albedo(white, true, at_angle(theta), seed++, kSamples / 2);
      auto without = r.albedo(white, false, at_angle(theta), seed++, kSamples / 2);
      auto tint = r.albedo(tinted, true, at_angle(theta), seed++, kSamples / 2);
      std::printf(
          "  white plastic roughness %.1f theta %2.0f: albedo %.5f +- %.5f compensated, %.5f not; "
          "tinted %.4f %.4f %.4f\n",
          roughness, theta, with[1].mean, with[1].se, without[1].mean, tint[0].mean, tint[1].mean, tint[2].mean);
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(with[c].mean, 1.0, 4.0 * with[c].se + 2.0 * kTable5Tolerance)
            << "roughness " << roughness << " theta " << theta;
        EXPECT_LE(without[c].mean, 1.0 + 4.0 * without[c].se) << "roughness " << roughness << " theta " << theta;
        EXPECT_LE(tint[c].mean, 1.0 + 4.0 * tint[c].se + 2.0 * kTable5Tolerance)
            << "tinted, roughness " << roughness << " theta " << theta;
      }
    }
}

// The harness's checks (tests/bsdf/bsdf_checks.hpp) for compensated lobes: every sample's f and pdf
// are bsdf_eval's and bsdf_pdf's, sampled directions follow bsdf_pdf (chi-square over the
// hemisphere, alpha = 0.01 with the Sidak correction), samples are returned as often as
// the pdf integrates to, and eval is reciprocal
TEST(Energy, CompensatedLobesSampleTheirPdfAndAreReciprocal) {
  EnergyRig& r = energy_rig();
  const std::pair<std::string, dev::Material> cases[] = {
      {"white metal 1.0", metal(glm::dvec3(1.0), 1.0)},
      {"gold metal 0.5", metal({1.0, 0.78, 0.34}, 0.5)},
      {"gold conductor 0.6", conductor(gold_eta(), gold_k(), 0.6)},
      {"plastic 0.7", plastic({0.2, 0.5, 0.8}, 0.7)},
      {"anisotropic metal 0.6", metal(glm::dvec3(0.9), 0.6, 0.8)},
  };
  const glm::dvec3 wo = at_angle(50.0);
  const double alpha = sidak_alpha(0.01, int(std::size(cases)));
  const int n_cos = 16, n_phi = 32, sub = 16;  // cells in (cos theta, phi); midpoints per cell side
  for (const auto& [name, m] : cases) {
    std::vector<cl_float4> s = r.sample(m, true, wo, 4321);
    // Samples agree with eval and pdf
    size_t bad = 0, returned = 0;
    std::vector<double> observed(size_t(n_cos) * n_phi, 0.0);
    auto cell = [&](glm::dvec3 w) {
      double phi = std::atan2(w.y, w.x) + (w.y < 0.0 ? 2.0 * kPi : 0.0);
      int i = std::clamp(int(w.z * n_cos), 0, n_cos - 1), j = std::clamp(int(phi / (2.0 * kPi) * n_phi), 0, n_phi - 1);
      return size_t(i) * n_phi + j;
    };
    for (size_t i = 0; i < kSamples; ++i) {
      double pdf = s[3 * i].s[3];
      if (pdf == 0.0) continue;
      ++returned;
      glm::dvec3 wi = d3(s[3 * i]), f = d3(s[3 * i + 1]), fe = d3(s[3 * i + 2]);
      double pdf_e = s[3 * i + 2].s[3], tol = 1e-4 + 1e-6 / wi.z;
      bool ok = wi.z > 0.0 && std::fabs(pdf - pdf_e) <= tol * pdf && s[3 * i + 1].s[3] == 1.0f;
      for (int c = 0; c < 3; ++c) ok = ok && std::fabs(f[c] - fe[c]) <= tol * std::max(f[c], fe[c]);
      if (!ok && ++bad <= 3)
        ADD_FAILURE() << name << " sample " << i << ": f " << f.y << " vs " << fe.y << ", pdf " << pdf << " vs "
                      << pdf_e;
      if (wi.z > 0.0) observed[cell(wi)] += 1.0;
    }
    EXPECT_EQ(bad, 0u) << name;
    // The pdf over each cell by the midpoint rule
    std::vector<std::pair<glm::dvec3, glm::dvec3>> pairs;
    const int nz = n_cos * sub, np = n_phi * sub;
    for (int a = 0; a < nz; ++a)
      for (int b = 0; b < np; ++b) {
        double z = (a + 0.5) / nz, phi = (b + 0.5) / np * 2.0 * kPi, rr = std::sqrt(1.0 - z * z);
        pairs.emplace_back(wo, glm::dvec3(rr * std::cos(phi), rr * std::sin(phi), z));
      }
    std::vector<cl_float4> pdf = r.eval(m, pairs);
    std::vector<double> expected(observed.size(), 0.0);
    double integral = 0.0;
    for (int a = 0; a < nz; ++a)
      for (int b = 0; b < np; ++b) {
        double p = pdf[size_t(a) * np + b].s[3] * (1.0 / nz) * (2.0 * kPi / np);
        expected[size_t(a / sub) * n_phi + b / sub] += p * kSamples;
        integral += p;
      }
    double fraction = double(returned) / kSamples, sigma = std::sqrt(integral * (1.0 - integral) / kSamples);
    EXPECT_NEAR(fraction, integral, 4.0 * sigma + 2e-4) << name << ": returned samples vs the pdf's integral";
    for (double& e : expected) e *= double(returned) / (integral * kSamples);
    ChiSquare chi2 = chi_square_test(observed, expected);
    EXPECT_GT(chi2.p_value, alpha) << name << ": chi2 " << chi2.statistic << " dof " << chi2.dof;
    // Reciprocity
    std::mt19937_64 gen(7);
    std::uniform_real_distribution<double> uni;
    std::vector<std::pair<glm::dvec3, glm::dvec3>> swapped;
    pairs.clear();
    auto above = [&] {
      double z = 0.01 + 0.99 * uni(gen), phi = 2.0 * kPi * uni(gen), rr = std::sqrt(1.0 - z * z);
      return glm::dvec3(rr * std::cos(phi), rr * std::sin(phi), z);
    };
    for (int k = 0; k < 4096; ++k) {
      pairs.emplace_back(above(), above());
      swapped.emplace_back(pairs.back().second, pairs.back().first);
    }
    std::vector<cl_float4> f1 = r.eval(m, pairs), f2 = r.eval(m, swapped);
    size_t unequal = 0;
    for (size_t k = 0; k < pairs.size(); ++k)
      for (int c = 0; c < 3; ++c)
        if (std::fabs(f1[k].s[c] - f2[k].s[c]) > 1e-5 * std::max(std::fabs(f1[k].s[c]), std::fabs(f2[k].s[c])))
          ++unequal;
    EXPECT_EQ(unequal, 0u) << name << ": f(wo, wi) != f(wi, wo)";
  }
}

class EnergyFurnaceTest : public ::testing::TestWithParam<std::string> {};

// White furnace: a white metal sphere (metallic 1, roughness 1) under a uniform background
// of 1 renders as 1 with compensation, and darker without
TEST_P(EnergyFurnaceTest, WhiteRoughMetalSphereVanishes) {
  DeviceEntry device;
  CANDELA_DEVICE_OR_SKIP(GetParam(), device);
  GltfBuilder g;
  int mat =
      g.add("materials", {{"pbrMetallicRoughness",
                           {{"baseColorFactor", {1, 1, 1, 1}}, {"metallicFactor", 1.0}, {"roughnessFactor", 1.0}}}});
  g.add_node({{"mesh", g.add_mesh({sphere_primitive(glm::vec3(0.0f), 1.0f, 3, mat)})}});
  g.add_camera({0, 0, 3.2f}, {0, 0, 0}, 0.75f);  // the sphere spans 0.84 of the image height
  g.set_background({1, 1, 1});
  Scene scene = load_scene(g, "energy-furnace-" + GetParam() + ".gltf");
  for (Strategy strategy : {Strategy::Nee, Strategy::Bsdf})
    for (bool compensate : {true, false}) {
      RenderSettings s;
      s.width = s.height = 32;
      s.strategy = strategy;
      s.energy_compensation = compensate;
      s.seed = 5;
      Renderer renderer = scene_renderer(device, scene, s);
      RenderResult r = renderer.render(0, 256);
      Estimate e = region_mean(r.film, 1, 8, 24, 8, 24);  // a square inside the sphere's outline
      std::printf("%s, compensation %s: sphere mean %.5f +- %.5f\n", strategy == Strategy::Nee ? "nee" : "bsdf",
                  compensate ? "on" : "off", e.mean, e.standard_error);
      EXPECT_LT(e.standard_error, 2e-3);
      if (compensate) {
        EXPECT_NEAR(e.mean, 1.0, 4.0 * e.standard_error);
      } else {
        EXPECT_LT(e.mean, 1.0 - 10.0 * e.standard_error);
      }
      EXPECT_EQ(r.film.dropped_samples(), 0u);
    }
}

INSTANTIATE_TEST_SUITE_P(Devices, EnergyFurnaceTest, kernel_devices(), DeviceParamName());

}  // namespace candela::test
