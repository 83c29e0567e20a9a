// Energy compensation of rough dielectrics (cl/bsdf/energy_dielectric.cl) on PoCL (the
// furnace on rusticl too): the device-computed table against its converged quadrature; the
// albedo of white glass, X = f (n_i / n_o)^2 integrated over the sphere, is 1 from both sides
// of a volumetric interface and of a thin sheet, by bsdf_sample weights and by an eval-based
// estimator, and never above 1 for tinted glass; samples agree with eval; X is reciprocal
// across the interface as Y = f / n_o^2; white rough glass spheres vanish in a white furnace;
// and a white Lambert base under a clear coat reflects all the light (cl/bsdf/gltf/coat.cl).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <glm/glm.hpp>
#include <random>

#include "bsdf/bsdf_checks.hpp"
#include "device/energy.hpp"
#include "gltf/gltf_loader.hpp"
#include "render/renderer.hpp"
#include "support/kernels.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

using nlohmann::json;

constexpr size_t kAlbedoSamples = 1 << 18;

glm::dvec3 at_angle(double theta_deg) {
  double t = theta_deg * kPi / 180.0;
  return {std::sin(t), 0.0, std::cos(t)};
}

// glTF glass: transmission 1, ior 1.5, thin-walled or refracting, base colour `tint`
dev::Material glass(double roughness, bool thin, glm::dvec3 tint = glm::dvec3(1.0)) {
  dev::Material m{};
  m.type = MATERIAL_GLTF;
  for (int c = 0; c < 3; ++c) m.base_color[c] = float(tint[c]);
  m.base_color[3] = 1.0f;
  for (int c = 0; c < 3; ++c) m.params.gltf.specular_color[c] = 1.0f;
  m.params.gltf.specular = 1.0f;
  m.params.gltf.ior = 1.5f;
  m.params.gltf.roughness = float(roughness);
  m.params.gltf.transmission = 1.0f;
  if (thin) m.flags |= MATERIAL_THIN_WALLED;
  for (dev::TextureRef& t : m.textures) {
    t.index = NO_TEXTURE;
    t.m[0] = t.m[4] = 1.0f;
  }
  return m;
}

struct DielectricRig {
  const KernelRig& rig;
  // From the kernel cache (TableMatchesConvergedQuadrature computes its own afresh)
  GgxAlbedoTable table;
  explicit DielectricRig(const KernelRig& r, AnisotropicAlbedo anisotropic = AnisotropicAlbedo::none)
      : rig(r), table(ggx_albedo_table(r.context, r.queue, r.program, r.program_cache_file, anisotropic)) {}

  std::vector<cl_float2> lookup(const cl::Buffer& tables, const std::vector<cl_float4>& q) {
    auto out = rig.output<cl_float2>(q.size());
    rig.run("test_energy_dielectric_lookup", q.size(), tables, rig.input(q), out);
    return out.read();
  }

  std::vector<float> quadrature(const std::vector<cl_float4>& q, cl_uint n) {
    auto out = rig.output<float>(q.size());
    rig.run("test_energy_dielectric_quadrature", q.size(), rig.input(q), n, out);
    return out.read();
  }

  // Per sample: (X |cos| / pdf, agrees with eval), (wi, pdf)
  std::vector<cl_float4> sample(const dev::Material& m, bool with_table, bool front, glm::dvec3 wo, cl_uint seed,
                                size_t n = kAlbedoSamples) {
    auto out = rig.output<cl_float4>(2 * n);
    rig.run("test_energy_dielectric_sample", n, rig.input(std::vector<dev::Material>{m}), table.buffer,
            cl_uint(with_table), cl_uint(front), f4(wo), seed, out);
    return out.read();
  }

  // (X, pdf) for (wo, wi) pairs, each seen from the front or the back
  std::vector<cl_float4> eval(const dev::Material& m, const std::vector<std::pair<glm::dvec3, glm::dvec3>>& pairs,
                              const std::vector<bool>& front) {
    std::vector<cl_float4> in;
    for (size_t i = 0; i < pairs.size(); ++i) {
      in.push_back(f4(pairs[i].first, front[i] ? 1.0 : 0.0));
      in.push_back(f4(pairs[i].second));
    }
    auto out = rig.output<cl_float4>(pairs.size());
    rig.run("test_energy_dielectric_eval", pairs.size(), rig.input(std::vector<dev::Material>{m}), table.buffer,
            rig.input(in), out);
    return out.read();
  }
};

DielectricRig& dielectric_rig() {
  static DielectricRig r(kernel_rig("pocl"));
  return r;
}

// The program with CD_FEATURE_ANISOTROPY and the anisotropic glass table integrated
DielectricRig& anisotropic_dielectric_rig() {
  static DielectricRig r(anisotropic_kernel_rig(), AnisotropicAlbedo::exact_glass);
  return r;
}

// glTF glass with KHR_materials_anisotropy (rotation 0: the major axis along the tangent, +x)
dev::Material anisotropic_glass(double roughness, double strength, bool thin) {
  dev::Material m = glass(roughness, thin);
  m.params.gltf.anisotropy_strength = float(strength);
  return m;
}

glm::dvec3 at_angles(double theta_deg, double phi_deg) {
  double t = theta_deg * kPi / 180.0, p = phi_deg * kPi / 180.0;
  return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

// The side wo is seen from: a thin sheet's, outside or inside a solid
const char* side_name(bool thin, bool front) { return thin ? "thin sheet" : front ? "outside" : "inside"; }

struct Albedo {
  Estimate channel[3];
  size_t disagree = 0;  // samples whose f or pdf differ from eval's
};

Albedo albedo(DielectricRig& r, const dev::Material& m, bool with_table, bool front, glm::dvec3 wo, cl_uint seed) {
  std::vector<cl_float4> s = r.sample(m, with_table, front, wo, seed);
  Albedo a;
  std::vector<cl_float4> w(kAlbedoSamples);
  for (size_t i = 0; i < kAlbedoSamples; ++i) {
    w[i] = s[2 * i];
    if (s[2 * i + 1].s[3] > 0.0f && s[2 * i].s[3] != 1.0f) ++a.disagree;
  }
  for (int c = 0; c < 3; ++c) a.channel[c] = sample_mean(w, c);
  return a;
}

}  // namespace

// The table as looked up, between its nodes, against the converged quadrature (256^2
// points) of E_s(mu, roughness, eta) from both sides
TEST(EnergyDielectric, TableMatchesConvergedQuadrature) {
  DielectricRig& r = dielectric_rig();
  GgxAlbedoTable fresh = ggx_albedo_table(r.rig.context, r.rig.queue, r.rig.program, "");
  std::printf("GGX and dielectric albedo tables computed in %.3f s\n", fresh.seconds);
  std::vector<cl_float4> q;
  for (float eta : {1.33f, 1.5f, 2.4f, 1.0f / 1.33f, 1.0f / 1.5f, 1.0f / 2.4f})
    for (float roughness : {0.1f, 0.35f, 0.7f, 1.0f})
      for (float mu : {0.05f, 0.3f, 0.62f, 0.9f, 1.0f}) q.push_back({{mu, roughness, eta, 0.0f}});
  std::vector<cl_float2> looked = r.lookup(fresh.buffer, q);
  std::vector<float> converged = r.quadrature(q, 256);
  double worst = 0.0;
  for (size_t k = 0; k < q.size(); ++k) {
    double err = std::fabs(double(looked[k].s[0]) - converged[k]);
    worst = std::max(worst, err);
    EXPECT_NEAR(looked[k].s[0], converged[k], 6e-3)
        << "mu " << q[k].s[0] << " roughness " << q[k].s[1] << " eta " << q[k].s[2];
    EXPECT_GE(looked[k].s[1], 0.0f);
    EXPECT_LE(looked[k].s[1], 1.0f);
  }
  std::printf(
      "worst lookup error %.2e over %zu queries; e.g. eta 1.5 roughness 1: E(1) %.4f, E_avg %.4f; "
      "inside: E(1) %.4f, E_avg %.4f\n",
      worst, q.size(), looked[39].s[0], looked[39].s[1], looked[99].s[0], looked[99].s[1]);
}

// The anisotropic table (a program with CD_FEATURE_ANISOTROPY) as looked up against the
// converged quadrature (64^2 points) of E_s(wo) for the lobes KHR_materials_anisotropy
// makes (ax = mix(alpha, 1, strength^2), ay = alpha), from both sides, at azimuths from the
// major axis (0) to the minor one (90); and the average E_s,avg within [0, 1]
TEST(EnergyDielectric, AnisotropicTableMatchesConvergedQuadrature) {
  DielectricRig& r = anisotropic_dielectric_rig();
  // Interpolation over five dimensions (up to 0.016 at the queries below: near the onset of
  // total internal reflection of line-shaped lobes, seen from inside) and the 24^2 quadrature
  const double kAnisoTableTolerance = 0.02;
  std::printf("anisotropic glass table %s in %.3f s\n", r.table.from_cache ? "loaded" : "computed", r.table.seconds);
  double worst = 0.0;
  size_t count = 0;
  for (auto [roughness, strength] : {std::pair{0.1, 1.0}, {0.1, 0.5}, {0.3, 0.7}, {0.5, 1.0}, {0.7, 0.4}}) {
    std::vector<cl_float4> q;
    for (float eta : {1.5f, 1.0f / 1.5f, 1.33f, 1.0f / 2.0f})
      for (double theta : {0.0, 40.0, 70.0, 85.0})
        for (double phi : {0.0, 35.0, 90.0}) {
          if (theta == 0.0 && phi > 0.0) continue;
          q.push_back(f4(at_angles(theta, phi), eta));
        }
    cl_float2 params = {{float(roughness), float(strength)}};
    auto looked_out = r.rig.output<cl_float2>(q.size());
    r.rig.run("test_energy_dielectric_aniso_lookup", q.size(), r.table.buffer, r.rig.input(q), params, looked_out);
    auto converged_out = r.rig.output<float>(q.size());
    r.rig.run("test_energy_dielectric_aniso_quadrature", q.size(), r.rig.input(q), params, cl_uint(64), converged_out);
    std::vector<cl_float2> looked = looked_out.read();
    std::vector<float> converged = converged_out.read();
    double worst_here = 0.0;
    for (size_t k = 0; k < q.size(); ++k) {
      double err = std::fabs(double(looked[k].s[0]) - converged[k]);
      worst_here = std::max(worst_here, err);
      EXPECT_NEAR(looked[k].s[0], converged[k], kAnisoTableTolerance)
          << "roughness " << roughness << " strength " << strength << " wo " << q[k].s[0] << " " << q[k].s[1] << " "
          << q[k].s[2] << " eta " << q[k].s[3];
      EXPECT_GE(looked[k].s[1], 0.0f);
      EXPECT_LE(looked[k].s[1], 1.0f);
    }
    std::printf("  roughness %.1f strength %.1f: worst lookup error %.4f over %zu directions and etas\n", roughness,
                strength, worst_here, q.size());
    worst = std::max(worst, worst_here);
    count += q.size();
  }
  std::printf("worst anisotropic lookup error %.4f over %zu queries\n", worst, count);
}

// White anisotropic glass (solid) returns every photon too, by bsdf_sample weights: from
// outside and inside, along both axes; without the table it loses up to about half
TEST(EnergyDielectric, WhiteAnisotropicGlassAlbedoIsOne) {
  DielectricRig& r = anisotropic_dielectric_rig();
  cl_uint seed = 700;
  double lowest_without = 1.0;
  for (bool front : {true, false})
    for (auto [roughness, strength] : {std::pair{0.1, 1.0}, {0.1, 0.5}, {0.4, 1.0}, {0.7, 0.5}})
      for (double theta : {0.0, 45.0, 75.0})
        for (double phi : {0.0, 90.0}) {
          if (theta == 0.0 && phi > 0.0) continue;
          dev::Material white = anisotropic_glass(roughness, strength, false);
          Albedo with = albedo(r, white, true, front, at_angles(theta, phi), seed++);
          Albedo without = albedo(r, white, false, front, at_angles(theta, phi), seed++);
          std::printf("  %-7s roughness %.1f strength %.1f theta %2.0f phi %2.0f: X-albedo %.5f +- %.5f, %.5f not\n",
                      side_name(false, front), roughness, strength, theta, phi, with.channel[1].mean,
                      with.channel[1].standard_error, without.channel[1].mean);
          EXPECT_EQ(with.disagree, 0u);
          lowest_without = std::min(lowest_without, without.channel[1].mean);
          for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(with.channel[c].mean, 1.0, 4.0 * with.channel[c].standard_error + 0.015)
                << side_name(false, front) << " roughness " << roughness << " strength " << strength << " theta "
                << theta << " phi " << phi;
        }
  std::printf("lowest X-albedo without the table %.4f\n", lowest_without);
  EXPECT_LT(lowest_without, 0.8);  // the cases are ones where compensation matters
}

// White glass returns every photon: X-albedo 1 from outside, from inside (total internal
// reflection included) and for a thin sheet, at every roughness and angle, by bsdf_sample
// weights; without the table it loses light at high roughness; tinted glass stays <= 1;
// every sample's f and pdf are eval's
TEST(EnergyDielectric, WhiteGlassAlbedoIsOneFromBothSides) {
  DielectricRig& r = dielectric_rig();
  cl_uint seed = 1;
  for (bool thin : {false, true})
    for (bool front : {true, false}) {
      if (thin && !front) continue;  // a sheet is the same from both faces
      for (double roughness : {0.1, 0.4, 0.7, 1.0})
        for (double theta : {0.0, 45.0, 70.0, 87.0}) {
          dev::Material white = glass(roughness, thin), tinted = glass(roughness, thin, {0.9, 0.5, 0.2});
          Albedo with = albedo(r, white, true, front, at_angle(theta), seed++);
          Albedo without = albedo(r, white, false, front, at_angle(theta), seed++);
          Albedo tint = albedo(r, tinted, true, front, at_angle(theta), seed++);
          std::printf("  %-10s roughness %.1f theta %2.0f: X-albedo %.5f +- %.5f compensated, %.5f not; tinted %.4f\n",
                      side_name(thin, front), roughness, theta, with.channel[1].mean, with.channel[1].standard_error,
                      without.channel[1].mean, tint.channel[0].mean);
          EXPECT_EQ(with.disagree, 0u);
          EXPECT_EQ(tint.disagree, 0u);
          for (int c = 0; c < 3; ++c) {
            const Estimate& e = with.channel[c];
            EXPECT_NEAR(e.mean, 1.0, 4.0 * e.standard_error + 0.01)
                << side_name(thin, front) << " " << roughness << " theta " << theta;
            EXPECT_LE(tint.channel[c].mean, 1.0 + 4.0 * tint.channel[c].standard_error + 0.01);
            EXPECT_LE(without.channel[c].mean, 1.0 + 4.0 * without.channel[c].standard_error);
          }
          if (roughness == 1.0 && theta == 0.0) {
            EXPECT_LT(without.channel[1].mean, 0.95);
          }
        }
    }
}

// The compensated lobe through the harness's sampling checks (check_sampling, with the table
// bound): rough glass of roughness 0.3, 0.7 and 1, solid and thin-walled, seen from outside
// (50 degrees) and from inside (30 degrees; and 65, beyond the critical angle, for the
// solid), 1M samples each. Sampled directions, the compensation lobe's cosine samples on
// the side its reflection share picks included, follow bsdf_pdf (chi-square over the
// sphere, cells around the mirror and the refracted or straight-through direction); the
// pdf integrates to at most 1 and to the fraction of samples returned; every sample's f and
// pdf are bsdf_eval's and bsdf_pdf's and its weight is bsdf_eval |cos| / bsdf_pdf; the
// eta^2-weighted albedo stays at most 1 + 4 SE, but for the rows noted below (the test is
// then marked skipped with the note, as the harness does with known kernel bugs)
TEST(EnergyDielectric, CompensatedRoughGlassSamplesItsPdf) {
  DielectricRig& r = dielectric_rig();
  const std::string excess =
      "the compensated lobe returns slightly more than 1 from inside rough glass of roughness 0.3 "
      "(eta^2-weighted albedo 1.0029 +- 0.0001 at 30 degrees, 1.0014 +- 0.0002 at 65 on PoCL, 1M samples): "
      "within the dielectric table's lookup error (4.2e-3, TableMatchesConvergedQuadrature) and the 0.01 that "
      "WhiteGlassAlbedoIsOneFromBothSides allows";
  KnownBugs bugs;
  for (bool thin : {false, true})
    for (double roughness : {0.3, 0.7, 1.0}) {
      CellSpec cells = roughness < 0.5 ? kNarrow : kGlossy;
      if (thin) cells.transmission = Focus::Straight;
      std::string name = std::string(thin ? "thin_" : "") + "glass_r" + std::to_string(roughness).substr(0, 3);
      MaterialCase mat = gltf_case(name, glass(roughness, thin), cells);
      if (!thin && roughness == 0.3) mat.bugs = {{"albedo/inside30", excess}, {"albedo/inside65", excess}};
      for (auto [theta, back] : {std::pair{50.0, false}, {30.0, true}, {65.0, true}}) {
        if (thin && theta == 65.0) continue;  // a sheet has no critical angle
        Geometry g = flat(theta, back);
        g.name = (back ? "inside" : "outside") + std::to_string(int(theta));
        SCOPED_TRACE(name + " " + g.name);
        check_sampling("pocl", BsdfRun(r.rig, mat.material, g, r.table.buffer), mat, bugs);
      }
    }
  BSDF_SKIP_KNOWN_BUGS(bugs);
}

// The eval-based estimator: X(wo, wi) |cos_i| integrated over the sphere with wi uniform
// (no sampling code involved) is 1 for white glass; and Y = f / n_o^2 is reciprocal:
// Y(wo, wi) seen from wo's side equals Y(wi, wo) seen from wi's side, for reflections on
// both sides and transmissions both ways
TEST(EnergyDielectric, EvalIsReciprocalAndConservesEnergy) {
  DielectricRig& r = dielectric_rig();
  std::mt19937_64 gen(11);
  std::uniform_real_distribution<double> uni;
  auto sphere = [&] {
    double z = 2.0 * uni(gen) - 1.0, phi = 2.0 * kPi * uni(gen), rr = std::sqrt(std::max(0.0, 1.0 - z * z));
    return glm::dvec3(rr * std::cos(phi), rr * std::sin(phi), z);
  };
  for (bool thin : {false, true})
    for (double roughness : {0.4, 0.7, 1.0}) {
      dev::Material m = glass(roughness, thin);
      // Energy: 2^18 uniform directions per wo, both sides
      for (bool front : {true, false})
        for (double theta : {0.0, 60.0}) {
          if (thin && !front) continue;
          const size_t n = 1 << 18;
          std::vector<std::pair<glm::dvec3, glm::dvec3>> pairs;
          for (size_t k = 0; k < n; ++k) pairs.emplace_back(at_angle(theta), sphere());
          std::vector<cl_float4> x = r.eval(m, pairs, std::vector<bool>(n, front));
          std::vector<cl_float4> w(n);
          for (size_t k = 0; k < n; ++k) {
            double s = 4.0 * kPi * std::fabs(pairs[k].second.z);
            w[k] = {{float(x[k].s[0] * s), float(x[k].s[1] * s), float(x[k].s[2] * s), 0.0f}};
          }
          Estimate e = sample_mean(w, 1);
          std::printf("  eval-based X-albedo, %-10s roughness %.1f theta %2.0f: %.4f +- %.4f\n", side_name(thin, front),
                      roughness, theta, e.mean, e.standard_error);
          EXPECT_NEAR(e.mean, 1.0, 4.0 * e.standard_error + 0.01);
        }
      // Reciprocity: random pairs, wo from the front or the back; the swapped pair is seen
      // from wi's side (the back when wi transmits through a volumetric interface)
      std::vector<std::pair<glm::dvec3, glm::dvec3>> pairs, swapped;
      std::vector<bool> front, front_swapped;
      for (int k = 0; k < 4096; ++k) {
        glm::dvec3 wo = sphere(), wi = sphere();
        wo.z = std::fabs(wo.z) + 0.01;
        wo = glm::normalize(wo);
        if (std::fabs(wi.z) < 0.01) continue;
        bool f = uni(gen) < 0.5;
        pairs.emplace_back(wo, wi);
        front.push_back(f);
        glm::dvec3 wo2 = wi, wi2 = wo;
        bool f2 = f;
        if (wi.z < 0.0) {  // the other side: its frame faces wi
          wo2 = -wi;
          wi2 = -wo;
          f2 = thin ? f : !f;
        }
        swapped.emplace_back(wo2, wi2);
        front_swapped.push_back(f2);
      }
      std::vector<cl_float4> x1 = r.eval(m, pairs, front), x2 = r.eval(m, swapped, front_swapped);
      size_t unequal = 0;
      for (size_t k = 0; k < pairs.size(); ++k) {
        double y1 = x1[k].s[3], y2 = x2[k].s[3];
        if (std::fabs(y1 - y2) > 1e-4 * std::max(std::fabs(y1), std::fabs(y2)) + 1e-7 && ++unequal <= 3)
          ADD_FAILURE() << (thin ? "thin " : "") << roughness << ": Y " << y1 << " vs " << y2 << " wo.z "
                        << pairs[k].first.z << " wi.z " << pairs[k].second.z << " front " << front[k];
      }
      EXPECT_EQ(unequal, 0u) << (thin ? "thin " : "volumetric ") << roughness << ": Y(wo, wi) != Y(wi, wo)";
    }
}

// The clear coat (cl/bsdf/gltf/coat.cl): a white Lambert base under a clear coat (factor 1,
// ior 1.5) reflects >= 98 % at every angle and coat roughness with compensation (the light
// trapped under the coat is returned), and under 1 without it at some angle; a white
// plastic base (its own specular layer) under the coat stays <= 1
TEST(EnergyClearcoat, WhiteLambertUnderClearCoatReflectsAll) {
  DielectricRig& r = dielectric_rig();
  cl_uint seed = 900;
  for (double coat_roughness : {0.0, 0.3, 0.7, 1.0}) {
    double worst_without = 1.0;
    for (double theta : {0.0, 45.0, 75.0, 88.0}) {
      dev::Material lambert = glass(0.5, false);
      lambert.params.gltf.transmission = 0.0f;
      lambert.params.gltf.specular = 0.0f;  // specular 0: a Lambert base
      lambert.params.gltf.clearcoat = 1.0f;
      lambert.params.gltf.clearcoat_roughness = float(coat_roughness);
      dev::Material plastic = lambert;
      plastic.params.gltf.specular = 1.0f;
      Albedo with = albedo(r, lambert, true, true, at_angle(theta), seed++);
      Albedo without = albedo(r, lambert, false, true, at_angle(theta), seed++);
      Albedo over_plastic = albedo(r, plastic, true, true, at_angle(theta), seed++);
      std::printf(
          "  clear coat roughness %.1f theta %2.0f: Lambert base %.5f +- %.5f compensated, %.5f not; "
          "plastic base %.5f\n",
          coat_roughness, theta, with.channel[1].mean, with.channel[1].standard_error, without.channel[1].mean,
          over_plastic.channel[1].mean);
      EXPECT_EQ(with.disagree, 0u);
      EXPECT_EQ(over_plastic.disagree, 0u);
      worst_without = std::min(worst_without, without.channel[1].mean);
      for (int c = 0; c < 3; ++c) {
        EXPECT_GE(with.channel[c].mean, 0.98) << "coat roughness " << coat_roughness << " theta " << theta;
        EXPECT_LE(with.channel[c].mean, 1.0 + 4.0 * with.channel[c].standard_error + 3e-3);
        EXPECT_LE(over_plastic.channel[c].mean, 1.0 + 4.0 * over_plastic.channel[c].standard_error + 3e-3);
        EXPECT_LE(without.channel[c].mean, 1.0 + 4.0 * without.channel[c].standard_error);
      }
    }
    EXPECT_LT(worst_without, 0.97) << "coat roughness " << coat_roughness;
  }
}

class EnergyGlassFurnace : public ::testing::TestWithParam<std::string> {};

// White furnace: white glass spheres (transmission 1, ior 1.5), solid (KHR_materials_volume)
// and thin-walled, at roughness 0.1 to 1, and anisotropic ones (strength 1, roughness 0.1
// and 0.4; PoCL) under a background of 1 render as 1 within 2 % with compensation; without
// it the roughest and the most anisotropic lose light
TEST_P(EnergyGlassFurnace, WhiteRoughGlassSpheresVanish) {
  DeviceEntry device;
  CANDELA_DEVICE_OR_SKIP(GetParam(), device);
  for (double strength : {0.0, 1.0})
    for (bool thin : {false, true})
      for (double roughness : {0.1, 0.4, 0.7, 1.0}) {
        // Anisotropic glass (its own table, computed in minutes on rusticl): PoCL, two roughnesses
        if (strength > 0.0 && (GetParam() != "pocl" || roughness > 0.4)) continue;
        GltfBuilder g;
        json ext = {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}}};
        if (!thin) ext["KHR_materials_volume"] = {{"thicknessFactor", 1.0}};
        if (strength > 0.0) ext["KHR_materials_anisotropy"] = {{"anisotropyStrength", strength}};
        int mat = g.add("materials",
                        {{"pbrMetallicRoughness",
                          {{"baseColorFactor", {1, 1, 1, 1}}, {"metallicFactor", 0.0}, {"roughnessFactor", roughness}}},
                         {"extensions", ext}});
        g.add_node({{"mesh", g.add_mesh({sphere_primitive(glm::vec3(0.0f), 1.0f, 3, mat)})}});
        g.add_camera({0, 0, 3.2f}, {0, 0, 0}, 0.75f);
        g.set_background({1, 1, 1});
        std::string path = ::testing::TempDir() + "energy-glass-furnace-" + GetParam() + ".gltf";
        g.write(path);
        Scene scene = load_gltf(path);
        for (bool compensate : {true, false}) {
          // Without compensation: the roughest isotropic and the most anisotropic solid sphere
          if (!compensate && !(strength > 0.0 ? !thin && roughness == 0.1 : roughness == 1.0)) continue;
          RenderSettings s;
          s.width = s.height = 32;
          s.strategy = Strategy::Bsdf;
          s.max_depth = 128;
          s.energy_compensation = compensate;
          s.seed = 9;
          Renderer renderer = scene_renderer(device, scene, s);
          RenderResult res = renderer.render(0, 256);
          Estimate e = region_mean(res.film, 1, 8, 24, 8, 24);
          std::printf("%s glass, roughness %.1f, anisotropy %.1f, compensation %s: sphere mean %.5f +- %.5f\n",
                      thin ? "thin" : "solid", roughness, strength, compensate ? "on" : "off", e.mean,
                      e.standard_error);
          EXPECT_LT(e.standard_error, 5e-3);
          if (compensate) {
            EXPECT_NEAR(e.mean, 1.0, 0.02 + 3.0 * e.standard_error);
          } else {
            EXPECT_LT(e.mean, 0.9);
          }
          EXPECT_EQ(res.film.dropped_samples(), 0u);
        }
      }
}

INSTANTIATE_TEST_SUITE_P(Devices, EnergyGlassFurnace, ::testing::Values("pocl", "rusticl"),
                         [](const auto& info) { return std::string(info.param); });

}  // namespace candela::test
