// Fresnel (cl/bsdf/fresnel.cl) and Trowbridge-Reitz / GGX (cl/bsdf/microfacet.cl) kernel routines
// against host formulas in double (tests/bsdf/test_microfacet.cl runs them):
//  - Fresnel: the dielectric r_s, r_p (PBRT 4th ed. sec. 9.3); Snell's law and total internal reflection;
//    conductors against the exact complex-index Fresnel equations (std::complex);
//  - GGX: D and Lambda against Walter et al. 2007's angular forms, D and the visible-normal
//    density D_w normalized (quadrature), ggx_sample_visible against D_w (chi-square,
//    1M samples, cells with expected count < 5 pooled, alpha = 0.01 with the Sidak
//    correction over this file's chi-square tests) and a wrong-alpha negative control.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <glm/glm.hpp>
#include <random>

#include "support/reference.hpp"
#include "support/stats.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

constexpr size_t kSamples = 1 << 20;

struct Alpha {
  double x, y;
};
const std::vector<Alpha> kAlphas = {{0.05, 0.05}, {0.2, 0.2}, {0.6, 0.6}, {1.0, 1.0}, {0.1, 0.5}};
const std::vector<double> kIncidenceDeg = {15.0, 45.0, 80.0};

// Chi-square tests of the file: devices x alphas x incidences
const double kAlpha = sidak_alpha(0.01, int(2 * kAlphas.size() * kIncidenceDeg.size()));

// A direction as the kernel receives it (rounded to float)
glm::dvec3 as_float(glm::dvec3 v) { return d3(f4(v)); }

glm::dvec3 spherical(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}
double deg(double d) { return d * kPi / 180.0; }

// --- Host references (double), beside those of support/reference.hpp ---

// The approximate conductor formula of PBRT 2nd ed. (good where eta^2 + k^2 >> 1)
double fresnel_conductor_lecture(double c, double eta, double k) {
  double a = eta * eta + k * k;
  double rp2 = (a * c * c - 2.0 * eta * c + 1.0) / (a * c * c + 2.0 * eta * c + 1.0);
  double rs2 = (a - 2.0 * eta * c + c * c) / (a + 2.0 * eta * c + c * c);
  return 0.5 * (rp2 + rs2);
}

// --- Kernels ------------------------------------------------------------------------

// D(m), Lambda(w), G1(w), D_w(m), G(w, m), Lambda(m) for pairs (w, m)
struct GgxValues {
  double d, lambda_w, g1_w, visible_d, g, lambda_m;
};

std::vector<float> dielectric(const KernelRig& rig, const std::vector<cl_float2>& in) {
  auto out = rig.output<float>(in.size());
  rig.run("test_fresnel_dielectric", in.size(), rig.input(in), out);
  return out.read();
}

std::vector<cl_float4> conductor(const KernelRig& rig, glm::dvec3 eta, glm::dvec3 kappa,
                                 const std::vector<float>& cos_i) {
  auto out = rig.output<cl_float4>(cos_i.size());
  rig.run("test_fresnel_conductor", cos_i.size(), f4(eta), f4(kappa), rig.input(cos_i), out);
  return out.read();
}

cl_float2 alpha2(Alpha a) { return {{float(a.x), float(a.y)}}; }

std::vector<GgxValues> ggx(const KernelRig& rig, Alpha a, const std::vector<std::pair<glm::dvec3, glm::dvec3>>& wm) {
  std::vector<cl_float4> in;
  in.reserve(2 * wm.size());
  for (const auto& [w, m] : wm) {
    in.push_back(f4(w));
    in.push_back(f4(m));
  }
  auto out = rig.output<cl_float4>(2 * wm.size());
  rig.run("test_ggx_eval", wm.size(), alpha2(a), rig.input(in), out);
  std::vector<cl_float4> o = out.read();
  std::vector<GgxValues> v(wm.size());
  for (size_t i = 0; i < wm.size(); ++i)
    v[i] = {o[2 * i].s[0], o[2 * i].s[1], o[2 * i].s[2], o[2 * i].s[3], o[2 * i + 1].s[0], o[2 * i + 1].s[1]};
  return v;
}

std::vector<glm::dvec3> sample_visible(const KernelRig& rig, Alpha a, glm::dvec3 w, cl_uint seed) {
  auto out = rig.output<cl_float4>(kSamples);
  rig.run("test_ggx_sample_visible", kSamples, alpha2(a), f4(w), seed, out);
  std::vector<cl_float4> v = out.read();
  std::vector<glm::dvec3> m;
  m.reserve(kSamples);
  for (const auto& s : v) m.push_back(d3(s));
  return m;
}

class MicrofacetTest : public DeviceTest {};

// Hemisphere quadrature of f(m) dw: midpoint rule in t = sqrt(1 - cos theta) (dcos = 2t dt),
// which crowds points toward the pole where the narrow lobes live
struct HemisphereGrid {
  int nt = 2000, nphi = 256;
  std::vector<glm::dvec3> dirs() const {
    std::vector<glm::dvec3> d;
    d.reserve(size_t(nt) * nphi);
    for (int i = 0; i < nt; ++i) {
      double t = (i + 0.5) / nt, z = 1.0 - t * t, r = std::sqrt(std::max(0.0, 1.0 - z * z));
      for (int j = 0; j < nphi; ++j) {
        double phi = (j + 0.5) * 2.0 * kPi / nphi;
        d.push_back({r * std::cos(phi), r * std::sin(phi), z});
      }
    }
    return d;
  }
  double weight(size_t index) const {
    double t = (int(index / nphi) + 0.5) / nt;
    return 2.0 * t / nt * 2.0 * kPi / nphi;
  }
};

// Cells of the chi-square test over the stretched normal n = normalize(m.x / ax, m.y / ay,
// m.z), in (cos theta, phi) of n: Heitz 2018 samples exactly this hemisphere (the alpha = 1
// configuration), where D_w is the same smooth, bounded density for every alpha. Cells
// uniform there follow the lobe however narrow it is (alpha = 0.05 gets as many populated
// cells as alpha = 1), and the midpoint rule over sub-cells stays accurate.
struct StretchedCells {
  Alpha a;
  int n_cos = 20, n_phi = 40, sub = 8;

  size_t size() const { return size_t(n_cos) * n_phi; }
  size_t index(glm::dvec3 m) const {
    glm::dvec3 n = glm::normalize(glm::dvec3(m.x / a.x, m.y / a.y, m.z));
    double phi = std::atan2(n.y, n.x);
    if (phi < 0.0) phi += 2.0 * kPi;
    int i = std::clamp(int(std::clamp(n.z, 0.0, 1.0) * n_cos), 0, n_cos - 1);
    int j = std::clamp(int(phi / (2.0 * kPi) * n_phi), 0, n_phi - 1);
    return size_t(i) * n_phi + j;
  }
  // Integral over each cell of D_w(m) dw_m = D_w(m(n)) |dw_m / dw_n| dw_n, where for
  // m = M n / |M n|, M = diag(ax, ay, 1): dw_m / dw_n = det M / |M n|^3
  std::vector<double> integrals(
      const std::function<std::vector<double>(const std::vector<glm::dvec3>&)>& visible_d) const {
    int nc = n_cos * sub, np = n_phi * sub;
    double dz = 1.0 / nc, dphi = 2.0 * kPi / np;
    std::vector<glm::dvec3> ms;
    std::vector<double> jac;
    for (int i = 0; i < nc; ++i) {
      double z = (i + 0.5) * dz, r = std::sqrt(1.0 - z * z);
      for (int j = 0; j < np; ++j) {
        double phi = (j + 0.5) * dphi;
        glm::dvec3 mn(a.x * r * std::cos(phi), a.y * r * std::sin(phi), z);
        double len = glm::length(mn);
        ms.push_back(mn / len);
        jac.push_back(a.x * a.y / (len * len * len));
      }
    }
    std::vector<double> d = visible_d(ms), cells(size(), 0.0);
    for (int i = 0; i < nc; ++i)
      for (int j = 0; j < np; ++j) {
        size_t k = size_t(i) * np + j;
        cells[size_t(i / sub) * n_phi + j / sub] += d[k] * jac[k] * dz * dphi;
      }
    return cells;
  }
};

// Samples of ggx_sample_visible with alpha `sampled` from w, histogrammed on the cells of
// alpha `hypothesis` against D_w of that alpha; *cell_sum = the cells' total probability
ChiSquare visible_chi_square(const KernelRig& rig, Alpha sampled, Alpha hypothesis, glm::dvec3 w, double* cell_sum) {
  StretchedCells cells{hypothesis};
  std::vector<double> expected = cells.integrals([&](const std::vector<glm::dvec3>& ms) {
    std::vector<std::pair<glm::dvec3, glm::dvec3>> wm;
    wm.reserve(ms.size());
    for (const auto& m : ms) wm.emplace_back(w, m);
    std::vector<double> d;
    d.reserve(ms.size());
    for (const GgxValues& v : ggx(rig, hypothesis, wm)) d.push_back(v.visible_d);
    return d;
  });
  *cell_sum = 0.0;
  for (double& e : expected) {
    *cell_sum += e;
    e *= kSamples;
  }
  std::vector<double> observed(cells.size(), 0.0);
  for (const glm::dvec3& m : sample_visible(rig, sampled, w, 1234)) observed[cells.index(m)] += 1.0;
  return chi_square_test(observed, expected);
}

}  // namespace

TEST_P(MicrofacetTest, FresnelDielectricAtNormalIncidence) {
  std::vector<float> f = dielectric(rig(), {{{1.0f, 1.5f}}, {{1.0f, 1.0f / 1.5f}}, {{1.0f, 1.0f}}});
  EXPECT_NEAR(f[0], 0.04, 1e-6);
  EXPECT_NEAR(f[1], 0.04, 1e-6);  // the same from the dense side
  EXPECT_NEAR(f[2], 0.0, 1e-7);   // index-matched
}

// Beyond the critical angle asin(1 / 1.5) exactly 1; just inside it below 1
TEST_P(MicrofacetTest, FresnelDielectricTotalInternalReflection) {
  const double critical = std::asin(1.0 / 1.5);
  std::vector<cl_float2> in;
  std::vector<double> theta;
  for (int i = 0; i <= 200; ++i) {
    double th = critical + 1e-4 + (kPi / 2.0 - critical - 1e-4) * i / 200.0;
    theta.push_back(th);
    in.push_back({{float(std::cos(th)), float(1.0 / 1.5)}});
  }
  in.push_back({{float(std::cos(critical - 0.01)), float(1.0 / 1.5)}});
  std::vector<float> f = dielectric(rig(), in);
  for (size_t i = 0; i < theta.size(); ++i) EXPECT_EQ(f[i], 1.0f) << "theta " << theta[i] * 180.0 / kPi;
  EXPECT_LT(f.back(), 1.0f);
}

// The dielectric r_s, r_p (PBRT 4th ed. sec. 9.3) in double at many angles and relative indices, both sides
TEST_P(MicrofacetTest, FresnelDielectricMatchesLecture) {
  std::vector<cl_float2> in;
  for (double eta : {1.5, 1.33, 2.4, 1.0 / 1.5, 1.0 / 1.33, 1.0 / 2.4})
    for (int i = 0; i <= 400; ++i) in.push_back({{float(std::cos(kPi / 2.0 * i / 400.0)), float(eta)}});
  std::vector<float> f = dielectric(rig(), in);
  size_t bad = 0;
  for (size_t i = 0; i < in.size(); ++i) {
    double ref = fresnel_dielectric(in[i].s[0], in[i].s[1]);
    if (std::fabs(f[i] - ref) > 1e-5 && ++bad <= 5)
      ADD_FAILURE() << "cos " << in[i].s[0] << " eta " << in[i].s[1] << ": " << f[i] << " vs " << ref;
  }
  EXPECT_EQ(bad, 0u);
}

// Refracted directions: unit, on the far side, in the plane of incidence, sin_i = eta sin_t;
// total internal reflection reported exactly where sin_i > eta
TEST_P(MicrofacetTest, FresnelRefractObeysSnell) {
  std::mt19937_64 gen(3);
  std::uniform_real_distribution<double> uni;
  std::vector<cl_float4> in;
  for (double eta : {1.5, 1.33, 1.0 / 1.5, 1.0 / 1.33})
    for (int i = 0; i < 2000; ++i) {
      double cos_i = uni(gen), phi = 2.0 * kPi * uni(gen);
      in.push_back(f4(glm::normalize(spherical(std::acos(cos_i), phi)), eta));
    }
  auto result = rig().output<cl_float4>(in.size());
  rig().run("test_fresnel_refract", in.size(), rig().input(in), result);
  std::vector<cl_float4> out = result.read();
  size_t bad = 0, tir = 0;
  auto fail = [&](size_t i, const std::string& what) {
    if (++bad <= 5)
      ADD_FAILURE() << what << ": w " << in[i].s[0] << " " << in[i].s[1] << " " << in[i].s[2] << " eta " << in[i].s[3]
                    << " -> " << out[i].s[0] << " " << out[i].s[1] << " " << out[i].s[2] << " ok " << out[i].s[3];
  };
  for (size_t i = 0; i < in.size(); ++i) {
    glm::dvec3 w = d3(in[i]), t = d3(out[i]);
    // Sines from the tangential components: 1 - cos^2 cancels near normal incidence
    auto sine = [](glm::dvec3 v) { return std::hypot(v.x, v.y) / glm::length(v); };
    double eta = in[i].s[3], sin_i = sine(w);
    double margin = sin_i / eta - 1.0;
    if (std::fabs(margin) < 1e-5) continue;  // too close to the critical angle to judge in float
    if (margin > 0.0) {
      ++tir;
      if (out[i].s[3] != 0.0f) fail(i, "refracted beyond the critical angle");
      continue;
    }
    if (out[i].s[3] != 1.0f) {
      fail(i, "total internal reflection reported below the critical angle");
      continue;
    }
    double sin_t = sine(t);
    if (std::fabs(glm::length(t) - 1.0) > 1e-6) fail(i, "not unit");
    if (!(t.z < 0.0)) fail(i, "not on the far side");
    if (std::fabs(glm::dot(glm::cross(w, glm::dvec3(0, 0, 1)), t)) > 1e-6) fail(i, "out of the plane of incidence");
    if (w.x * t.x + w.y * t.y > 1e-7) fail(i, "not turned to the opposite azimuth");
    if (std::fabs(sin_i - eta * sin_t) > 2e-6 * std::max(1.0, eta)) fail(i, "Snell's law");
  }
  EXPECT_EQ(bad, 0u);
  EXPECT_GT(tir, 1000u) << "total internal reflection must be exercised";
}

// Lecture metals, the loader's presets and a dielectric (k = 0)
struct Metal {
  const char* name;
  glm::dvec3 eta, k;
};
const std::vector<Metal> kMetals = {
    {"gold", {0.143119, 0.374957, 1.44248}, {3.98316, 2.38572, 1.60322}},
    {"silver", {0.155265, 0.116723, 0.138342}, {4.82835, 3.12225, 2.14696}},
    {"aluminium", {1.65746, 0.880369, 0.521229}, {9.22387, 6.26952, 4.837}},
    {"chromium", {4.36968, 2.9167, 1.6547}, {5.20637, 4.23137, 3.75491}},
    {"lecture gold, silver, copper", {0.370, 0.177, 0.617}, {2.820, 3.638, 2.630}},
    {"lecture steel, dielectrics", {2.485, 1.5, 1.33}, {3.433, 0.0, 0.0}},
};

TEST_P(MicrofacetTest, FresnelConductorAtNormalIncidence) {
  for (const Metal& m : kMetals) {
    cl_float4 f = conductor(rig(), m.eta, m.k, {1.0f})[0];
    for (int c = 0; c < 3; ++c) {
      double eta = float(m.eta[c]), k = float(m.k[c]);
      double ref = ((eta - 1.0) * (eta - 1.0) + k * k) / ((eta + 1.0) * (eta + 1.0) + k * k);
      EXPECT_NEAR(f.s[c], ref, 1e-5 * ref + 1e-7) << m.name << " channel " << c;
    }
  }
}

// The exact complex-index Fresnel equations at many angles (and k = 0 equals a dielectric)
TEST_P(MicrofacetTest, FresnelConductorMatchesComplexFresnel) {
  std::vector<float> cos_i;
  for (int i = 0; i <= 400; ++i) cos_i.push_back(float(std::cos(kPi / 2.0 * i / 400.0)));
  for (const Metal& m : kMetals) {
    std::vector<cl_float4> f = conductor(rig(), m.eta, m.k, cos_i);
    size_t bad = 0;
    for (size_t i = 0; i < cos_i.size(); ++i)
      for (int c = 0; c < 3; ++c) {
        double ref = fresnel_conductor(cos_i[i], float(m.eta[c]), float(m.k[c]));
        if (std::fabs(f[i].s[c] - ref) > 1e-5 && ++bad <= 5)
          ADD_FAILURE() << m.name << " channel " << c << " cos " << cos_i[i] << ": " << f[i].s[c] << " vs " << ref;
      }
    EXPECT_EQ(bad, 0u) << m.name;
  }
}

// Sanity: the approximation for eta^2 + k^2 >> 1 (Pharr and Humphreys, Physically Based
// Rendering, 2nd ed., 2010) lies within a few percent for metals
TEST_P(MicrofacetTest, FresnelConductorNearLectureApproximation) {
  std::vector<float> cos_i;
  for (int d = 0; d <= 85; d += 5) cos_i.push_back(float(std::cos(deg(d))));
  for (size_t mi = 0; mi + 1 < kMetals.size(); ++mi) {
    const Metal& m = kMetals[mi];
    std::vector<cl_float4> f = conductor(rig(), m.eta, m.k, cos_i);
    for (size_t i = 0; i < cos_i.size(); ++i)
      for (int c = 0; c < 3; ++c) {
        double approx = fresnel_conductor_lecture(cos_i[i], m.eta[c], m.k[c]);
        EXPECT_NEAR(f[i].s[c], approx, 0.03 * approx) << m.name << " channel " << c << " cos " << cos_i[i];
      }
  }
}

// D, Lambda, G1 = 1 / (1 + Lambda) and the height-correlated G against Walter et al. 2007's
// angular forms at random directions
TEST_P(MicrofacetTest, GgxMatchesLectureFormulas) {
  std::mt19937_64 gen(5);
  std::uniform_real_distribution<double> uni;
  for (Alpha a : kAlphas) {
    std::vector<std::pair<glm::dvec3, glm::dvec3>> wm;
    for (int i = 0; i < 4096; ++i) {
      // cos theta down to 0.02 for w; m up to where D is still far from underflow
      glm::dvec3 w = as_float(spherical(std::acos(0.02 + 0.98 * uni(gen)), 2.0 * kPi * uni(gen)));
      glm::dvec3 m = as_float(spherical(std::atan(3.0 * std::max(a.x, a.y) * uni(gen)), 2.0 * kPi * uni(gen)));
      wm.emplace_back(w, m);
    }
    std::vector<GgxValues> v = ggx(rig(), a, wm);
    size_t bad = 0;
    for (size_t i = 0; i < wm.size(); ++i) {
      auto [w, m] = wm[i];
      double d = ggx_d_angular(a.x, a.y, m), lw = ggx_lambda_angular(a.x, a.y, w), lm = ggx_lambda_angular(a.x, a.y, m);
      double g1 = 1.0 / (1.0 + lw), g = 1.0 / (1.0 + lw + lm);
      bool ok = std::fabs(v[i].d - d) <= 2e-5 * d && std::fabs(v[i].lambda_w - lw) <= 2e-5 * lw + 1e-6 &&
                std::fabs(v[i].g1_w - g1) <= 1e-5 * g1 && std::fabs(v[i].g - g) <= 1e-5 * g &&
                std::fabs(v[i].lambda_m - lm) <= 2e-5 * lm + 1e-6;
      if (!ok && ++bad <= 5)
        ADD_FAILURE() << "alpha " << a.x << " " << a.y << " w " << w.x << " " << w.y << " " << w.z << " m " << m.x
                      << " " << m.y << " " << m.z << ": D " << v[i].d << " vs " << d << ", Lambda " << v[i].lambda_w
                      << " vs " << lw << ", G1 " << v[i].g1_w << " vs " << g1 << ", G " << v[i].g << " vs " << g;
    }
    EXPECT_EQ(bad, 0u) << "alpha " << a.x << " " << a.y;
  }
}

// Projected microfacet area is the macro-surface's: integral of D(m) cos theta_m dw = 1
TEST_P(MicrofacetTest, GgxDistributionIsNormalized) {
  HemisphereGrid grid;
  std::vector<glm::dvec3> dirs = grid.dirs();
  std::vector<std::pair<glm::dvec3, glm::dvec3>> wm;
  for (const auto& m : dirs) wm.emplace_back(glm::dvec3(0, 0, 1), m);
  for (Alpha a : kAlphas) {
    std::vector<GgxValues> v = ggx(rig(), a, wm);
    double sum = 0.0;
    for (size_t i = 0; i < dirs.size(); ++i) sum += v[i].d * dirs[i].z * grid.weight(i);
    EXPECT_NEAR(sum, 1.0, 2e-4) << "alpha " << a.x << " " << a.y;
  }
}

// The visible normals seen from w are a distribution: integral of D_w(m) dw = 1, i.e.
// G1(w) is consistent with D (Heitz 2014, Understanding the masking-shadowing function)
TEST_P(MicrofacetTest, GgxVisibleNormalsAreNormalized) {
  HemisphereGrid grid;
  std::vector<glm::dvec3> dirs = grid.dirs();
  for (Alpha a : kAlphas)
    for (double theta : {0.0, 30.0, 60.0, 85.0}) {
      glm::dvec3 w = spherical(deg(theta), deg(30.0));
      std::vector<std::pair<glm::dvec3, glm::dvec3>> wm;
      for (const auto& m : dirs) wm.emplace_back(w, m);
      std::vector<GgxValues> v = ggx(rig(), a, wm);
      double sum = 0.0;
      for (size_t i = 0; i < dirs.size(); ++i) sum += v[i].visible_d * grid.weight(i);
      EXPECT_NEAR(sum, 1.0, 2e-4) << "alpha " << a.x << " " << a.y << " theta_w " << theta;
    }
}

// ggx_sample_visible follows ggx_visible_d, for narrow to rough and anisotropic lobes
TEST_P(MicrofacetTest, GgxVisibleSamplesFollowVisibleD) {
  for (Alpha a : kAlphas)
    for (double theta : kIncidenceDeg) {
      glm::dvec3 w = spherical(deg(theta), deg(30.0));
      double cell_sum = 0.0;
      ChiSquare chi2 = visible_chi_square(rig(), a, a, w, &cell_sum);
      std::string where =
          "alpha " + std::to_string(a.x) + " " + std::to_string(a.y) + " theta_w " + std::to_string(theta);
      EXPECT_NEAR(cell_sum, 1.0, 1e-4) << where;
      EXPECT_GT(chi2.p_value, kAlpha) << where << ": chi2 " << chi2.statistic << " dof " << chi2.dof;
    }
}

// Negative control: samples of alpha 0.2 are told apart from D_w of alpha 0.22
TEST_P(MicrofacetTest, ChiSquareRejectsAWrongAlpha) {
  double cell_sum = 0.0;
  ChiSquare chi2 = visible_chi_square(rig(), {0.2, 0.2}, {0.22, 0.22}, spherical(deg(45.0), 0.0), &cell_sum);
  EXPECT_LT(chi2.p_value, 1e-6) << "chi2 " << chi2.statistic << " dof " << chi2.dof;
}

INSTANTIATE_TEST_SUITE_P(Devices, MicrofacetTest, kernel_devices(), DeviceParamName());

}  // namespace candela::test
