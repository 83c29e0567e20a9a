// Chi-square tests of the kernels' sampling routines against their integrated pdfs:
// 1M samples each, cells with expected count < 5 pooled, alpha = 0.01 with the Sidak
// correction over the tests of this file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/glm.hpp>

#include "compile/scene_compiler.hpp"
#include "support/reference.hpp"
#include "support/stats.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

constexpr size_t kSamples = 1 << 20;
constexpr int kTestsInFile = 5;
const double kAlpha = sidak_alpha(0.01, kTestsInFile);

std::vector<cl_float4> run_direction_kernel(const KernelRig& rig, cl_uint which, cl_uint seed) {
  auto out = rig.output<cl_float4>(kSamples);
  rig.run("test_sample_direction", kSamples, which, seed, out);
  return out.read();
}

// Histogram over (cos theta, phi) cells against the pdf integrated over each cell
ChiSquare direction_chi_square(const std::vector<cl_float4>& dirs, double cos_lo, int n_cos, int n_phi,
                               double (*cell_prob)(double, double, double)) {
  std::vector<double> observed(n_cos * n_phi, 0.0), expected(n_cos * n_phi, 0.0);
  double dphi = 2.0 * kPi / n_phi, dcos = (1.0 - cos_lo) / n_cos;
  for (const auto& d : dirs) {
    double z = std::clamp(double(d.s[2]), cos_lo, 1.0);
    double phi = std::atan2(double(d.s[1]), double(d.s[0]));
    if (phi < 0) phi += 2.0 * kPi;
    int i = std::min(n_cos - 1, int((z - cos_lo) / dcos));
    int j = std::min(n_phi - 1, int(phi / dphi));
    observed[i * n_phi + j] += 1.0;
  }
  for (int i = 0; i < n_cos; ++i)
    for (int j = 0; j < n_phi; ++j)
      expected[i * n_phi + j] = dirs.size() * cell_prob(cos_lo + i * dcos, cos_lo + (i + 1) * dcos, dphi);
  return chi_square_test(observed, expected);
}

// Area of the part of triangle (a, b, c) inside the box [x0,x1] x [y0,y1]
double clipped_area(std::vector<glm::dvec2> poly, double x0, double x1, double y0, double y1) {
  auto clip = [&](auto inside, auto cross) {
    std::vector<glm::dvec2> out;
    for (size_t i = 0; i < poly.size(); ++i) {
      glm::dvec2 p = poly[i], q = poly[(i + 1) % poly.size()];
      bool pin = inside(p), qin = inside(q);
      if (pin) out.push_back(p);
      if (pin != qin) out.push_back(cross(p, q));
    }
    poly = out;
  };
  auto at_x = [](double x) {
    return [x](glm::dvec2 p, glm::dvec2 q) { return p + (q - p) * ((x - p.x) / (q.x - p.x)); };
  };
  auto at_y = [](double y) {
    return [y](glm::dvec2 p, glm::dvec2 q) { return p + (q - p) * ((y - p.y) / (q.y - p.y)); };
  };
  clip([&](glm::dvec2 p) { return p.x >= x0; }, at_x(x0));
  clip([&](glm::dvec2 p) { return p.x <= x1; }, at_x(x1));
  clip([&](glm::dvec2 p) { return p.y >= y0; }, at_y(y0));
  clip([&](glm::dvec2 p) { return p.y <= y1; }, at_y(y1));
  double area = 0.0;
  for (size_t i = 0; i < poly.size(); ++i) {
    glm::dvec2 p = poly[i], q = poly[(i + 1) % poly.size()];
    area += p.x * q.y - q.x * p.y;
  }
  return 0.5 * std::fabs(area);
}

class SamplingTest : public ::testing::Test {
 protected:
  const KernelRig& rig() { return kernel_rig("pocl"); }
};

}  // namespace

TEST_F(SamplingTest, CosineHemisphereMatchesPdf) {
  auto dirs = run_direction_kernel(rig(), 0, 1234);
  for (size_t i = 0; i < 1000; ++i) {
    const auto& d = dirs[i];
    ASSERT_NEAR(d.s[0] * d.s[0] + d.s[1] * d.s[1] + d.s[2] * d.s[2], 1.0, 1e-5);
    ASSERT_GE(d.s[2], 0.0f);
    ASSERT_NEAR(d.s[3], cosine_hemisphere_pdf(d.s[2]), 1e-6);
  }
  // Integral of cos(theta)/pi over a cell: dphi / pi * (c1^2 - c0^2) / 2
  auto prob = [](double c0, double c1, double dphi) { return dphi / kPi * 0.5 * (c1 * c1 - c0 * c0); };
  ChiSquare r = direction_chi_square(dirs, 0.0, 20, 40, prob);
  EXPECT_GT(r.p_value, kAlpha) << "chi2 " << r.statistic << " dof " << r.dof;
}

TEST_F(SamplingTest, UniformSphereMatchesPdf) {
  auto dirs = run_direction_kernel(rig(), 1, 99);
  for (size_t i = 0; i < 1000; ++i) ASSERT_NEAR(dirs[i].s[3], uniform_sphere_pdf(), 1e-7);
  auto prob = [](double c0, double c1, double dphi) { return dphi * (c1 - c0) / (4.0 * kPi); };
  ChiSquare r = direction_chi_square(dirs, -1.0, 30, 40, prob);
  EXPECT_GT(r.p_value, kAlpha) << "chi2 " << r.statistic << " dof " << r.dof;
}

TEST_F(SamplingTest, TriangleSamplingIsUniformInArea) {
  glm::dvec2 a(0.1, 0.0), b(1.0, 0.2), c(0.35, 0.9);
  auto out = rig().output<cl_float4>(kSamples);
  rig().run("test_sample_triangle", kSamples, cl_uint(7), f4({a, 0.0}), f4({b, 0.0}), f4({c, 0.0}), out);
  std::vector<cl_float4> pts = out.read();

  const int n = 24;
  double area = 0.5 * std::fabs((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y));
  std::vector<double> observed(n * n, 0.0), expected(n * n, 0.0);
  for (const auto& p : pts) {
    int i = std::clamp(int(p.s[0] * n), 0, n - 1), j = std::clamp(int(p.s[1] * n), 0, n - 1);
    observed[j * n + i] += 1.0;
  }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      expected[j * n + i] =
          kSamples * clipped_area({a, b, c}, double(i) / n, double(i + 1) / n, double(j) / n, double(j + 1) / n) / area;
  ChiSquare r = chi_square_test(observed, expected);
  EXPECT_GT(r.p_value, kAlpha) << "chi2 " << r.statistic << " dof " << r.dof;
}

TEST_F(SamplingTest, RngIsUniform) {
  const size_t n = kSamples / 4;
  auto out = rig().output<float>(4 * n);
  rig().run("test_rng_uniform", n, cl_uint(5), out);
  std::vector<float> u = out.read();
  // Pairs of successive numbers on a 32 x 32 grid: uniformity and independence
  const int g = 32;
  std::vector<double> observed(g * g, 0.0), expected(g * g, double(2 * n) / (g * g));
  for (size_t i = 0; i < 2 * n; ++i) {
    ASSERT_GE(u[2 * i], 0.0f);
    ASSERT_LT(u[2 * i], 1.0f);
    observed[int(u[2 * i] * g) * g + int(u[2 * i + 1] * g)] += 1.0;
  }
  ChiSquare r = chi_square_test(observed, expected);
  EXPECT_GT(r.p_value, kAlpha) << "chi2 " << r.statistic << " dof " << r.dof;
}

// Light selection through the alias table realizes exactly the pmf the estimator divides
// by, even for lights whose power is far below 2^-24 of the total: the chosen indices of
// random integers pass a chi-square test, and an even sweep over the 32-bit range picks
// each light as often as its pmf says
TEST_F(SamplingTest, LightSelectionMatchesItsPmf) {
  for (const std::vector<double>& weights :
       {std::vector<double>{1e-12, 3.0, 0.5, 1e-9, 7.0, 2.0, 1e-3, 0.25, 4.0, 1e-15}, std::vector<double>{1.0},
        std::vector<double>{2.0, 2.0, 2.0}, std::vector<double>{1.0, 1e-20, 5.0, 0.3, 0.3, 9.0, 1e-7}}) {
    std::vector<double> pmf;
    std::vector<dev::AliasBin> bins = alias_table(weights, &pmf);
    ASSERT_EQ(bins.size(), weights.size());
    double total = 0.0, wsum = 0.0;
    for (double w : weights) wsum += w;
    for (size_t i = 0; i < pmf.size(); ++i) {
      EXPECT_GE(pmf[i], 0x1.0p-32) << "light " << i << " can never be picked";
      if (weights[i] / wsum > 1e-6) {
        EXPECT_NEAR(pmf[i], weights[i] / wsum, 1e-9);
      }
      total += pmf[i];
    }
    EXPECT_DOUBLE_EQ(total, 1.0);

    cl::Buffer tb = rig().input(bins);
    auto out = rig().output<cl_uint>(kSamples);
    auto select = [&](cl_uint mode, cl_uint stride) {
      rig().run("test_light_select", kSamples, tb, cl_uint(weights.size()), cl_uint(17), mode, stride, out);
      std::vector<cl_uint> picks = out.read();
      std::vector<double> observed(weights.size(), 0.0);
      for (cl_uint p : picks) {
        EXPECT_LT(p, weights.size());
        if (p < weights.size()) observed[p] += 1.0;
      }
      return observed;
    };
    std::vector<double> observed = select(0, 0), expected(weights.size());
    for (size_t i = 0; i < weights.size(); ++i) expected[i] = pmf[i] * kSamples;
    ChiSquare r = chi_square_test(observed, expected);
    EXPECT_GT(r.p_value, kAlpha) << "chi2 " << r.statistic << " dof " << r.dof;
    // x = i * 2^12 over i < 2^20 visits every 4096th integer: the counts are the pmf's
    // within the sweep's granularity (one integer in 4096 per bin boundary)
    ASSERT_EQ(kSamples, size_t(1) << 20);
    std::vector<double> swept = select(1, 1u << 12);
    for (size_t i = 0; i < weights.size(); ++i)
      EXPECT_NEAR(swept[i], pmf[i] * kSamples, 2.0 * weights.size() + 1.0) << "light " << i;
  }
}

// The test itself must be able to fail: a wrong pdf is rejected
TEST_F(SamplingTest, ChiSquareRejectsAWrongPdf) {
  auto dirs = run_direction_kernel(rig(), 0, 1234);
  auto uniform = [](double c0, double c1, double dphi) { return dphi * (c1 - c0) / (2.0 * kPi); };
  ChiSquare r = direction_chi_square(dirs, 0.0, 20, 40, uniform);
  EXPECT_LT(r.p_value, 1e-6);
}

// A property's value with three significant digits (std::to_string gives six decimals)
std::string format_double(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

// atan2_fast against double-precision atan2 (within two float ulps of pi, 2.4e-7 each):
// every direction of a fine circle at magnitudes from 1e-30 to 1e30, the axes and the
// signed zeros
TEST_F(SamplingTest, Atan2FastIsWithinTwoUlpsOfPi) {
  std::vector<cl_float2> in;
  for (float scale : {1e-30f, 1e-3f, 1.0f, 7.5f, 1e30f})
    for (int k = 0; k < 20000; ++k) {
      double phi = 2.0 * kPi * (k + 0.37) / 20000.0 - kPi;
      in.push_back({{float(scale * std::sin(phi)), float(scale * std::cos(phi))}});
    }
  for (float y : {0.0f, -0.0f, 1.0f, -1.0f})
    for (float x : {0.0f, -0.0f, 2.0f, -2.0f}) in.push_back({{y, x}});
  auto out = rig().output<float>(in.size());
  rig().run("test_atan2_fast", in.size(), rig().input(in), out);
  std::vector<float> got = out.read();
  double worst = 0.0;
  for (size_t i = 0; i < in.size(); ++i) {
    double want = std::atan2(double(in[i].s[0]), double(in[i].s[1]));
    ASSERT_EQ(std::signbit(got[i]), std::signbit(want)) << in[i].s[0] << ", " << in[i].s[1];
    worst = std::max(worst, std::fabs(double(got[i]) - want));
  }
  EXPECT_LT(worst, 4e-7);  // float pi's ulp is 2.4e-7
  RecordProperty("max_error_radians", format_double(worst));
}

// acos_fast against double-precision acos over [-1, 1]: an even sweep, the float grid next
// to -1, 0 and 1 (where the sine is a difference of nearly equal numbers), and the ends;
// beyond them (a dot product of unit vectors a rounding past 1) the ends' angles
TEST_F(SamplingTest, AcosFastIsWithinTwoUlpsOfPi) {
  std::vector<float> in;
  for (int k = 0; k <= 200000; ++k) in.push_back(float(-1.0 + 2.0 * k / 200000.0));
  for (float x : {-1.0f, 0.0f, 1.0f}) {
    float lo = x, hi = x;
    for (int k = 0; k < 2000; ++k) {
      lo = std::nextafter(lo, -2.0f);
      hi = std::nextafter(hi, 2.0f);
      if (lo >= -1.0f) in.push_back(lo);
      if (hi <= 1.0f) in.push_back(hi);
    }
  }
  for (float x : {-1.0f, -0.5f, -0.0f, 0.0f, 0.5f, 1.0f}) in.push_back(x);
  auto out = rig().output<float>(in.size());
  rig().run("test_acos_fast", in.size(), rig().input(in), out);
  std::vector<float> got = out.read();
  double worst = 0.0;
  for (size_t i = 0; i < in.size(); ++i) worst = std::max(worst, std::fabs(double(got[i]) - std::acos(double(in[i]))));
  EXPECT_LT(worst, 4.8e-7);             // two ulps of float pi (2.4e-7 each)
  EXPECT_EQ(got[in.size() - 1], 0.0f);  // acos(1)
  RecordProperty("max_error_radians", format_double(worst));

  std::vector<float> beyond = {std::nextafter(1.0f, 2.0f), 1.5f, std::nextafter(-1.0f, -2.0f), -1.5f};
  auto beyond_out = rig().output<float>(beyond.size());
  rig().run("test_acos_fast", beyond.size(), rig().input(beyond), beyond_out);
  std::vector<float> ends = beyond_out.read();
  EXPECT_EQ(ends[0], 0.0f);
  EXPECT_EQ(ends[1], 0.0f);
  EXPECT_NEAR(ends[2], M_PI, 4.8e-7);
  EXPECT_NEAR(ends[3], M_PI, 4.8e-7);
}

TEST(Stats, GammaQKnownValues) {
  // Chi-square with 2 dof: survival function exp(-x/2)
  EXPECT_NEAR(gamma_q(1.0, 1.5), std::exp(-1.5), 1e-12);
  // Chi-square 95th percentile with 10 dof is 18.307
  EXPECT_NEAR(gamma_q(5.0, 18.307 / 2.0), 0.05, 1e-4);
  EXPECT_NEAR(gamma_q(50.0, 50.0), 0.48119, 2e-4);  // 1/2 - 1/(3 sqrt(2 pi a)) + O(1/a)
}

}  // namespace candela::test
