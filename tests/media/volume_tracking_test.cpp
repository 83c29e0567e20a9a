// Grid media against numbers computed independently on the host, and the volume integrator
// at extreme parameters (issue 8):
//  - tracking against quadrature: a non-linear density grid (17 x 13 x 11 nodes, sums of
//    sines and seeded per-node noise, with empty regions), rays through it, and the
//    transmittance exp(-integral sigma_t) from a double-precision quadrature of the trilinear
//    density written here from the README's definition of node placement. Ratio tracking
//    (shadow rays, media_shadow_transmittance) and delta tracking's free flight (the
//    probability that media_sample_segment, the integrator's distance sampler, reaches the
//    end of the segment in an albedo-1 medium) match it in the mean within 5 standard
//    errors, at optical depths from 0.01 to 30 (transmittance down to 1e-13);
//  - Henyey-Greenstein sampling at g = +-0.99 and +-0.999 against the cdf (Kolmogorov-Smirnov on
//    the deflection angle measured in double precision);
//  - stability: the white furnace (albedo-1 medium in a null boundary under a background of
//    1 renders as 1) at g = +-0.99, very dense (sigma_s = 500: hundreds of scattering events
//    per path) and very thin (sigma_s = 1e-3) media.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "render/renderer.hpp"
#include "support/gltf_builder.hpp"
#include "support/reference.hpp"
#include "support/scenes.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

using nlohmann::json;

json scattering_medium(glm::vec3 sigma_s, double g) {
  return {{"sigma_a", {0, 0, 0}}, {"sigma_s", {sigma_s.x, sigma_s.y, sigma_s.z}}, {"g", g}};
}

Scene load_tracking_scene(const GltfBuilder& g, const std::string& name) {
  return load_scene(g, "volume-tracking-" + name + ".gltf");
}

// --- Tracking against quadrature ---

// The density grid: node i of an axis at lo + i / (n - 1) (hi - lo), trilinear between
// nodes, 0 outside the box (README, "Volumes")
struct HostGrid {
  glm::ivec3 n{17, 13, 11};
  glm::dvec3 lo{-1.0, -0.75, -0.6}, hi{1.0, 0.75, 0.6};
  std::vector<float> v;  // the values the scene holds (floats, x fastest)

  HostGrid() {
    uint32_t h = 12345u;  // seeded per-node noise (a xorshift stream)
    for (int k = 0; k < n.z; ++k)
      for (int j = 0; j < n.y; ++j)
        for (int i = 0; i < n.x; ++i) {
          glm::dvec3 p = node(i, j, k);
          h ^= h << 13;
          h ^= h >> 17;
          h ^= h << 5;
          double noise = double(h >> 8) / double(1u << 24);
          double s = 0.45 + 0.5 * std::sin(2.3 * p.x + 0.4) * std::sin(3.1 * p.y - 0.7) +
                     0.35 * std::cos(4.1 * p.z + 1.9 * p.x) + 0.25 * noise;
          v.push_back(float(std::max(0.0, s)));
        }
  }
  glm::dvec3 node(int i, int j, int k) const { return lo + glm::dvec3(i, j, k) / glm::dvec3(n - 1) * (hi - lo); }
  double value(int i, int j, int k) const { return v[size_t((k * n.y + j) * n.x + i)]; }
  double at(glm::dvec3 p) const {
    glm::dvec3 u = (p - lo) / (hi - lo);
    for (int a = 0; a < 3; ++a)
      if (u[a] < 0.0 || u[a] > 1.0) return 0.0;
    glm::dvec3 g = u * glm::dvec3(n - 1);
    int i = std::min(int(g.x), n.x - 2), j = std::min(int(g.y), n.y - 2), k = std::min(int(g.z), n.z - 2);
    double fx = g.x - i, fy = g.y - j, fz = g.z - k, sum = 0.0;
    for (int dz = 0; dz < 2; ++dz)
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx)
          sum += (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy) * (dz ? fz : 1 - fz) * value(i + dx, j + dy, k + dz);
    return sum;
  }
  // The part [t0, t1] of the ray inside the box, within [0, tmax]
  bool span(glm::dvec3 o, glm::dvec3 d, double tmax, double* t0, double* t1) const {
    *t0 = 0.0;
    *t1 = tmax;
    for (int a = 0; a < 3; ++a) {
      if (d[a] == 0.0) {
        if (o[a] < lo[a] || o[a] > hi[a]) return false;
        continue;
      }
      double ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
      *t0 = std::max(*t0, std::min(ta, tb));
      *t1 = std::min(*t1, std::max(ta, tb));
    }
    return *t0 < *t1;
  }
  // Majorant cells (README): up to 16 per axis splitting the box evenly, each the largest
  // node of the grid cells it overlaps (times density_scale and the largest channel of
  // sigma_t on the device; here in units of the density)
  glm::ivec3 majorant_cells() const { return glm::min(n - 1, glm::ivec3(16)); }
  double majorant_at(glm::dvec3 p) const {
    glm::ivec3 cells = majorant_cells();
    glm::ivec3 c;
    for (int a = 0; a < 3; ++a)
      c[a] = std::clamp(int(std::floor((p[a] - lo[a]) / (hi[a] - lo[a]) * cells[a])), 0, cells[a] - 1);
    int r[3][2];
    for (int a = 0; a < 3; ++a) {
      double m = n[a] - 1;
      r[a][0] = int(std::floor(double(c[a]) / cells[a] * m));
      r[a][1] = std::min(int(std::ceil(double(c[a] + 1) / cells[a] * m)), n[a] - 1);
    }
    double peak = 0.0;
    for (int k = r[2][0]; k <= r[2][1]; ++k)
      for (int j = r[1][0]; j <= r[1][1]; ++j)
        for (int i = r[0][0]; i <= r[0][1]; ++i) peak = std::max(peak, value(i, j, k));
    return peak;
  }
  // Integral of f(p) along o + t d, t in [0, tmax] inside the box: split at every node plane
  // and majorant cell boundary the ray crosses, where the trilinear density along the ray is
  // a cubic in t and the majorant constant, and 4-point Gauss-Legendre on each piece (exact
  // for polynomials of degree 7: the density and its square)
  template <typename F>
  double integrate(glm::dvec3 o, glm::dvec3 d, double tmax, F f) const {
    double t0, t1;
    if (!span(o, d, tmax, &t0, &t1)) return 0.0;
    std::vector<double> cuts = {t0, t1};
    glm::ivec3 cells = majorant_cells();
    for (int a = 0; a < 3; ++a) {
      if (d[a] == 0.0) continue;
      for (int i = 0; i < n[a]; ++i) cuts.push_back((node(i, i, i)[a] - o[a]) / d[a]);
      for (int i = 0; i <= cells[a]; ++i) cuts.push_back((lo[a] + (hi[a] - lo[a]) * i / cells[a] - o[a]) / d[a]);
    }
    std::sort(cuts.begin(), cuts.end());
    const double a1 = std::sqrt(3.0 / 7.0 - 2.0 / 7.0 * std::sqrt(1.2)),
                 a2 = std::sqrt(3.0 / 7.0 + 2.0 / 7.0 * std::sqrt(1.2));
    const double w1 = (18.0 + std::sqrt(30.0)) / 36.0, w2 = (18.0 - std::sqrt(30.0)) / 36.0;
    const double x[4] = {-a2, -a1, a1, a2}, w[4] = {w2, w1, w1, w2};
    double sum = 0.0;
    for (size_t c = 0; c + 1 < cuts.size(); ++c) {
      double a = std::max(cuts[c], t0), b = std::min(cuts[c + 1], t1);
      if (!(b > a)) continue;
      double mid = 0.5 * (a + b), half = 0.5 * (b - a);
      for (int q = 0; q < 4; ++q) sum += half * w[q] * f(o + (mid + half * x[q]) * d);
    }
    return sum;
  }
  double integral(glm::dvec3 o, glm::dvec3 d, double tmax) const {
    return integrate(o, d, tmax, [&](glm::dvec3 p) { return at(p); });
  }
  // Ratio tracking's second moment: tentative collisions form a Poisson process of rate
  // sigma_bar, each multiplying the estimate by 1 - sigma_t / sigma_bar, so
  // E[T^2] = exp(-integral (2 sigma_t - sigma_t^2 / sigma_bar)); sigma_t = scale x density,
  // sigma_bar = scale x majorant x 1.0001
  double ratio_tracking_second_moment(glm::dvec3 o, glm::dvec3 d, double tmax, double scale) const {
    double e = integrate(o, d, tmax, [&](glm::dvec3 p) {
      double st = scale * at(p), sb = scale * majorant_at(p) * 1.0001;
      return sb > 0.0 ? 2.0 * st - st * st / sb : 0.0;
    });
    return std::exp(-e);
  }
  // The same integral by composite Simpson on [t0, t1] (steps intervals): a check of the above
  double simpson(glm::dvec3 o, glm::dvec3 d, double tmax, int steps) const {
    double t0, t1;
    if (!span(o, d, tmax, &t0, &t1)) return 0.0;
    double h = (t1 - t0) / steps, sum = 0.0;
    for (int s = 0; s <= steps; ++s) sum += (s == 0 || s == steps ? 1.0 : s % 2 ? 4.0 : 2.0) * at(o + (t0 + s * h) * d);
    return sum * h / 3.0;
  }
};

struct TrackRay {
  const char* what;
  glm::dvec3 org, dir;
  double tmax;
  bool inside;  // the origin lies in the medium (delta tracking's segment starts there)
};

std::vector<TrackRay> tracking_rays() {
  return {
      {"oblique, ends inside", {-0.7, -0.3, 0.2}, glm::normalize(glm::dvec3(1.0, 0.35, -0.25)), 1.3, true},
      {"from outside, across x", {-1.6, 0.1, -0.05}, glm::normalize(glm::dvec3(1.0, 0.05, 0.02)), INFINITY, false},
      {"backward diagonal, leaves", {0.6, 0.5, -0.4}, glm::normalize(glm::dvec3(-1.0, -0.8, 0.6)), INFINITY, true},
      {"along +y", {0.13, -0.7, 0.05}, {0.0, 1.0, 0.0}, INFINITY, true},
      {"through an empty region", {-0.5, 0.2, -0.3}, glm::normalize(glm::dvec3(1.1, -0.5, 0.75)), INFINITY, true},
  };
}

// The grid's medium (albedo 1, grey sigma_s = 1) times density_scale, in a null-boundary box
// exactly around the grid
struct TrackingScene {
  Scene scene;
  CompiledScene compiled;
  SceneOnDevice sod;
  TrackingScene(const HostGrid& grid, double density_scale, const std::string& name)
      : scene(make(grid, density_scale, name)), compiled(compile_scene(scene)), sod(kernel_rig("pocl"), compiled) {}
  static Scene make(const HostGrid& grid, double density_scale, const std::string& name) {
    GltfBuilder g;
    json medium = scattering_medium(glm::vec3(1.0f), 0.0);
    medium["grid"] = {{"size", {grid.n.x, grid.n.y, grid.n.z}},
                      {"min", {grid.lo.x, grid.lo.y, grid.lo.z}},
                      {"max", {grid.hi.x, grid.hi.y, grid.hi.z}},
                      {"density", grid.v}};
    medium["density_scale"] = density_scale;
    int box = g.add("materials", null_boundary_material(medium));
    g.add_node({{"mesh", g.add_mesh(box_primitives(glm::vec3(grid.lo), glm::vec3(grid.hi), box))}});
    return load_tracking_scene(g, name);
  }
};

// n estimates from one of the test kernels: (value per channel, w)
std::vector<cl_float4> run_tracking(const TrackingScene& ts, const char* kernel, const TrackRay& r, size_t n,
                                    cl_uint seed) {
  const KernelRig& rig = kernel_rig("pocl");
  auto out = rig.output<cl_float4>(n);
  rig.run(kernel, n, ts.sod, f4(r.org), f4(r.dir), float(r.tmax), seed, out);
  return out.read();
}

struct Moments {
  double mean = 0.0, se = 0.0;
  bool finite = true, non_negative = true;
};
template <typename F>
Moments moments(const std::vector<cl_float4>& v, F value) {
  Moments m;
  double sum = 0.0, sum2 = 0.0;
  for (const cl_float4& x : v) {
    double y = value(x);
    m.finite = m.finite && std::isfinite(y);
    m.non_negative = m.non_negative && y >= 0.0;
    sum += y;
    sum2 += y * y;
  }
  double n = double(v.size());
  m.mean = sum / n;
  m.se = std::sqrt(std::max(0.0, sum2 / n - m.mean * m.mean) / (n - 1.0));
  return m;
}

// Optical depths of the ray across the box along x ("from outside, across x"); the others
// scale with them
const std::vector<double> kOpticalDepths = {0.01, 0.3, 1.0, 3.0, 10.0, 30.0};
constexpr size_t kTrackingSamples = 1 << 18;

double density_scale_for(const HostGrid& grid, double tau) {
  const TrackRay across = tracking_rays()[1];
  return tau / grid.integral(across.org, across.dir, across.tmax);
}

// The host reference itself: Gauss-Legendre on the pieces agrees with a fine Simpson rule,
// and the grid has empty regions, down to whole majorant cells (which the walk skips)
TEST(VolumeTracking, HostQuadratureIsConsistent) {
  HostGrid grid;
  for (const TrackRay& r : tracking_rays()) {
    double a = grid.integral(r.org, r.dir, r.tmax), b = grid.simpson(r.org, r.dir, r.tmax, 200000);
    EXPECT_GT(a, 0.1) << r.what;
    EXPECT_NEAR(a, b, 1e-7 * a) << r.what;
  }
  int zeros = 0;
  for (float x : grid.v) zeros += x == 0.0f;
  EXPECT_GT(zeros, 100);
  EXPECT_GT(*std::max_element(grid.v.begin(), grid.v.end()), 1.0f);
  int empty_cells = 0;
  glm::ivec3 cells = grid.majorant_cells();
  for (int k = 0; k < cells.z; ++k)
    for (int j = 0; j < cells.y; ++j)
      for (int i = 0; i < cells.x; ++i)
        empty_cells +=
            grid.majorant_at(grid.lo + (glm::dvec3(i, j, k) + 0.5) / glm::dvec3(cells) * (grid.hi - grid.lo)) == 0.0;
  EXPECT_GT(empty_cells, 0);
  int rays_through_empty = 0;  // the walk skips an empty cell on some of the test rays
  for (const TrackRay& r : tracking_rays()) {
    double t0, t1;
    if (!grid.span(r.org, r.dir, r.tmax, &t0, &t1)) continue;
    bool crosses = false;
    for (int s = 0; s <= 2000; ++s)
      crosses = crosses || grid.majorant_at(r.org + (t0 + (t1 - t0) * s / 2000.0) * r.dir) == 0.0;
    rays_through_empty += crosses;
  }
  EXPECT_GT(rays_through_empty, 0);
  std::printf("  %d of %zu nodes empty, largest %.3f; %d of %d majorant cells empty, crossed by %d of the rays\n",
              zeros, grid.v.size(), double(*std::max_element(grid.v.begin(), grid.v.end())), empty_cells,
              cells.x* cells.y* cells.z, rays_through_empty);
  // Trilinear interpolation reproduces the nodes
  EXPECT_DOUBLE_EQ(grid.at(grid.node(3, 5, 7)), grid.value(3, 5, 7));
  EXPECT_DOUBLE_EQ(grid.at(grid.node(16, 12, 10)), grid.value(16, 12, 10));
}

// Ratio tracking (shadow rays: media_shadow_transmittance, through the null boundary) and
// delta tracking's free flight (media_sample_segment in an albedo-1 medium: the flight
// reaches the end with probability T) against exp(-integral sigma_t), optical depth 0.01 to 30
class VolumeTrackingDepth : public ::testing::TestWithParam<int> {};

TEST_P(VolumeTrackingDepth, RatioAndDeltaTrackingMatchQuadrature) {
  HostGrid grid;
  double tau_across = kOpticalDepths[size_t(GetParam())];
  double scale = density_scale_for(grid, tau_across);
  TrackingScene ts(grid, scale, "depth" + std::to_string(GetParam()));
  cl_uint seed = cl_uint(31 + 7 * GetParam());
  for (const TrackRay& r : tracking_rays()) {
    double tau = scale * grid.integral(r.org, r.dir, r.tmax);  // sigma_t = density_scale x density
    double want = std::exp(-tau);
    SCOPED_TRACE(std::string(r.what) + ", optical depth " + std::to_string(tau) + ", T " + std::to_string(want));

    // Ratio tracking: every channel the same grey estimate. Its exact standard error comes
    // from the second moment (HostGrid::ratio_tracking_second_moment); the relative variance
    // E[T^2] / T^2 - 1 = exp(integral sigma_t^2 / sigma_bar) - 1 grows exponentially with
    // the optical depth, so at depth 30 the estimate is mostly tiny with rare large values:
    // the sample's own standard error is then no measure of the error and the exact one is
    // used
    std::vector<cl_float4> rt = run_tracking(ts, "test_media_transmittance", r, kTrackingSamples, seed);
    EXPECT_EQ(rt[0].s[3], r.inside ? 1.0f : 0.0f) << "media_at_origin";
    Moments m = moments(rt, [](const cl_float4& x) { return double(x.s[0]); });
    double second = grid.ratio_tracking_second_moment(r.org, r.dir, r.tmax, scale);
    double se = std::sqrt(std::max(0.0, second - want * want) / double(kTrackingSamples));
    EXPECT_TRUE(m.finite);
    EXPECT_TRUE(m.non_negative);
    EXPECT_NEAR(m.mean, want, 5.0 * se + 1e-6 * want) << "ratio tracking, SE " << se << " (sample's " << m.se
                                                      << "), relative variance " << second / (want * want) - 1.0;
    if (second < 20.0 * want * want) {  // light tails: the sample's variance estimates the exact one
      EXPECT_NEAR(m.se / se, 1.0, 0.15) << "ratio tracking's variance: the majorant cells differ from the README's";
    }
    if (tau_across <= 3.0) {
      EXPECT_LT(se, 0.02 * want) << "ratio tracking too noisy to test anything";
    }
    for (size_t i = 0; i < rt.size(); i += 101) ASSERT_EQ(rt[i].s[1], rt[i].s[0]);

    if (!r.inside) {
      std::printf("  %-26s tau %7.3f  T %.4g  ratio %.4g (z %+.2f, rel. var. %.3g)\n", r.what, tau, want, m.mean,
                  (m.mean - want) / se, second / (want * want) - 1.0);
      continue;
    }
    // Delta tracking: the binary "reached the end" estimate, weight exactly 1 (grey,
    // albedo 1: a free flight either passes or scatters). Its standard error is the
    // binomial one of the reference, sqrt(T (1 - T) / n), exact where the sample's is 0.
    std::vector<cl_float4> dt = run_tracking(ts, "test_media_free_flight", r, kTrackingSamples, seed + 1000u);
    size_t passed = 0, scattered = 0;
    for (const cl_float4& x : dt) {
      int event = int(x.s[3]);
      ASSERT_TRUE(event == 0 || event == 1) << "absorbed in an albedo-1 medium: event " << x.s[3];
      ASSERT_NEAR(x.s[0], 1.0f, 1e-5f);  // sn / avg(sn): 1 up to rounding
      ASSERT_NEAR(x.s[2], 1.0f, 1e-5f);
      passed += event == 0;
      scattered += event == 1;
    }
    double n = double(dt.size()), mean = double(passed) / n;
    double se_binary = std::sqrt(want * (1.0 - want) / n);
    EXPECT_NEAR(mean, want, 5.0 * se_binary)
        << "delta tracking: " << passed << " of " << dt.size() << " passed, SE " << se_binary;
    EXPECT_EQ(passed + scattered, dt.size());
    std::printf("  %-26s tau %7.3f  T %.4g  ratio %.4g (z %+.2f, rel. var. %.3g)  delta %.4g (z %+.2f)\n", r.what, tau,
                want, m.mean, (m.mean - want) / se, second / (want * want) - 1.0, mean,
                se_binary > 0.0 ? (mean - want) / se_binary : 0.0);
  }
}

INSTANTIATE_TEST_SUITE_P(Grid, VolumeTrackingDepth, ::testing::Range(0, int(kOpticalDepths.size())),
                         [](const auto& info) {
                           std::string s = std::to_string(kOpticalDepths[size_t(info.param)]);
                           s = s.substr(0, s.find_last_not_of('0') + 1);
                           if (s.back() == '.') s.pop_back();
                           std::replace(s.begin(), s.end(), '.', '_');
                           return "tau" + s;
                         });

// The comparison has power: at optical depth 1 across, the same estimates reject the
// transmittance of a density 3 % higher, and that of the grid read with its nodes at
// lo + i / n of the box (an off-by-one in the node placement) by more than 5 standard errors
TEST(VolumeTracking, ComparisonRejectsAWrongReference) {
  HostGrid grid;
  double scale = density_scale_for(grid, 1.0);
  TrackingScene ts(grid, scale, "power");
  HostGrid misplaced = grid;
  misplaced.hi = grid.lo + (grid.hi - grid.lo) * glm::dvec3(grid.n - 1) / glm::dvec3(grid.n);
  for (const TrackRay& r : tracking_rays()) {
    if (!r.inside) continue;
    SCOPED_TRACE(r.what);
    double want = std::exp(-scale * grid.integral(r.org, r.dir, r.tmax));
    double wrong_density = std::pow(want, 1.03);
    double wrong_nodes = std::exp(-scale * misplaced.integral(r.org, r.dir, r.tmax));
    std::vector<cl_float4> rt = run_tracking(ts, "test_media_transmittance", r, kTrackingSamples, 77);
    Moments m = moments(rt, [](const cl_float4& x) { return double(x.s[0]); });
    std::vector<cl_float4> dt = run_tracking(ts, "test_media_free_flight", r, kTrackingSamples, 78);
    Moments d = moments(dt, [](const cl_float4& x) { return x.s[3] == 0.0f ? 1.0 : 0.0; });
    for (const auto& [what, e] : {std::pair<const char*, Moments>{"ratio", m}, {"delta", d}}) {
      EXPECT_NEAR(e.mean, want, 5.0 * e.se) << what;
      EXPECT_GT(std::fabs(e.mean - wrong_density), 5.0 * e.se) << what << " SE " << e.se;
      EXPECT_GT(std::fabs(e.mean - wrong_nodes), 5.0 * e.se) << what << " SE " << e.se;
      std::printf("  %-26s %s: z %+.2f, against 3 %% more density %+.1f, against misplaced nodes %+.1f\n", r.what, what,
                  (e.mean - want) / e.se, (e.mean - wrong_density) / e.se, (e.mean - wrong_nodes) / e.se);
    }
  }
}

// --- Henyey-Greenstein sampling near |g| = 1 ---

// The deflection angle of phase_sample's directions follows Henyey and Greenstein's cdf at g = +-0.99
// and +-0.999, where the peak is (1 - |g|) / sqrt|g| wide (1e-3 rad at 0.999): Kolmogorov-
// Smirnov over 2^20 samples at alpha = 0.01 (critical D = 1.63 / sqrt(n)), on the angle
// measured in double precision as atan2(|wi x d|, wi . d) from the float directions (accurate
// to ~1e-7 rad: the cosine itself would only resolve angles above ~3e-4 rad). The sampled pdf
// (and phase_pdf) equals the formula at the measured angle within 1 %. The cdf inversion as
// mu = (1 + g^2 - s^2) / (2 g) and sin = sqrt(1 - cos^2) failed this at |g| = 0.999 (D = 0.048,
// 30x the critical value; pdf errors up to 36 %); since D is the same for every g (the
// samples are a monotone map of the same u), it passes with D = 6.7e-4.
TEST(VolumePhaseNearOne, DeflectionAnglesFollowTheCdf) {
  const KernelRig& rig = kernel_rig("pocl");
  const size_t n = 1 << 20;
  const glm::vec3 wo_f = glm::normalize(glm::vec3(0.3f, -0.5f, 0.8f));
  const glm::dvec3 travel = -glm::dvec3(wo_f);  // the incoming travel direction
  for (float g : {0.99f, -0.99f, 0.999f, -0.999f}) {
    SCOPED_TRACE("g " + std::to_string(g));
    auto out = rig.output<cl_float4>(n);
    auto evals = rig.output<float>(n);
    rig.run("test_phase_sample", n, g, cl_float4{{wo_f.x, wo_f.y, wo_f.z, 0.0f}}, cl_uint(5), out, evals);
    std::vector<cl_float4> v = out.read();
    std::vector<float> e = evals.read();
    const double gd = g;
    // 1 - mu = 2 sin^2(theta / 2), mu the cosine of the deflection: the phase function and
    // its cdf in terms of x = 1 - mu (henyey_greenstein_deflection)
    auto cdf_x = [&](double x) { return henyey_greenstein_deflection_cdf(gd, x); };
    auto hg_x = [&](double x) { return henyey_greenstein_deflection(gd, x); };
    std::vector<double> xs(n);
    size_t pdf_off = 0;
    double worst_pdf = 0.0;
    for (size_t i = 0; i < n; ++i) {
      glm::dvec3 wi(v[i].s[0], v[i].s[1], v[i].s[2]);
      double theta = std::atan2(glm::length(glm::cross(wi, travel)), glm::dot(wi, travel));
      double half = std::sin(0.5 * theta);
      xs[i] = 2.0 * half * half;
      double want = hg_x(xs[i]);
      double err = std::max(std::fabs(v[i].s[3] - want), std::fabs(e[i] - want)) / want;
      worst_pdf = std::max(worst_pdf, err);
      pdf_off += err > 0.01;
    }
    std::sort(xs.begin(), xs.end());
    double d = 0.0;
    for (size_t i = 0; i < n; ++i) {
      double f = cdf_x(xs[i]);
      d = std::max({d, std::fabs(f - double(i) / n), std::fabs(f - double(i + 1) / n)});
    }
    double critical = 1.63 / std::sqrt(double(n));
    EXPECT_LT(d, critical) << "KS distance of the deflection angles";
    EXPECT_EQ(pdf_off, 0u) << "samples whose pdf is off the formula by more than 1 % (worst " << worst_pdf << ")";
    std::printf("  g %+.3f: KS D %.2e (critical %.2e), median deflection %.3g rad, worst pdf error %.2g\n", gd, d,
                critical, 2.0 * std::asin(std::sqrt(0.5 * xs[n / 2])), worst_pdf);
  }
}

// --- Stability: white furnaces at extreme parameters ---

struct FurnaceCase {
  const char* name;
  glm::vec3 sigma_s;
  float g;
  bool grid;
  Strategy strategy;
  uint32_t spp;
  uint32_t max_depth;
  double max_se;  // the test must be able to see an error this large
};

Film render_furnace(const FurnaceCase& c, uint32_t seed) {
  json medium = scattering_medium(c.sigma_s, c.g);
  if (c.grid) {  // a constant grid of density 0.25 x 4: the same medium through delta tracking
    medium["grid"] = {{"size", {2, 2, 2}},
                      {"min", {-0.6, -0.6, -0.6}},
                      {"max", {0.6, 0.6, 0.6}},
                      {"density", std::vector<float>(8, 0.25f)}};
    medium["density_scale"] = 4.0;
  }
  Scene scene = load_tracking_scene(furnace_sphere(null_boundary_material(medium)), std::string("furnace-") + c.name);
  return render_film(scene, c.strategy, 16, 16, c.spp, c.max_depth, seed);
}

constexpr uint32_t kNoDepthCap = 1u << 24;  // never reached: paths end by escaping

const std::vector<FurnaceCase> kFurnaces = {
    // Henyey-Greenstein near its limits: sampled directions within ~1e-4 rad of straight on
    {"g099_bsdf", {1.0f, 2.0f, 4.0f}, 0.99f, false, Strategy::Bsdf, 128, kNoDepthCap, 0.01},
    {"gm099_bsdf", {1.0f, 2.0f, 4.0f}, -0.99f, false, Strategy::Bsdf, 128, kNoDepthCap, 0.01},
    {"g099_bsdf_grid", {1.0f, 2.0f, 4.0f}, 0.99f, true, Strategy::Bsdf, 128, kNoDepthCap, 0.01},
    // nee at |g| = 0.99: each light sample is weighted by 4 pi f_p, whose variance over a
    // uniform background is (1 + g)^2 / (8 g (1 - g)^2) - 1, about 5e3: noisy, still unbiased
    {"g099_nee", {1.0f, 2.0f, 4.0f}, 0.99f, false, Strategy::Nee, 2048, kNoDepthCap, 0.1},
    {"gm099_nee", {1.0f, 2.0f, 4.0f}, -0.99f, false, Strategy::Nee, 2048, kNoDepthCap, 0.1},
    // Very dense: optical radius 250, hundreds of scattering events per path
    {"dense_bsdf", {500.0f, 500.0f, 500.0f}, 0.0f, false, Strategy::Bsdf, 32, kNoDepthCap, 0.01},
    {"dense_nee", {500.0f, 500.0f, 500.0f}, 0.0f, false, Strategy::Nee, 32, kNoDepthCap, 0.01},
    {"dense_bsdf_grid", {500.0f, 500.0f, 500.0f}, 0.0f, true, Strategy::Bsdf, 32, kNoDepthCap, 0.01},
    {"dense_g09_bsdf", {500.0f, 500.0f, 500.0f}, 0.9f, false, Strategy::Bsdf, 16, kNoDepthCap, 0.01},
    // Very thin: almost every flight passes
    {"thin_nee", {1e-3f, 2e-3f, 4e-3f}, 0.0f, false, Strategy::Nee, 64, kNoDepthCap, 0.01},
    {"thin_bsdf_grid", {1e-3f, 2e-3f, 4e-3f}, 0.5f, true, Strategy::Bsdf, 64, kNoDepthCap, 0.01},
    {"thin_nee_grid", {1e-3f, 2e-3f, 4e-3f}, 0.5f, true, Strategy::Nee, 64, kNoDepthCap, 0.01},
};

class VolumeStability : public ::testing::TestWithParam<int> {};

TEST_P(VolumeStability, FurnaceStaysOne) {
  const FurnaceCase& c = kFurnaces[size_t(GetParam())];
  Film f = render_furnace(c, 40u + uint32_t(GetParam()));
  EXPECT_EQ(f.dropped_samples(), 0u);
  for (int ch = 0; ch < 3; ++ch) {
    Estimate e = region_mean(f, ch, 0, 16, 0, 16);
    EXPECT_TRUE(std::isfinite(e.mean) && std::isfinite(e.standard_error));
    EXPECT_LE(e.standard_error, c.max_se) << "too noisy to test anything";
    EXPECT_NEAR(e.mean, 1.0, 4.5 * e.standard_error + 1e-4)
        << c.name << " channel " << ch << " SE " << e.standard_error;
    Estimate mid = region_mean(f, ch, 4, 12, 4, 12);  // inside the sphere's outline
    EXPECT_NEAR(mid.mean, 1.0, 4.5 * mid.standard_error + 1e-4) << c.name << " middle, channel " << ch;
    std::printf("  %s channel %d: %.5f +- %.5f (middle %.5f +- %.5f)\n", c.name, ch, e.mean, e.standard_error, mid.mean,
                mid.standard_error);
  }
}

INSTANTIATE_TEST_SUITE_P(Media, VolumeStability, ::testing::Range(0, int(kFurnaces.size())),
                         [](const auto& info) { return std::string(kFurnaces[size_t(info.param)].name); });

// The depth cap is a bias, not noise: the dense sphere under the default cap (16 scattering
// events) loses the paths that would scatter more often before leaving, and is darker than 1
// by many standard errors. With bsdf and a grey albedo-1 medium every surviving path carries
// exactly 1, so the image mean is the fraction of paths that leave within the cap.
TEST(VolumeStabilityControl, DepthCapDarkensTheDenseFurnace) {
  FurnaceCase c = kFurnaces[5];
  c.max_depth = 16;
  Film f = render_furnace(c, 99u);
  Estimate e = region_mean(f, 0, 4, 12, 4, 12);
  EXPECT_LT(e.mean, 0.8);
  EXPECT_LT(e.mean + 10.0 * e.standard_error, 1.0) << "mean " << e.mean << " SE " << e.standard_error;
  std::printf("  dense sphere, depth cap 16: middle %.4f +- %.4f\n", e.mean, e.standard_error);
  EXPECT_EQ(f.dropped_samples(), 0u);
}

}  // namespace
}  // namespace candela::test
