// Light sampling (cl/lights/lights.cl) on the real kernel code:
//  - chi-square of lights_sample directions against the summed lights_pdf, integrated
//    over (cos theta, phi) cells: 1M samples, cells with expected count < 5 pooled,
//    alpha = 0.01 with the Sidak correction over the chi-square tests of this file;
//  - ls.pdf = lights_pdf(chosen light, wi) wherever a traced ray confirms the light;
//  - irradiance estimates E[L cos / pdf] against closed forms, within 4 standard errors;
//  - the auto strategy's shortcut: lights_omega_bound holds the extent's solid angle, and
//    every choice path_nee_surely_takes settles is path_nee_takes_by_moments' choice, and
//    settling first by the lobes' own terms changes none of the latter's choices.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <memory>
#include <random>

#include "compile/scene_compiler.hpp"
#include "support/reference.hpp"
#include "support/scenes.hpp"
#include "support/stats.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

constexpr size_t kSamples = 1 << 20;
constexpr int kChiSquareTests = 6 * 2;  // per device: quad 1, environment 3, mixture 2
const double kAlpha = sidak_alpha(0.01, kChiSquareTests);

// Flags of test_lights_sample (tests/lights/test_lights.cl)
constexpr unsigned kOk = 1, kCompared = 2, kShadowClear = 4, kAtInfinity = 8, kDelta = 16;

// A shading point: the test kernels' arguments p, n and transmits
struct Context {
  glm::dvec3 p, n;  // n = 0: a point in a medium
  bool transmits;
  cl_uint bind(cl::Kernel& k, cl_uint first) const {
    return bind_args(k, first, f4(p), f4(n), cl_uint(transmits ? 1 : 0));
  }
};

// Parallelogram c +- a e1 +- b e2, front (counter-clockwise) facing along e2 x e1
std::vector<glm::vec3> parallelogram(glm::vec3 c, glm::vec3 e1, glm::vec3 e2, float a, float b) {
  return {c - a * e1 - b * e2, c - a * e1 + b * e2, c + a * e1 + b * e2, c + a * e1 - b * e2};
}

Scene with_materials(glm::vec3 emission) {
  Scene s;
  s.materials.resize(2);  // 0: diffuse, 1: single-sided emitter
  s.materials[1].emission = emission;
  return s;
}

// (a) An emissive quad (two triangle lights) facing the origin, partly hidden by a blocker
std::vector<glm::vec3> quad_light() {
  return parallelogram({0.2f, 0.1f, 1.2f}, {1.0f, 0.0f, 0.3f}, {0.0f, 1.0f, -0.2f}, 0.7f, 0.5f);
}
Scene quad_scene() {
  Scene s = with_materials(glm::vec3(2.0f));
  add_polygon(&s, quad_light(), 1);
  add_polygon(&s, parallelogram({0.1f, 0.05f, 0.6f}, {1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, 0.15f, 0.15f), 0);
  return s;
}
const Context kQuadContext{{0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, false};

// (b) The environment alone, a floor below to block some rays
Scene environment_scene() {
  Scene s = with_materials(glm::vec3(0.0f));
  s.background = glm::vec3(1.0f);
  add_polygon(&s, parallelogram({0.0f, 0.0f, -1.0f}, {0.0f, 1.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, 1.0f, 1.0f), 0);
  return s;
}
const glm::dvec3 kTilted = glm::normalize(glm::dvec3(0.3, 0.2, 1.0));
const Context kEnvHemisphere{{0.0, 0.0, 0.0}, kTilted, false};
const Context kEnvTransmits{{0.0, 0.0, 0.0}, kTilted, true};
const Context kEnvMedium{{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, false};

// (c) A small triangle light and the environment, above a floor
const std::vector<glm::vec3> kSmallTriangle = {{0.6f, 0.3f, 1.8f}, {0.75f, 0.65f, 1.9f}, {1.05f, 0.35f, 1.7f}};
Scene mixture_scene() {
  Scene s = with_materials(glm::vec3(800.0f));
  s.background = glm::vec3(1.0f);
  add_polygon(&s, kSmallTriangle, 1);
  add_polygon(&s, parallelogram({0.0f, 0.0f, -0.5f}, {0.0f, 1.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, 2.0f, 2.0f), 0);
  return s;
}
const Context kMixHemisphere{{0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, false};
const Context kMixTransmits{{0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, true};
const Context kMixMedium{{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, false};

// Samples of test_lights_sample
struct Samples {
  std::vector<cl_float4> raw;  // 2 per sample
  size_t size() const { return raw.size() / 2; }
  glm::dvec3 wi(size_t i) const { return d3(raw[2 * i]); }
  double pdf(size_t i) const { return raw[2 * i].s[3]; }
  double radiance(size_t i) const { return raw[2 * i + 1].s[0]; }
  double pdf_eval(size_t i) const { return raw[2 * i + 1].s[1]; }
  unsigned light(size_t i) const { return unsigned(raw[2 * i + 1].s[2]); }
  unsigned flags(size_t i) const { return unsigned(raw[2 * i + 1].s[3]); }
};

class LightsTest : public DeviceTest {
 protected:
  void use_scene(const Scene& s) {
    compiled_ = compile_scene(s);
    scene_ = std::make_unique<SceneOnDevice>(rig(), compiled_);
  }

  // check: also evaluate lights_pdf and trace the rays (SamplePdfMatchesLightsPdf)
  Samples sample(const Context& c, cl_uint seed, size_t n = kSamples, bool check = false) {
    auto out = rig().output<cl_float4>(2 * n);
    rig().run("test_lights_sample", n, *scene_, c, seed, cl_uint(check ? 1 : 0), out);
    return {out.read()};
  }

  // Cells of directions about a frame: grids [c_lo, c_hi) x [0, 2 pi), stacked in cos
  struct Histogram {
    glm::dvec3 t, b, a;  // float-rounded, as the kernel sees them
    struct Grid {
      double c_lo, c_hi;
      int n_cos, n_phi;
    };
    std::vector<Grid> grids;
    explicit Histogram(glm::dvec3 axis) {
      // Duff et al. 2017 frame about the axis
      axis = glm::normalize(axis);
      double sign = std::copysign(1.0, axis.z), p = -1.0 / (sign + axis.z), q = axis.x * axis.y * p;
      t = d3(f4({1.0 + sign * axis.x * axis.x * p, sign * q, -sign * axis.x}));
      b = d3(f4({q, sign + axis.y * axis.y * p, -axis.y}));
      a = d3(f4(axis));
    }
    std::vector<cl_float4> cells() const {
      std::vector<cl_float4> v;
      for (const Grid& g : grids)
        for (int i = 0; i < g.n_cos; ++i)
          for (int j = 0; j < g.n_phi; ++j) {
            double dc = (g.c_hi - g.c_lo) / g.n_cos, dp = 2.0 * kPi / g.n_phi;
            v.push_back({{float(g.c_lo + i * dc), float(g.c_lo + (i + 1) * dc), float(j * dp), float((j + 1) * dp)}});
          }
      return v;
    }
    int bin(const glm::dvec3& w) const {
      double c = std::clamp(glm::dot(w, a), -1.0, 1.0);
      double phi = std::atan2(glm::dot(w, b), glm::dot(w, t));
      if (phi < 0.0) phi += 2.0 * kPi;
      int first = 0;
      for (size_t k = 0; k < grids.size(); ++k) {
        const Grid& g = grids[k];
        if (c < g.c_hi || k + 1 == grids.size()) {
          int i = std::clamp(int((c - g.c_lo) / (g.c_hi - g.c_lo) * g.n_cos), 0, g.n_cos - 1);
          int j = std::clamp(int(phi / (2.0 * kPi) * g.n_phi), 0, g.n_phi - 1);
          return first + i * g.n_phi + j;
        }
        first += g.n_cos * g.n_phi;
      }
      return -1;
    }
  };

  // Probability of each cell under the summed lights_pdf (mode 1: the wrong pdf)
  std::vector<double> cell_probabilities(const Context& c, const Histogram& h, cl_uint mode = 0, cl_uint sub = 32) {
    std::vector<cl_float4> cells = h.cells();
    auto out = rig().output<float>(cells.size());
    rig().run("test_lights_pdf_cells", cells.size(), *scene_, c, f4(h.t), f4(h.b), f4(h.a), sub, mode,
              rig().input(cells), out);
    std::vector<float> p = out.read();
    return std::vector<double>(p.begin(), p.end());
  }

  // Chi-square of the sampled directions against cell probabilities (renormalized when
  // `normalize`); samples that lights_sample rejected are left out (measure zero)
  static ChiSquare chi_square(const Samples& s, const Histogram& h, std::vector<double> prob, bool normalize = false) {
    std::vector<double> observed(prob.size(), 0.0);
    double kept = 0.0;
    for (size_t i = 0; i < s.size(); ++i) {
      if (!(s.flags(i) & kOk)) continue;
      observed[size_t(h.bin(s.wi(i)))] += 1.0;
      kept += 1.0;
    }
    double total = 0.0;
    for (double p : prob) total += p;
    for (double& p : prob) p *= kept / (normalize ? total : 1.0);
    return chi_square_test(observed, prob);
  }

  // Histogram about the direction from c.p to the centroid of `light`: a cap of n_cap x
  // n_phi cells just covering it (2% margin), the rest of the sphere in n_rest x n_phi
  // cells. Cells are small against the light, so the midpoint rule is accurate even
  // where the pdf jumps at the light's edges.
  static Histogram cap_histogram(const Context& c, const std::vector<glm::vec3>& light, int n_cap, int n_rest,
                                 int n_phi) {
    glm::dvec3 centroid(0.0);
    for (const auto& v : light) centroid += glm::dvec3(v) / double(light.size());
    Histogram h(centroid - c.p);
    double max_angle = 0.0;
    for (const auto& v : light)
      max_angle = std::max(max_angle, std::acos(glm::dot(glm::normalize(glm::dvec3(v) - c.p), h.a)));
    double c_cap = std::cos(1.02 * max_angle);
    h.grids = {{-1.0, c_cap, n_rest, n_phi}, {c_cap, 1.0, n_cap, n_phi}};
    return h;
  }

  void expect_normalized(const std::vector<double>& prob) {
    double total = 0.0;
    for (double p : prob) total += p;
    EXPECT_NEAR(total, 1.0, 2e-3) << "the summed lights_pdf integrates to 1 over the sphere";
  }

  void expect_few_rejected(const Samples& s) {
    size_t rejected = 0;
    for (size_t i = 0; i < s.size(); ++i) rejected += !(s.flags(i) & kOk);
    EXPECT_LE(rejected, s.size() / 10000) << "lights_sample returned false";
  }

  CompiledScene compiled_;
  std::unique_ptr<SceneOnDevice> scene_;
};

// Irradiance at p (normal n) from a polygon of unit radiance above p's horizon
// (Lambert; Arvo 1995, Applications of Irradiance Tensors): E = 1/2 sum_i Theta_i n.Gamma_i,
// Theta_i the angle subtended by edge i, Gamma_i the unit normal of its plane through p
double polygon_irradiance(const glm::dvec3& p, const glm::dvec3& n, const std::vector<glm::vec3>& poly) {
  double e = 0.0;
  for (size_t i = 0; i < poly.size(); ++i) {
    glm::dvec3 u = glm::dvec3(poly[i]) - p, v = glm::dvec3(poly[(i + 1) % poly.size()]) - p;
    glm::dvec3 c = glm::cross(u, v);
    double theta = std::atan2(glm::length(c), glm::dot(u, v));
    e += 0.5 * theta * glm::dot(n, c / glm::length(c));
  }
  return std::fabs(e);
}

// Mean and standard error of L max(cos, 0) / pdf about n (n = 0: L / pdf)
std::pair<double, double> irradiance_estimate(const Samples& s, const glm::dvec3& n) {
  double sum = 0.0, sum2 = 0.0;
  bool medium = glm::dot(n, n) == 0.0;
  for (size_t i = 0; i < s.size(); ++i) {
    double f = 0.0;
    if (s.flags(i) & kOk) f = s.radiance(i) * (medium ? 1.0 : std::max(glm::dot(s.wi(i), n), 0.0)) / s.pdf(i);
    sum += f;
    sum2 += f * f;
  }
  double m = sum / s.size();
  return {m, std::sqrt(std::max(sum2 / s.size() - m * m, 0.0) / (s.size() - 1))};
}

}  // namespace

// (a) One emissive quad (two triangle lights) from a surface point
TEST_P(LightsTest, QuadLightDirectionsMatchPdf) {
  use_scene(quad_scene());
  ASSERT_EQ(compiled_.buffers.lights.size(), 2u);
  Samples s = sample(kQuadContext, 11);
  expect_few_rejected(s);
  Histogram h = cap_histogram(kQuadContext, quad_light(), 20, 4, 32);
  auto prob = cell_probabilities(kQuadContext, h);
  expect_normalized(prob);
  ChiSquare r = chi_square(s, h, prob);
  EXPECT_GT(r.p_value, kAlpha) << "chi2 " << r.statistic << " dof " << r.dof;
  EXPECT_GT(r.dof, 200);
}

// The harness rejects a pdf that forgets the light's cosine in dw/dA (even renormalized)
TEST_P(LightsTest, ChiSquareRejectsAWrongLightPdf) {
  use_scene(quad_scene());
  Samples s = sample(kQuadContext, 11);
  Histogram h = cap_histogram(kQuadContext, quad_light(), 20, 4, 32);
  ChiSquare r = chi_square(s, h, cell_probabilities(kQuadContext, h, 1), true);
  EXPECT_LT(r.p_value, 1e-6) << "chi2 " << r.statistic << " dof " << r.dof;
}

// (b) The environment alone: cosine over the hemisphere of n, else the whole sphere
TEST_P(LightsTest, EnvironmentDirectionsMatchPdf) {
  use_scene(environment_scene());
  ASSERT_EQ(compiled_.buffers.lights.size(), 1u);
  // Axis away from n so that the hemisphere's edge crosses the cells
  Histogram h(glm::dvec3(1.0, -0.5, 0.4));
  h.grids = {{-1.0, 1.0, 24, 32}};
  cl_uint seed = 21;
  for (const Context& c : {kEnvHemisphere, kEnvTransmits, kEnvMedium}) {
    SCOPED_TRACE(c.transmits ? "transmits" : glm::dot(c.n, c.n) > 0.0 ? "hemisphere" : "medium");
    Samples s = sample(c, seed++);
    expect_few_rejected(s);
    // The documented pdfs: cos(theta) / pi about n, else 1 / (4 pi)
    bool hemisphere = !c.transmits && glm::dot(c.n, c.n) > 0.0;
    for (size_t i = 0; i < s.size(); ++i) {
      if (!(s.flags(i) & kOk)) continue;
      double cos_n = glm::dot(s.wi(i), c.n);
      if (hemisphere) {
        ASSERT_GE(cos_n, -1e-6) << "below the hemisphere";
      }
      ASSERT_NEAR(s.pdf(i), hemisphere ? cosine_hemisphere_pdf(cos_n) : uniform_sphere_pdf(), 1e-6) << "sample " << i;
    }
    auto prob = cell_probabilities(c, h);
    expect_normalized(prob);
    ChiSquare r = chi_square(s, h, prob);
    EXPECT_GT(r.p_value, kAlpha) << "chi2 " << r.statistic << " dof " << r.dof;
  }
}

// (c) A small triangle light and the environment: density sum_L lights_pdf(L, wi)
TEST_P(LightsTest, MixtureDirectionsMatchSummedPdf) {
  use_scene(mixture_scene());
  ASSERT_EQ(compiled_.buffers.lights.size(), 2u);
  for (const auto& l : compiled_.buffers.lights) {
    EXPECT_GT(l.pmf, 0.2f);
    EXPECT_LT(l.pmf, 0.8f);
  }
  cl_uint seed = 31;
  for (const Context& c : {kMixHemisphere, kMixMedium}) {
    SCOPED_TRACE(glm::dot(c.n, c.n) > 0.0 ? "hemisphere" : "medium");
    Samples s = sample(c, seed++);
    expect_few_rejected(s);
    Histogram h = cap_histogram(c, kSmallTriangle, 12, 20, 32);
    auto prob = cell_probabilities(c, h);
    expect_normalized(prob);
    ChiSquare r = chi_square(s, h, prob);
    EXPECT_GT(r.p_value, kAlpha) << "chi2 " << r.statistic << " dof " << r.dof;
  }
}

// ls.pdf equals lights_pdf(chosen light, wi) wherever a traced ray confirms that light
// (first hit is its primitive, or escapes for the environment); a finite light's target
// is reachable by the integrator's shadow ray
TEST_P(LightsTest, SamplePdfMatchesLightsPdf) {
  struct Case {
    const char* name;
    Scene scene;
    Context c;
  };
  const Case cases[] = {{"quad", quad_scene(), kQuadContext},
                        {"environment hemisphere", environment_scene(), kEnvHemisphere},
                        {"environment transmits", environment_scene(), kEnvTransmits},
                        {"environment medium", environment_scene(), kEnvMedium},
                        {"mixture hemisphere", mixture_scene(), kMixHemisphere},
                        {"mixture transmits", mixture_scene(), kMixTransmits},
                        {"mixture medium", mixture_scene(), kMixMedium}};
  cl_uint seed = 41;
  for (const Case& cs : cases) {
    SCOPED_TRACE(cs.name);
    use_scene(cs.scene);
    Samples s = sample(cs.c, seed++, 1 << 18, true);
    size_t compared = 0, mismatched = 0, finite = 0, shadow_blocked = 0;
    for (size_t i = 0; i < s.size(); ++i) {
      unsigned f = s.flags(i);
      if (!(f & kOk)) continue;
      const dev::Light& l = compiled_.buffers.lights[s.light(i)];
      ASSERT_FALSE(f & kDelta);
      ASSERT_EQ(bool(f & kAtInfinity), l.type == LIGHT_ENVIRONMENT);
      if (!(f & kCompared)) continue;
      ++compared;
      if (!(std::fabs(s.pdf_eval(i) - s.pdf(i)) <= 1e-3 * s.pdf(i)) && mismatched++ < 5)
        ADD_FAILURE() << "sample " << i << " light " << s.light(i) << ": ls.pdf " << s.pdf(i) << " lights_pdf "
                      << s.pdf_eval(i);
      // Seen from the front: the material's emission; the environment: its radiance
      double want = l.type == LIGHT_ENVIRONMENT ? l.radiance[0] : cs.scene.materials[1].emission.x;
      ASSERT_FLOAT_EQ(s.radiance(i), want) << "sample " << i;
      if (l.type == LIGHT_TRIANGLE) {
        ++finite;
        shadow_blocked += !(f & kShadowClear);
      }
    }
    EXPECT_EQ(mismatched, 0u);
    EXPECT_GT(compared, s.size() / 2) << "too few samples confirmed by a traced ray";
    EXPECT_EQ(shadow_blocked, 0u) << "of " << finite << " shadow rays toward targets on a visible light";
  }
}

// Irradiance under a constant environment L = 1: pi over the hemisphere of n (also
// through the sphere sampling of a transmitting surface); fluence 4 pi in a medium
TEST_P(LightsTest, EnvironmentIrradianceEstimate) {
  use_scene(environment_scene());
  const struct {
    Context c;
    double want;
  } cases[] = {{kEnvHemisphere, kPi}, {kEnvTransmits, kPi}, {kEnvMedium, 4.0 * kPi}};
  cl_uint seed = 51;
  for (const auto& cs : cases) {
    Samples s = sample(cs.c, seed++);
    auto [mean, se] = irradiance_estimate(s, cs.c.n);
    EXPECT_NEAR(mean, cs.want, 4.0 * se + 1e-5 * cs.want) << "transmits " << cs.c.transmits << " n " << cs.c.n.z;
  }
}

// A small triangle light far away: E = L x (Lambert's polygon irradiance), which the
// form factor A cos(theta_light) cos(theta_p) / d^2 approximates
TEST_P(LightsTest, SmallFarTriangleIrradianceEstimate) {
  const std::vector<glm::vec3> tri = {{1.3f, -1.1f, 10.0f}, {1.5f, -0.8f, 10.1f}, {1.7f, -1.15f, 9.95f}};
  Scene sc = with_materials(glm::vec3(5.0f));
  add_polygon(&sc, tri, 1);
  use_scene(sc);
  const Context c{{0.0, 0.0, 0.0}, glm::normalize(glm::dvec3(0.1, 0.05, 1.0)), false};
  double area;
  glm::dvec3 nl = triangle_normal_area(tri[0], tri[1], tri[2], &area);
  glm::dvec3 centre = (glm::dvec3(tri[0]) + glm::dvec3(tri[1]) + glm::dvec3(tri[2])) / 3.0 - c.p;
  double d = glm::length(centre);
  double form = area * std::fabs(glm::dot(nl, centre / d)) * glm::dot(c.n, centre / d) / (d * d);
  double exact = polygon_irradiance(c.p, c.n, tri);
  ASSERT_NEAR(form, exact, 1e-3 * exact);
  Samples s = sample(c, 61);
  auto [mean, se] = irradiance_estimate(s, c.n);
  EXPECT_NEAR(mean, 5.0 * exact, 4.0 * se + 1e-6 * 5.0 * exact) << "se " << se;
}

// Triangle light plus environment: the selection pmf weighs each estimate, so the sum
// is pi L_env + L_tri E_tri (no visibility in light sampling itself)
TEST_P(LightsTest, MixtureIrradianceEstimate) {
  use_scene(mixture_scene());
  cl_uint seed = 71;
  for (const Context& c : {kMixHemisphere, kMixTransmits}) {
    Samples s = sample(c, seed++);
    auto [mean, se] = irradiance_estimate(s, c.n);
    double want = kPi * 1.0 + 800.0 * polygon_irradiance(c.p, c.n, kSmallTriangle);
    EXPECT_NEAR(mean, want, 4.0 * se) << "transmits " << c.transmits;
  }
}

// The auto strategy's shortcut (path_nee_surely_takes, cl/integrator/integrator_path.cl)
// from points around the quad's triangles, 10^-2 to 10^3 of the quad's size away, with
// lobes as sharp as 10^-4 sr: every lights_omega_bound holds the extent's solid angle, and
// every choice the shortcut settles is the one the second moments make. With lobes of at
// least 0.3 sr (diffuse and rough surfaces, where light sampling wins) it settles most of
// the choices for light sampling (71 %), and nearly all of them (99 %) 20 sizes away or more (else it would
// only cost). The environment has no bound and is never settled by it.
TEST_P(LightsTest, AutoShortcutAgreesWithTheSecondMoments) {
  constexpr size_t kPoints = 1 << 16;
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  glm::dvec3 centre(0.0);
  for (const auto& v : quad_light()) centre += glm::dvec3(v) / 4.0;
  std::vector<cl_float4> points;
  std::vector<double> distance;
  for (size_t i = 0; i < kPoints; ++i) {
    double z = 2.0 * uni(gen) - 1.0, phi = 2.0 * M_PI * uni(gen), r = std::sqrt(1.0 - z * z);
    double d = std::pow(10.0, -2.0 + 5.0 * uni(gen));  // the quad is about 1.5 x 1.0
    points.push_back(f4(centre + d * glm::dvec3(r * std::cos(phi), r * std::sin(phi), z)));
    distance.push_back(d);
  }
  // The choices with and without settling first by the lobes' own terms must be the same
  // (path_nee_takes_by_moments' own_terms_first); returns test_lights_nee_shortcut's out
  auto run = [&](cl_uint light, cl_uint seed, float sharpest) {
    auto out = rig().output<cl_float4>(kPoints);
    auto full = rig().output<cl_float>(kPoints);
    rig().run("test_lights_nee_shortcut", kPoints, *scene_, light, seed, sharpest, rig().input(points), out, full);
    std::vector<cl_float4> o = out.read();
    std::vector<cl_float> f = full.read();
    size_t differ = 0, leaves = 0;
    for (size_t i = 0; i < kPoints; ++i) {
      differ += o[i].s[3] != f[i];
      leaves += f[i] == 0.0f;
    }
    EXPECT_EQ(differ, 0u) << "settling by the lobes' own terms changed a choice";
    EXPECT_GT(leaves, kPoints / 20) << "too few choices for BSDF sampling to test settling by the own terms";
    return o;
  };
  use_scene(quad_scene());
  for (cl_uint light : {0u, 1u})
    for (float sharpest : {4.0f, 0.5f}) {
      SCOPED_TRACE("triangle light " + std::to_string(light) + ", lobes down to 10^-" + std::to_string(sharpest) +
                   " sr");
      size_t takes = 0, settled = 0, wrong = 0, far_takes = 0, far_settled = 0;
      std::vector<cl_float4> out = run(light, 31 + light, sharpest);
      for (size_t i = 0; i < kPoints; ++i) {
        ASSERT_GE(out[i].s[0], out[i].s[1]) << "lights_omega_bound below the extent's solid angle, point " << i;
        bool surely = out[i].s[2] != 0.0f, by_moments = out[i].s[3] != 0.0f;
        takes += by_moments;
        settled += surely;
        wrong += surely && !by_moments;
        if (distance[i] > 20.0) {
          far_takes += by_moments;
          far_settled += surely;
        }
      }
      EXPECT_EQ(wrong, 0u) << "the shortcut took a light the second moments leave to BSDF sampling";
      EXPECT_GT(takes, kPoints / 10) << "too few choices for light sampling to test the shortcut";
      EXPECT_LT(takes, kPoints - kPoints / 20) << "too few choices for BSDF sampling to test the shortcut";
      if (sharpest < 1.0f) {
        EXPECT_GT(settled, takes * 2 / 3) << "the shortcut settles few of the choices";  // 71 %
        EXPECT_GT(far_settled, far_takes * 95 / 100)
            << "far from the light it should settle nearly every choice";  // 99 %
      }
    }
  use_scene(mixture_scene());
  size_t environments = 0;
  for (cl_uint light = 0; light < compiled_.buffers.lights.size(); ++light) {
    if (compiled_.buffers.lights[light].type != LIGHT_ENVIRONMENT) continue;
    ++environments;
    for (const cl_float4& o : run(light, 41, 4.0f)) {
      ASSERT_LT(o.s[0], 0.0f) << "an environment has no bound";
      ASSERT_EQ(o.s[2], 0.0f) << "the shortcut settled an environment";
    }
  }
  EXPECT_EQ(environments, 1u);
}

INSTANTIATE_TEST_SUITE_P(Devices, LightsTest, kernel_devices(), DeviceParamName());

}  // namespace candela::test
