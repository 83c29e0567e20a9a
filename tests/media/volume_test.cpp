// Participating media on the real kernels (cl/media/phase.cl, cl/media/media.cl, cl/integrator/integrator_path.cl):
//  - phase functions: chi-square of phase_sample against Henyey and Greenstein's (1941)
//    pdf (host, double) over (cos, phi) cells, 1M samples, alpha = 0.01 with the Sidak
//    correction over this file's chi-square tests; the sampled pdf equals phase_pdf; the
//    pdf integrates to 1; the mean cosine between old and new travel directions is g;
//  - renders with closed forms: an absorbing slab (null boundary) and a camera inside an
//    absorbing box show L exp(-sigma_a d); an emissive non-scattering slab shows
//    emission (1 - exp(-sigma_a d)) / sigma_a; a KHR_materials_volume glass slab shows
//    L (1 - F)^2 T / (1 - F^2 T^2) at normal incidence;
//  - white furnaces: chromatic scattering media of albedo 1 inside a null boundary under a
//    background of 1 render as 1, both strategies, g = 0 and 0.7, homogeneous and grid;
//  - nee and bsdf agree on a scattering medium lit by an area light;
//  - a grid of constant density renders as the homogeneous medium; ratio tracking through a
//    linear density grid gives exp(-integral sigma_t).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <glm/glm.hpp>

#include "base/error.hpp"
#include "render/renderer.hpp"
#include "scene/vdb_grid.hpp"
#include "support/gltf_builder.hpp"
#include "support/reference.hpp"
#include "support/scenes.hpp"
#include "support/stats.hpp"
#include "support/test_support.hpp"

#ifdef CANDELA_HAVE_NANOVDB
#include <nanovdb/util/IO.h>
#include <nanovdb/util/Primitives.h>
#endif

namespace candela::test {
namespace {

using nlohmann::json;

constexpr size_t kPhaseSamples = 1 << 20;
const std::vector<float> kPhaseG = {0.0f, 0.3f, 0.5f, 0.7f, -0.3f, -0.5f, -0.9f, 0.95f};
constexpr int kChiSquareTests = 8 * 2;  // kPhaseG on each device
const double kAlpha = sidak_alpha(0.01, kChiSquareTests);

const glm::dvec3 kWo = glm::normalize(glm::dvec3(0.3, -0.5, 0.8));

// A frame around kWo for the (cos, phi) cells
struct Frame3 {
  glm::dvec3 t, b, n;
};
Frame3 frame_around(glm::dvec3 n) {
  glm::dvec3 a = std::fabs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  glm::dvec3 t = glm::normalize(glm::cross(a, n));
  return {t, glm::cross(n, t), n};
}

struct PhaseSamples {
  std::vector<cl_float4> wi_pdf;
  std::vector<float> evals;
};

PhaseSamples sample_phase(const KernelRig& rig, float g, cl_uint seed) {
  auto out = rig.output<cl_float4>(kPhaseSamples);
  auto evals = rig.output<float>(kPhaseSamples);
  rig.run("test_phase_sample", kPhaseSamples, g, f4(kWo), seed, out, evals);
  return {out.read(), evals.read()};
}

// Cells: kCos rings with edges crowded toward c = -1 and c = 1 (the forward peak at
// wi = -wo for g > 0, the backward one for g < 0) and
// kPhi sectors. Expected probabilities integrate the host pdf over each ring (Simpson).
constexpr int kCos = 48, kPhi = 8;
double cos_edge(int i) {  // -1 .. 1, dense near both ends (forward and backward peaks)
  return -std::cos(kPi * double(i) / kCos);
}
int cos_cell(double c) {
  double x = std::acos(-std::clamp(c, -1.0, 1.0)) / kPi;
  return std::min(kCos - 1, int(x * kCos));
}

std::vector<double> expected_cells(double g) {
  std::vector<double> p(size_t(kCos * kPhi));
  for (int i = 0; i < kCos; ++i) {
    double a = cos_edge(i), b = cos_edge(i + 1), ring = 0.0;
    const int n = 200;  // Simpson intervals
    for (int k = 0; k <= n; ++k) {
      double w = k == 0 || k == n ? 1.0 : (k % 2 ? 4.0 : 2.0);
      ring += w * henyey_greenstein(g, a + (b - a) * k / n);
    }
    ring *= (b - a) / (3.0 * n) * 2.0 * kPi;
    for (int j = 0; j < kPhi; ++j) p[size_t(i * kPhi + j)] = ring / kPhi;
  }
  return p;
}

std::vector<double> observed_cells(const PhaseSamples& s) {
  Frame3 f = frame_around(kWo);
  std::vector<double> o(size_t(kCos * kPhi), 0.0);
  for (const cl_float4& v : s.wi_pdf) {
    glm::dvec3 wi(v.s[0], v.s[1], v.s[2]);
    double c = glm::dot(wi, f.n);
    double phi = std::atan2(glm::dot(wi, f.b), glm::dot(wi, f.t)) + kPi;
    int j = std::min(kPhi - 1, int(phi / (2.0 * kPi) * kPhi));
    o[size_t(cos_cell(c) * kPhi + j)] += 1.0;
  }
  return o;
}

class PhaseTest : public ::testing::TestWithParam<std::tuple<std::string, int>> {
 protected:
  void SetUp() override {
    rig_ = rig_or_null(std::get<0>(GetParam()));
    if (!rig_) GTEST_SKIP() << std::get<0>(GetParam()) << " OpenCL device is not available";
    g_ = kPhaseG[size_t(std::get<1>(GetParam()))];
    seed_ = cl_uint(17 + std::get<1>(GetParam()) + (std::get<0>(GetParam()) == "rusticl" ? 100 : 0));
  }
  const KernelRig* rig_ = nullptr;
  float g_ = 0.0f;
  cl_uint seed_ = 0;
};

TEST_P(PhaseTest, SamplesFollowThePdf) {
  PhaseSamples s = sample_phase(*rig_, g_, seed_);
  std::vector<double> prob = expected_cells(g_), expected(prob.size());
  double total = 0.0;
  for (size_t i = 0; i < prob.size(); ++i) {
    total += prob[i];
    expected[i] = prob[i] * double(kPhaseSamples);
  }
  EXPECT_NEAR(total, 1.0, 1e-6) << "host pdf does not integrate to 1";
  ChiSquare r = chi_square_test(observed_cells(s), expected);
  EXPECT_GT(r.p_value, kAlpha) << "g " << g_ << ": chi2 " << r.statistic << " dof " << r.dof;
  // The sample's pdf is phase_pdf at the sampled direction and Henyey and Greenstein's formula
  Frame3 f = frame_around(kWo);
  for (size_t i = 0; i < kPhaseSamples; i += 97) {
    const cl_float4& v = s.wi_pdf[i];
    glm::dvec3 wi(v.s[0], v.s[1], v.s[2]);
    ASSERT_NEAR(glm::length(wi), 1.0, 1e-5);
    double want = henyey_greenstein(g_, glm::dot(wi, f.n));
    ASSERT_NEAR(v.s[3], want, 2e-4 * want) << "sample " << i;
    ASSERT_NEAR(s.evals[i], v.s[3], 2e-4 * want) << "sample " << i;  // float rounding of wi near the peak
  }
}

// The same histogram must reject samples of g against the pdf of g + 0.05 (the test has power)
TEST_P(PhaseTest, ChiSquareRejectsAWrongG) {
  if (g_ > 0.9f) GTEST_SKIP();
  PhaseSamples s = sample_phase(*rig_, g_, seed_);
  std::vector<double> prob = expected_cells(g_ + 0.05);
  for (double& p : prob) p *= double(kPhaseSamples);
  EXPECT_LT(chi_square_test(observed_cells(s), prob).p_value, 1e-6);
}

// Mean cosine between the old travel direction (-wo) and the new one (wi) is g
TEST_P(PhaseTest, MeanCosineIsG) {
  PhaseSamples s = sample_phase(*rig_, g_, seed_ + 7);
  double sum = 0.0, sum2 = 0.0;
  for (const cl_float4& v : s.wi_pdf) {
    double c = -glm::dot(glm::dvec3(v.s[0], v.s[1], v.s[2]), kWo);
    sum += c;
    sum2 += c * c;
  }
  double n = double(kPhaseSamples), mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / n);
  EXPECT_NEAR(mean, g_, 4.0 * se + 1e-6) << "SE " << se;
}

// phase_eval integrates to 1 over the sphere (quadrature crowded toward the peak)
TEST_P(PhaseTest, PdfIntegratesToOne) {
  const int nc = 2000, np = 16;
  Frame3 f = frame_around(kWo);
  std::vector<cl_float4> dirs;
  std::vector<double> weights;
  for (int i = 0; i < nc; ++i) {
    double x0 = double(i) / nc, x1 = double(i + 1) / nc, xm = 0.5 * (x0 + x1);
    double c = -std::cos(kPi * xm), dc = std::cos(kPi * x0) - std::cos(kPi * x1);
    double sn = std::sqrt(std::max(0.0, 1.0 - c * c));
    for (int j = 0; j < np; ++j) {
      double phi = 2.0 * kPi * (j + 0.5) / np;
      glm::dvec3 d = sn * std::cos(phi) * f.t + sn * std::sin(phi) * f.b + c * f.n;
      dirs.push_back(f4(d));
      weights.push_back(dc * 2.0 * kPi / np);
    }
  }
  auto out = rig_->output<float>(dirs.size());
  rig_->run("test_phase_eval", dirs.size(), g_, f4(kWo), rig_->input(dirs), out);
  std::vector<float> v = out.read();
  double integral = 0.0;
  for (size_t i = 0; i < v.size(); ++i) integral += v[i] * weights[i];
  EXPECT_NEAR(integral, 1.0, 2e-3) << "g " << g_;
}

INSTANTIATE_TEST_SUITE_P(Devices, PhaseTest,
                         ::testing::Combine(kernel_devices(), ::testing::Range(0, int(kPhaseG.size()))),
                         [](const auto& info) {
                           return std::get<0>(info.param) + "_g" + std::to_string(std::get<1>(info.param));
                         });

// --- Scenes ---

json medium_json(glm::vec3 sigma_a, glm::vec3 sigma_s, double g = 0.0, glm::vec3 emission = glm::vec3(0.0f)) {
  return {{"sigma_a", {sigma_a.x, sigma_a.y, sigma_a.z}},
          {"sigma_s", {sigma_s.x, sigma_s.y, sigma_s.z}},
          {"g", g},
          {"emission", {emission.x, emission.y, emission.z}}};
}

Scene load(const GltfBuilder& g, const std::string& name) { return load_scene(g, "volume-" + name + ".gltf"); }

Film render(const Scene& scene, Strategy s, int size, uint32_t spp, uint32_t max_depth, uint32_t seed,
            const std::string& device = "pocl") {
  return render_film(scene, s, size, size, spp, max_depth, seed, *device_by_name(device));
}

const char* name(Strategy s) { return s == Strategy::Nee ? "nee" : "bsdf"; }

// Every pixel of a nearly parallel view (yfov 0.01: ray lengths within 3e-5 of the axial
// ones) against a per-channel closed form, within 5 standard errors and 5e-4 relative
void expect_image(const Film& f, glm::dvec3 want, const std::string& what) {
  for (int c = 0; c < 3; ++c) {
    Estimate e = region_mean(f, c, 0, f.width, 0, f.height);
    EXPECT_NEAR(e.mean, want[c], 5.0 * e.standard_error + 5e-4 * want[c] + 1e-6)
        << what << " channel " << c << " SE " << e.standard_error;
  }
  EXPECT_EQ(f.dropped_samples(), 0u);
}

const glm::vec3 kSigmaA(0.5f, 1.0f, 2.0f);
const glm::vec3 kLight(1.0f, 2.0f, 3.0f);

// Camera on +z looking down -z through a medium box [-1,1]^2 x [0, d] at an emitter at z = -1
class VolumeRender : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    auto dev = device_by_name(GetParam());
    if (!dev) GTEST_SKIP() << GetParam() << " OpenCL device is not available";
  }
  Film render_view(GltfBuilder& g, const std::string& label, uint32_t spp, Strategy s = Strategy::Nee) {
    g.add_camera(glm::vec3(0.0f, 0.0f, 3.0f), glm::vec3(0.0f), 0.01f);
    return render(load(g, label + "-" + GetParam()), s, 8, spp, 64, 5, GetParam());
  }
  void add_emitter(GltfBuilder& g, glm::vec3 radiance) {
    int light = g.add("materials", emissive_material(radiance));
    g.add_node({{"mesh", g.add_mesh({quad_primitive({{-2, -2, -1}, {2, -2, -1}, {2, 2, -1}, {-2, 2, -1}}, light)})}});
  }
};

// An absorbing slab of thickness d in a null boundary: L exp(-sigma_a d) per channel
TEST_P(VolumeRender, AbsorbingSlabTransmits) {
  const float d = 0.8f;
  GltfBuilder g;
  add_emitter(g, kLight);
  int slab = g.add("materials", null_boundary_material(medium_json(kSigmaA, glm::vec3(0.0f))));
  g.add_node({{"mesh", g.add_mesh(box_primitives({-1, -1, 0}, {1, 1, d}, slab))}});
  Film f = render_view(g, "slab", 16);
  glm::dvec3 want;
  for (int c = 0; c < 3; ++c) want[c] = kLight[c] * std::exp(-double(kSigmaA[c]) * d);
  expect_image(f, want, "absorbing slab");
}

// The camera inside an absorbing box (found by media_at_origin), and in a global absorbing
// medium: the light crosses both
TEST_P(VolumeRender, CameraInsideMedia) {
  GltfBuilder g;
  add_emitter(g, kLight);
  int box = g.add("materials", null_boundary_material(medium_json(kSigmaA, glm::vec3(0.0f))));
  g.add_node({{"mesh", g.add_mesh(box_primitives({-1, -1, 1}, {1, 1, 4}, box))}});
  const glm::vec3 fog(0.1f, 0.05f, 0.02f);
  g.doc["scenes"][0]["extras"]["candela"]["medium"] = medium_json(fog, glm::vec3(0.0f));
  Film f = render_view(g, "camera-inside", 16);
  // Camera at z = 3: 2 units of the box, then 2 of fog down to the emitter at z = -1
  glm::dvec3 want;
  for (int c = 0; c < 3; ++c) want[c] = kLight[c] * std::exp(-2.0 * kSigmaA[c] - 2.0 * fog[c]);
  expect_image(f, want, "camera inside");
}

// A non-scattering emissive slab over black: emission (1 - exp(-sigma_a d)) / sigma_a
TEST_P(VolumeRender, EmissiveSlab) {
  const float d = 1.5f;
  const glm::vec3 e(0.4f, 0.8f, 1.2f);
  GltfBuilder g;  // no light: only the medium emits
  int slab = g.add("materials", null_boundary_material(medium_json(kSigmaA, glm::vec3(0.0f), 0.0, e)));
  g.add_node({{"mesh", g.add_mesh(box_primitives({-1, -1, 0}, {1, 1, d}, slab))}});
  for (Strategy s : {Strategy::Nee, Strategy::Bsdf}) {
    Film f = render_view(g, std::string("emissive-") + name(s), 16, s);
    glm::dvec3 want;
    for (int c = 0; c < 3; ++c) want[c] = e[c] * (1.0 - std::exp(-double(kSigmaA[c]) * d)) / kSigmaA[c];
    expect_image(f, want, std::string("emissive slab ") + name(s));
  }
}

// An emission grid: a non-scattering slab z in [0, d] whose emission grid ramps linearly
// along the view axis, E(z) = e x scale x (c0 + c1 z / d), under a density grid that is 0
// everywhere (nothing attenuates: the majorant cells must still be positive where the
// emission grid is, or nothing is gathered) or 1 with absorption kSigmaA. The camera looks
// down -z from z = 3: L = integral over s in [0, d] of exp(-sigma_a density s) E(d - s) ds.
json emission_slab(float d, glm::vec3 e, float density, float scale, float c0, float c1) {
  json medium = medium_json(kSigmaA, glm::vec3(0.0f), 0.0, e);
  medium["grid"] = {{"size", {2, 2, 9}},
                    {"min", {-1, -1, 0}},
                    {"max", {1, 1, d}},
                    {"density", std::vector<float>(2 * 2 * 9, density)}};
  std::vector<float> ramp;
  const int nz = 5;
  for (int z = 0; z < nz; ++z)
    for (int i = 0; i < 4; ++i) ramp.push_back(c0 + c1 * float(z) / float(nz - 1));
  medium["emission_grid"] = {{"size", {2, 2, nz}}, {"min", {-1, -1, 0}}, {"max", {1, 1, d}}, {"values", ramp}};
  medium["emission_scale"] = scale;
  return medium;
}

TEST_P(VolumeRender, EmissionGridRamp) {
  const float d = 1.5f, scale = 0.5f, c0 = 0.25f, c1 = 1.5f;
  const glm::vec3 e(0.4f, 0.8f, 1.2f);
  for (float density : {0.0f, 1.0f}) {
    GltfBuilder g;  // no light: only the medium emits
    int slab = g.add("materials", null_boundary_material(emission_slab(d, e, density, scale, c0, c1)));
    g.add_node({{"mesh", g.add_mesh(box_primitives({-1, -1, 0}, {1, 1, d}, slab))}});
    glm::dvec3 want(0.0);
    const int steps = 20000;  // midpoint rule, converged far below the tolerance
    for (int c = 0; c < 3; ++c)
      for (int i = 0; i < steps; ++i) {
        double s = (i + 0.5) * d / steps, z = d - s;
        want[c] += std::exp(-double(kSigmaA[c]) * density * s) * e[c] * scale * (c0 + c1 * z / d) * d / steps;
      }
    for (Strategy s : {Strategy::Nee, Strategy::Bsdf}) {
      std::string label = "emission-grid-" + std::to_string(int(density)) + "-" + name(s);
      Film f = render_view(g, label, 256, s);
      expect_image(f, want, label);
    }
  }
}

// A glass slab (KHR_materials_volume, ior 1.5) of thickness d at normal incidence:
// L (1 - F)^2 T / (1 - F^2 T^2), F = 0.04, T = exp(-sigma_a d), sigma_a = -ln(c) / distance
TEST_P(VolumeRender, AbsorbingGlassSlab) {
  const float d = 0.5f, distance = 0.4f;
  const glm::vec3 color(0.9f, 0.6f, 0.3f);
  GltfBuilder g;
  add_emitter(g, kLight);
  json glass = {
      {"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 1}}, {"metallicFactor", 0.0}, {"roughnessFactor", 0.0}}},
      {"extensions",
       {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
        {"KHR_materials_volume",
         {{"thicknessFactor", d},
          {"attenuationDistance", distance},
          {"attenuationColor", {color.x, color.y, color.z}}}}}}};
  int slab = g.add("materials", glass);
  g.add_node({{"mesh", g.add_mesh(box_primitives({-1, -1, 0}, {1, 1, d}, slab))}});
  Film f = render_view(g, "glass", 512);
  const double F = 0.04;
  glm::dvec3 want;
  for (int c = 0; c < 3; ++c) {
    double t = std::exp(std::log(double(color[c])) / distance * d);
    want[c] = kLight[c] * (1.0 - F) * (1.0 - F) * t / (1.0 - F * F * t * t);
  }
  expect_image(f, want, "absorbing glass");
}

// A sphere of scattering medium (albedo 1, chromatic sigma_s) in a null boundary under a
// background of 1 is invisible: every pixel 1. Homogeneous and as a constant grid.
class VolumeFurnace : public ::testing::TestWithParam<std::tuple<Strategy, float, bool>> {};

json constant_grid(glm::vec3 lo, glm::vec3 hi, float value) {
  return {{"size", {2, 2, 2}},
          {"min", {lo.x, lo.y, lo.z}},
          {"max", {hi.x, hi.y, hi.z}},
          {"density", std::vector<float>(8, value)}};
}

TEST_P(VolumeFurnace, InvisibleUnderUniformBackground) {
  auto [s, g_value, grid] = GetParam();
  json medium = medium_json(glm::vec3(0.0f), glm::vec3(1.0f, 2.0f, 4.0f), g_value);
  if (grid) {
    medium["grid"] = constant_grid(glm::vec3(-0.6f), glm::vec3(0.6f), 0.25f);
    medium["density_scale"] = 4.0;  // density 1: the same medium
  }
  Film f = render(load(furnace_sphere(null_boundary_material(medium)), "furnace"), s, 16, 256, 1000, 11);
  Estimate e = image_mean(f);
  EXPECT_LT(e.standard_error, 0.01) << "too noisy to test anything";
  EXPECT_NEAR(e.mean, 1.0, 4.0 * e.standard_error + 1e-5) << name(s) << " g " << g_value << " SE " << e.standard_error;
  for (int c = 0; c < 3; ++c) {
    Estimate ec = region_mean(f, c, 4, 12, 4, 12);  // the sphere's middle
    EXPECT_NEAR(ec.mean, 1.0, 5.0 * ec.standard_error + 1e-5) << "channel " << c;
  }
  EXPECT_EQ(f.dropped_samples(), 0u);
}

// A smooth glass sphere (ior 1.5) whose interior scatters with albedo 1 (extras.candela.medium
// on a KHR_materials_volume material) is invisible too: the medium is entered and left by
// refraction, and light reaches the medium only through the delta lobe (nee's shadow rays
// from inside stop at the glass)
class GlassFurnace : public ::testing::TestWithParam<Strategy> {};

TEST_P(GlassFurnace, ScatteringGlassIsInvisible) {
  json glass = {
      {"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 1}}, {"metallicFactor", 0.0}, {"roughnessFactor", 0.0}}},
      {"extensions",
       {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
        {"KHR_materials_volume", {{"thicknessFactor", 1.0}}}}},
      {"extras", {{"candela", {{"medium", medium_json(glm::vec3(0.0f), glm::vec3(2.0f, 1.0f, 0.5f), 0.5)}}}}}};
  Film f = render(load(furnace_sphere(glass), "glass-furnace"), GetParam(), 16, 128, 1000, 21);
  Estimate e = image_mean(f);
  EXPECT_LT(e.standard_error, 0.01) << "too noisy to test anything";
  EXPECT_NEAR(e.mean, 1.0, 4.0 * e.standard_error + 1e-5) << name(GetParam()) << " SE " << e.standard_error;
  EXPECT_EQ(f.dropped_samples(), 0u);
}

INSTANTIATE_TEST_SUITE_P(Media, GlassFurnace, ::testing::Values(Strategy::Nee, Strategy::Bsdf),
                         [](const auto& info) { return std::string(name(info.param)); });

// The furnace has power: the same sphere with absorption (albedo 2/3) is visibly darker
TEST(VolumeFurnaceControl, AbsorbingSphereIsDarker) {
  json medium = medium_json(glm::vec3(0.5f, 1.0f, 2.0f), glm::vec3(1.0f, 2.0f, 4.0f));
  Film f = render(load(furnace_sphere(null_boundary_material(medium)), "furnace-absorbing"), Strategy::Nee, 16, 64,
                  1000, 12);
  for (int c = 0; c < 3; ++c) {
    Estimate e = region_mean(f, c, 4, 12, 4, 12);
    EXPECT_LT(e.mean, 0.9) << "channel " << c;
    EXPECT_LT(e.mean + 10.0 * e.standard_error, 1.0) << "channel " << c;
  }
}

INSTANTIATE_TEST_SUITE_P(Media, VolumeFurnace,
                         ::testing::Combine(::testing::Values(Strategy::Nee, Strategy::Bsdf),
                                            ::testing::Values(0.0f, 0.7f), ::testing::Bool()),
                         [](const auto& info) {
                           return std::string(name(std::get<0>(info.param))) + "_g" +
                                  (std::get<1>(info.param) > 0.0f ? "07" : "0") +
                                  (std::get<2>(info.param) ? "_grid" : "_homogeneous");
                         });

// A box of scattering, absorbing medium on a floor under an area light
Scene lit_medium_scene(bool grid) {
  GltfBuilder g;
  int floor = g.add("materials", lambert_material(0.5f));
  int light = g.add("materials", emissive_material(glm::vec3(8.0f)));
  json medium = medium_json(glm::vec3(0.2f, 0.4f, 0.8f), glm::vec3(1.5f, 1.0f, 0.5f), 0.4);
  if (grid) {
    medium["grid"] = constant_grid(glm::vec3(-0.8f, 0.0f, -0.8f), glm::vec3(0.8f, 0.9f, 0.8f), 0.5f);
    medium["density_scale"] = 2.0;
  }
  int box = g.add("materials", null_boundary_material(medium));
  const float l = 0.4f, h = 1.8f;
  g.add_node({{"mesh", g.add_mesh({quad_facing_up(3.0f, 0.0f, floor), quad_facing_down_rotated(l, h, light)})}});
  g.add_node({{"mesh", g.add_mesh(box_primitives({-0.6f, 0.0f, -0.6f}, {0.6f, 0.9f, 0.6f}, box))}});
  g.add_camera(glm::vec3(0.0f, 1.2f, 2.6f), glm::vec3(0.0f, 0.4f, 0.0f), 0.8f);
  return load(g, grid ? "lit-grid" : "lit");
}

double compare_blocks(const Film& a, const Film& b, int size, int block, const std::string& what) {
  double chi2 = 0.0;
  int blocks = 0;
  for (int by = 0; by < size; by += block)
    for (int bx = 0; bx < size; bx += block)
      for (int c = 0; c < 3; ++c) {
        Estimate ea = region_mean(a, c, bx, bx + block, by, by + block);
        Estimate eb = region_mean(b, c, bx, bx + block, by, by + block);
        double se = std::sqrt(ea.standard_error * ea.standard_error + eb.standard_error * eb.standard_error);
        if (se == 0.0) {
          EXPECT_EQ(ea.mean, eb.mean) << what << " block " << bx << "," << by;
          continue;
        }
        double z = (ea.mean - eb.mean) / se;
        chi2 += z * z;
        ++blocks;
        EXPECT_LT(std::fabs(z), 4.5) << what << " block " << bx << "," << by << " channel " << c << ": " << ea.mean
                                     << " vs " << eb.mean;
      }
  EXPECT_LT(chi2, blocks + 5.0 * std::sqrt(2.0 * blocks)) << what;
  return chi2;
}

// nee and bsdf agree on a scattering medium lit by an area light, block by block
TEST(VolumeStrategies, NeeAndBsdfAgreeOnALitMedium) {
  Scene scene = lit_medium_scene(false);
  const int size = 24;
  Film nee = render(scene, Strategy::Nee, size, 256, 32, 3);
  Film bsdf = render(scene, Strategy::Bsdf, size, 1024, 32, 4);
  compare_blocks(nee, bsdf, size, 6, "nee vs bsdf");
  // The medium is lit: the box's middle is brighter than black by many standard errors
  Estimate mid = region_mean(nee, 0, 9, 15, 9, 15);
  EXPECT_GT(mid.mean, 10.0 * mid.standard_error);
}

// A grid of constant density renders as the homogeneous medium (delta tracking and ratio
// tracking against the closed forms)
TEST(VolumeGrid, ConstantGridEqualsHomogeneous) {
  const int size = 24;
  Film a = render(lit_medium_scene(false), Strategy::Nee, size, 256, 32, 8);
  Film b = render(lit_medium_scene(true), Strategy::Nee, size, 256, 32, 9);
  compare_blocks(a, b, size, 6, "homogeneous vs grid");
}

// Ratio tracking through a grid whose density rises linearly along x: transmittance
// exp(-sigma_t integral of density), for an axial and an oblique ray; media_at_origin
// finds the null-bounded box around the origin
TEST(VolumeGrid, RatioTrackingMatchesLinearDensity) {
  GltfBuilder g;
  const glm::vec3 sigma_t(0.6f, 1.2f, 2.4f);
  json medium = medium_json(glm::vec3(0.6f, 1.2f, 2.4f) * 0.5f, sigma_t * 0.5f);
  // density(x) = 0.2 + 0.8 (x + 1) / 2 on [-1, 1], 9 nodes along x (8 majorant cells, so
  // the walk through the majorant grid is exercised), 2 along y and z
  std::vector<float> density;
  const int nx = 9;
  for (int z = 0; z < 2; ++z)
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < nx; ++x) density.push_back(0.2f + 0.8f * float(x) / float(nx - 1));
  medium["grid"] = {{"size", {nx, 2, 2}}, {"min", {-1, -1, -1}}, {"max", {1, 1, 1}}, {"density", density}};
  int box = g.add("materials", null_boundary_material(medium));
  g.add_node({{"mesh", g.add_mesh(box_primitives(glm::vec3(-1.0f), glm::vec3(1.0f), box))}});
  Scene scene = load(g, "linear-grid");
  CompiledScene compiled = compile_scene(scene);
  const KernelRig& rig = kernel_rig("pocl");
  SceneOnDevice sod(rig, compiled);
  auto density_at = [](double x) { return 0.2 + 0.8 * (x + 1.0) / 2.0; };
  struct Case {
    glm::dvec3 org, dir;
    double tmax;
  };
  glm::dvec3 oblique = glm::normalize(glm::dvec3(1.0, 0.3, -0.2));
  glm::dvec3 backward = glm::normalize(glm::dvec3(-1.0, -0.4, 0.5));
  for (const Case& c : {Case{{-0.5, 0.1, 0.0}, {1, 0, 0}, 1.2}, Case{{-0.9, -0.2, 0.1}, oblique, INFINITY},
                        Case{{0.8, 0.3, -0.2}, backward, INFINITY}}) {
    const size_t n = 1 << 16;
    auto out = rig.output<cl_float4>(n);
    rig.run("test_media_transmittance", n, sod, f4(c.org), f4(c.dir), float(c.tmax), cl_uint(3), out);
    std::vector<cl_float4> v = out.read();
    // Path inside the box: up to tmax or to the box's exit
    double t_exit = INFINITY;
    for (int a = 0; a < 3; ++a)
      if (c.dir[a] != 0.0) t_exit = std::min(t_exit, ((c.dir[a] > 0 ? 1.0 : -1.0) - c.org[a]) / c.dir[a]);
    double t1 = std::min(c.tmax, t_exit);
    // integral of density along the ray (linear in t): trapezoid is exact
    double integral = 0.5 * (density_at(c.org.x) + density_at(c.org.x + t1 * c.dir.x)) * t1;
    for (int ch = 0; ch < 3; ++ch) {
      auto [mean, se] = sample_mean(v, ch);
      double want = std::exp(-double(sigma_t[ch]) * integral);
      EXPECT_NEAR(mean, want, 5.0 * se + 1e-6) << "channel " << ch << " SE " << se;
    }
    EXPECT_EQ(v[0].s[3], 1.0f) << "the origin lies inside the box's medium";
  }
}

// An emission grid leaves transmittance alone: its positive majorant cells over a thin
// medium only add null collisions to ratio tracking. The compiled records: the emission
// grid's own MEDIUM_GRID record, last, named by Medium.emission_grid.
TEST(VolumeGrid, EmissionGridKeepsTransmittance) {
  GltfBuilder g;
  const float d = 1.5f, density = 0.1f;  // sigma_t bound 0.2 < 1 / cell size = 16 / 1.5
  int slab = g.add("materials", null_boundary_material(emission_slab(d, glm::vec3(1.0f), density, 1.0f, 0.0f, 1.0f)));
  g.add_node({{"mesh", g.add_mesh(box_primitives({-1, -1, 0}, {1, 1, d}, slab))}});
  Scene scene = load(g, "emission-grid-transmittance");
  CompiledScene compiled = compile_scene(scene);
  const auto& media = compiled.buffers.media;
  ASSERT_EQ(media.size(), 3u);  // vacuum global, the slab, its emission grid
  EXPECT_EQ(media[1].emission_grid, 2u);
  EXPECT_EQ(media[2].type, MEDIUM_GRID);
  EXPECT_EQ(media[2].emission_grid, 0u);
  EXPECT_EQ(media[2].grid_size[2], 5u);
  EXPECT_FLOAT_EQ(media[2].density_scale, 1.0f);
  // The majorant cells: raised to 1 / cell size except the first layer along z (the ramp is
  // 0 at z = 0 but rises within that cell's trilinear reach, so it is raised too)
  EXPECT_FLOAT_EQ(media[1].majorant, 8.0f / d);
  const KernelRig& rig = kernel_rig("pocl");
  SceneOnDevice sod(rig, compiled);
  const size_t n = 1 << 16;
  auto out = rig.output<cl_float4>(n);
  rig.run("test_media_transmittance", n, sod, cl_float4{{0.1f, 0.2f, d + 1.0f, 0.0f}}, f4({0.0, 0.0, -1.0}),
          float(INFINITY), cl_uint(11), out);
  std::vector<cl_float4> v = out.read();
  for (int ch = 0; ch < 3; ++ch) {
    auto [mean, se] = sample_mean(v, ch);
    double want = std::exp(-double(kSigmaA[ch]) * density * d);
    EXPECT_NEAR(mean, want, 5.0 * se + 1e-6) << "channel " << ch << " SE " << se;
  }
}

// Where media come from: KHR_materials_volume, extras, the scene; the compiled records
TEST(VolumeLoader, MediaFromExtensionsExtrasAndScene) {
  GltfBuilder g;
  json glass = {{"pbrMetallicRoughness", {{"metallicFactor", 0.0}, {"roughnessFactor", 0.0}}},
                {"extensions",
                 {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
                  {"KHR_materials_volume",
                   {{"thicknessFactor", 1.0}, {"attenuationDistance", 2.0}, {"attenuationColor", {0.5, 0.25, 1.0}}}}}},
                {"extras", {{"candela", {{"medium", {{"sigma_s", {0.1, 0.2, 0.3}}, {"g", 0.5}}}}}}}};
  json clear = glass;
  clear["extensions"]["KHR_materials_volume"] = {{"thicknessFactor", 1.0}};
  clear.erase("extras");
  json thin = clear;
  thin["extensions"].erase("KHR_materials_volume");
  int m_glass = g.add("materials", glass), m_clear = g.add("materials", clear), m_thin = g.add("materials", thin);
  int m_null = g.add("materials", null_boundary_material(medium_json(glm::vec3(1.0f), glm::vec3(0.0f))));
  int m_opaque = g.add("materials", lambert_material(0.5f));
  float x = 0.0f;
  for (int m : {m_glass, m_clear, m_thin, m_null, m_opaque}) {
    g.add_node({{"mesh", g.add_mesh(box_primitives(glm::vec3(x), glm::vec3(x + 1.0f), m))}});
    x += 3.0f;
  }
  g.doc["scenes"][0]["extras"]["candela"]["medium"] = medium_json(glm::vec3(0.0f), glm::vec3(0.05f), -0.3);
  Scene scene = load(g, "loader");
  ASSERT_GE(scene.global_medium, 0);
  EXPECT_FLOAT_EQ(scene.media[size_t(scene.global_medium)].g, -0.3f);
  const MaterialDesc& mg = scene.materials[size_t(m_glass)];
  ASSERT_GE(mg.medium, 0);
  const MediumDesc& md = scene.media[size_t(mg.medium)];
  EXPECT_NEAR(md.sigma_a.x, std::log(2.0) / 2.0, 1e-6);  // -ln(0.5) / 2
  EXPECT_NEAR(md.sigma_a.y, std::log(4.0) / 2.0, 1e-6);
  EXPECT_EQ(md.sigma_a.z, 0.0f);
  EXPECT_FLOAT_EQ(md.sigma_s.y, 0.2f);
  EXPECT_FLOAT_EQ(md.g, 0.5f);
  EXPECT_FALSE(mg.null_boundary);
  EXPECT_EQ(scene.materials[size_t(m_clear)].medium, -1);
  EXPECT_EQ(scene.materials[size_t(m_thin)].medium, -1);
  EXPECT_TRUE(scene.materials[size_t(m_null)].null_boundary);
  EXPECT_EQ(scene.materials[size_t(m_opaque)].medium, -1);
  EXPECT_TRUE(scene.features().media);
  EXPECT_NE(scene.features().build_options().find("-DCD_FEATURE_MEDIA=1"), std::string::npos);

  CompiledScene c = compile_scene(scene);
  const auto& b = c.buffers;
  EXPECT_FLOAT_EQ(b.media[GLOBAL_MEDIUM].sigma_s[0], 0.05f);
  EXPECT_EQ(b.materials[size_t(m_glass)].medium, 1 + mg.medium);
  int vacuum = b.materials[size_t(m_clear)].medium;  // clear solids hold vacuum, not the fog
  ASSERT_GT(vacuum, 0);
  EXPECT_EQ(b.media[size_t(vacuum)].sigma_s[0] + b.media[size_t(vacuum)].sigma_a[0], 0.0f);
  EXPECT_EQ(b.materials[size_t(m_thin)].medium, NO_MEDIUM);
  EXPECT_EQ(b.materials[size_t(m_opaque)].medium, NO_MEDIUM);
  EXPECT_TRUE(b.materials[size_t(m_null)].flags & MATERIAL_NULL_BOUNDARY);

  // Without media the kernel has no media code and the buffers stay empty
  GltfBuilder plain;
  plain.add_node(
      {{"mesh", plain.add_mesh(box_primitives(glm::vec3(0.0f), glm::vec3(1.0f), plain.add("materials", clear)))}});
  Scene none = load(plain, "no-media");
  EXPECT_FALSE(none.features().media);
  EXPECT_TRUE(compile_scene(none).buffers.media.empty());
}

TEST(VolumeLoader, MalformedMediaAreClearErrors) {
  const std::vector<json> bad = {
      {{"sigma_a", {1, 2}}},
      {{"sigma_s", {1, -1, 0}}},
      {{"g", 1.0}},
      {{"density_scale", -1}},
      {{"grid",
        {{"size", {2, 2, 1}}, {"min", {0, 0, 0}}, {"max", {1, 1, 1}}, {"density", std::vector<float>(4, 1.0f)}}}},
      {{"grid",
        {{"size", {2, 2, 2}}, {"min", {0, 0, 0}}, {"max", {1, 0, 1}}, {"density", std::vector<float>(8, 1.0f)}}}},
      {{"grid",
        {{"size", {2, 2, 2}}, {"min", {0, 0, 0}}, {"max", {1, 1, 1}}, {"density", std::vector<float>(7, 1.0f)}}}},
      {{"grid",
        {{"size", {2, 2, 2}}, {"min", {0, 0, 0}}, {"max", {1, 1, 1}}, {"density", std::vector<float>(8, -1.0f)}}}},
  };
  // Emission grids: without a dense density grid, the wrong number of values, a negative
  // value, a box outside the density grid's, a bad scale, a scale without a grid
  json dense = {{"size", {2, 2, 2}}, {"min", {0, 0, 0}}, {"max", {1, 1, 1}}, {"density", std::vector<float>(8, 1.0f)}};
  json eg = {{"size", {2, 2, 2}}, {"min", {0, 0, 0}}, {"max", {1, 1, 1}}, {"values", std::vector<float>(8, 1.0f)}};
  auto with = [&](json grid, const char* key, json value) {
    grid[key] = value;
    return grid;
  };
  const std::vector<std::pair<json, std::string>> bad_emission = {
      {{{"emission_grid", eg}}, "needs an inline dense grid"},
      {{{"grid", {{"vdb", "smoke.vdb"}}}, {"emission_grid", eg}}, "needs an inline dense grid"},
      {{{"grid", dense}, {"emission_grid", with(eg, "values", std::vector<float>(7, 1.0f))}},
       "emission_grid.values must be an array"},
      {{{"grid", dense}, {"emission_grid", with(eg, "values", std::vector<float>(8, -1.0f))}},
       "emission_grid.values must hold finite non-negative"},
      {{{"grid", dense}, {"emission_grid", with(eg, "max", {1, 1.5, 1})}}, "inside the density grid's box"},
      {{{"grid", dense}, {"emission_grid", with(eg, "size", {2, 1, 2})}}, "emission_grid.size must hold"},
      {{{"grid", dense}, {"emission_grid", eg}, {"emission_scale", -1}}, "emission_scale must be finite"},
      {{{"grid", dense}, {"emission_scale", 2}}, "emission_scale needs an emission_grid"},
  };
  int k = 0;
  for (const auto& [medium, message] : bad_emission) {
    GltfBuilder g;
    g.add_node({{"mesh", g.add_mesh(box_primitives(glm::vec3(0.0f), glm::vec3(1.0f),
                                                   g.add("materials", null_boundary_material(medium))))}});
    try {
      load(g, "bad-emission-" + std::to_string(k++));
      ADD_FAILURE() << "no error for " << medium.dump();
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
  int i = 0;
  for (const json& medium : bad) {
    GltfBuilder g;
    g.add_node({{"mesh", g.add_mesh(box_primitives(glm::vec3(0.0f), glm::vec3(1.0f),
                                                   g.add("materials", null_boundary_material(medium))))}});
    EXPECT_THROW(load(g, "bad-" + std::to_string(i++)), Error) << medium.dump();
  }
  // A global medium that emits where nothing attenuates would give infinite radiance
  GltfBuilder g;
  g.add_node({{"mesh", g.add_mesh(box_primitives(glm::vec3(0.0f), glm::vec3(1.0f),
                                                 g.add("materials", lambert_material(0.5f))))}});
  g.doc["scenes"][0]["extras"]["candela"]["medium"] =
      medium_json(glm::vec3(0.0f, 1.0f, 1.0f), glm::vec3(0.0f), 0.0, glm::vec3(1.0f));
  EXPECT_THROW(load(g, "bad-emitting-fog"), Error);
}

// A NanoVDB fog sphere (written here with NanoVDB's own builder) goes to the device as its
// NanoVDB buffer, byte for byte, over its index box, and renders as a white furnace
TEST(VolumeNanoVdb, FogSphereLoadsAndIsAFurnace) {
#ifndef CANDELA_HAVE_NANOVDB
  EXPECT_FALSE(nanovdb_supported());
  GTEST_SKIP() << "built without NanoVDB";
#else
  ASSERT_TRUE(nanovdb_supported());
  auto handle = nanovdb::createFogVolumeSphere<float>(0.4f, nanovdb::Vec3f(0.1f, 0.0f, 0.0f), 0.05, 3.0,
                                                      nanovdb::Vec3d(0.0), "density");
  nanovdb::io::writeGrid(::testing::TempDir() + "volume-sphere.nvdb", handle);
  GltfBuilder g;
  json medium = medium_json(glm::vec3(0.0f), glm::vec3(1.0f, 2.0f, 4.0f), 0.3);
  medium["grid"] = {{"nanovdb", "volume-sphere.nvdb"}, {"name", "density"}};
  int m = g.add("materials", null_boundary_material(medium));
  g.add_node({{"mesh", g.add_mesh(box_primitives(glm::vec3(-0.8f), glm::vec3(0.8f), m))}});
  g.add_camera(glm::vec3(0.0f, 0.3f, 2.5f), glm::vec3(0.0f), 0.6f);
  g.set_background(glm::vec3(1.0f));
  Scene scene = load(g, "nanovdb");
  const MediumDesc& md = scene.media[size_t(scene.materials[size_t(m)].medium)];
  ASSERT_TRUE(md.is_nanovdb());
  const nanovdb::FloatGrid* grid = handle.grid<float>();
  ASSERT_EQ(md.nanovdb.size() * 4, grid->gridSize());
  EXPECT_EQ(std::memcmp(md.nanovdb.data(), grid, grid->gridSize()), 0);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(md.grid_min[k], float(grid->indexBBox().min()[k] - 1));
    EXPECT_EQ(md.grid_max[k], float(grid->indexBBox().max()[k] + 1));
  }
  EXPECT_EQ(*std::max_element(md.majorant_density.begin(), md.majorant_density.end()), 1.0f)
      << "a fog sphere is 1 inside";
  Film f = render(scene, Strategy::Nee, 16, 64, 1000, 13);
  Estimate e = image_mean(f);
  EXPECT_LT(e.standard_error, 0.01);
  EXPECT_NEAR(e.mean, 1.0, 4.0 * e.standard_error + 1e-5) << "SE " << e.standard_error;
#endif
}

INSTANTIATE_TEST_SUITE_P(Devices, VolumeRender, kernel_devices(), DeviceParamName());

}  // namespace
}  // namespace candela::test
