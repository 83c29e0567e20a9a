// KHR_materials_dispersion (cl/bsdf/dispersion.cl) on PoCL, in a test program of its own
// built with CD_FEATURE_DISPERSION on (the shared one has it off): the per-channel ior against
// the extension's formula; Snell's law at each channel's ior (red, green and blue refract to
// different directions, in the order of their indices); a dispersion of 0 samples bit for bit
// what the program without the feature samples; the loader and Scene::features; and a white
// furnace of a dispersive smooth glass sphere, whose channels each average 1.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <glm/glm.hpp>

#include "bsdf/bsdf_checks.hpp"
#include "device/kernel_sources.hpp"
#include "device/program_cache.hpp"
#include "support/gltf_builder.hpp"
#include "support/kernels.hpp"
#include "support/scenes.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

using nlohmann::json;

// The channels' wavelengths (nm): the Fraunhofer C, d and F lines
constexpr double kLambda[3] = {656.27, 587.56, 486.13};

// The extension's formula: ior(lambda) = max(ior + (ior - 1) / V (523655 / lambda^2 - 1.5168), 1), V = 20 / dispersion
double ref_ior(double ior, double dispersion, double lambda) {
  return std::max(ior + (ior - 1.0) * (dispersion / 20.0) * (523655.0 / (lambda * lambda) - 1.5168), 1.0);
}

// The test program with CD_FEATURE_DISPERSION on, on PoCL (built once per process)
KernelRig& dispersion_rig() {
  static std::unique_ptr<KernelRig> rig;
  if (!rig) {
    KernelRig& shared = kernel_rig("pocl");
    ProgramBuild b =
        build_program(shared.context, shared.device, test_program_source(),
                      "-cl-std=CL1.2 -DCD_FEATURE_DISPERSION=1 -DCD_FEATURE_IRIDESCENCE=0 -DCD_FEATURE_ANISOTROPY=0");
    rig = std::make_unique<KernelRig>(shared.device, shared.context, b.program);
  }
  return *rig;
}

// A glTF material: white, dielectric, of roughness r, transmission t, ior and dispersion
dev::Material material(double roughness, double transmission, double ior, double dispersion) {
  dev::Material m = gltf(glm::dvec3(1.0), 0.0, roughness, transmission);
  dev::GltfMaterial& g = m.params.gltf;
  g.ior = float(ior);
  g.clearcoat_normal_scale = 1.0f;
  g.dispersion = float(dispersion);
  return m;
}

const glm::dvec3 kUp(0.0, 0.0, 1.0), kTangent(1.0, 0.0, 0.0);

// test_dispersion_sample: n records of three float4 from wo, the surface's normal `n`
std::vector<cl_float4> sample(KernelRig& r, const dev::Material& m, int channel, glm::dvec3 n, glm::dvec3 wo,
                              size_t count, cl_uint seed) {
  auto out = r.output<cl_float4>(3 * count);
  r.run("test_dispersion_sample", count, r.input(std::vector<dev::Material>{m}), cl_int(channel), f4(n), f4(n),
        f4(kTangent), f4(wo), seed, out);
  return out.read();
}

// The refracted direction and eta of the first transmitted sample (wi below the surface
// on the other side of n from wo)
bool refraction(const std::vector<cl_float4>& rec, glm::dvec3 wo, glm::dvec3 n, glm::dvec3* wi, double* eta) {
  for (size_t i = 0; i < rec.size() / 3; ++i) {
    glm::dvec3 w = d3(rec[3 * i]);
    if (rec[3 * i].s[3] > 0.0f && glm::dot(w, n) * glm::dot(wo, n) < 0.0) {
      *wi = w;
      *eta = rec[3 * i + 1].s[3];
      return true;
    }
  }
  return false;
}

}  // namespace

// The kernel's ior at known (ior, dispersion, wavelength) is the formula's, the clamp at 1
// included; across the C and F lines it spans (ior - 1) / V, the Abbe number's definition
TEST(Dispersion, IorIsTheExtensionsFormula) {
  KernelRig& r = dispersion_rig();
  std::vector<cl_float4> in;
  std::vector<double> want;
  for (double ior : {1.05, 1.33, 1.5, 2.4})
    for (double d : {0.0, 0.2, 1.0, 5.0, 400.0})
      for (double lambda : {380.0, 486.13, 550.0, 587.56, 656.27, 780.0}) {
        in.push_back({{float(ior), float(d), float(lambda), 0.0f}});
        want.push_back(ref_ior(ior, d, lambda));
      }
  auto out = r.output<float>(in.size());
  r.run("test_dispersion_ior", in.size(), r.input(in), out);
  std::vector<float> got = out.read();
  for (size_t i = 0; i < in.size(); ++i)
    EXPECT_NEAR(got[i], want[i], 2e-6 * want[i]) << in[i].s[0] << " " << in[i].s[1] << " " << in[i].s[2];
  // Known values: ior 1.5, V = 20 at the C line: 1.5 + 0.025 (523655 / 656.27^2 - 1.5168)
  EXPECT_NEAR(ref_ior(1.5, 1.0, 656.27), 1.4924762, 1e-6);
  EXPECT_NEAR(ref_ior(1.5, 1.0, kLambda[2]) - ref_ior(1.5, 1.0, kLambda[0]), 0.5 / 20.0, 1e-4 * 0.025);
  EXPECT_EQ(ref_ior(1.05, 400.0, 780.0), 1.0);  // clamped
}

// Smooth dispersive glass: each channel's refraction obeys Snell's law at ior(lambda_c),
// entering (eta = ior_c) and leaving (eta = 1 / ior_c); red bends least, blue most; channel
// -1 (a path that has not chosen) refracts at the material's ior
TEST(Dispersion, ChannelsRefractBySnellsLawAtTheirIor) {
  KernelRig& r = dispersion_rig();
  const double ior = 1.5, disp = 2.0;  // V = 10
  dev::Material m = material(0.0, 1.0, ior, disp);
  for (bool entering : {true, false}) {
    // Leaving, wo is inside, below the (front-facing +z) surface: the normal given is -z
    glm::dvec3 n = entering ? kUp : -kUp;
    double theta = entering ? 1.0 : 0.35;  // inside: below the critical angle of every channel
    glm::dvec3 wo(std::sin(theta), 0.0, std::cos(theta));
    double tangential[3];
    for (int c = -1; c < 3; ++c) {
      SCOPED_TRACE(std::string(entering ? "entering" : "leaving") + ", channel " + std::to_string(c));
      double ior_c = c < 0 ? ior : ref_ior(ior, disp, kLambda[c]);
      double eta_want = entering ? ior_c : 1.0 / ior_c;
      glm::dvec3 wi(0.0);
      double eta = 0.0;
      ASSERT_TRUE(refraction(sample(r, m, c, n, wo, 256, 7u), wo, n, &wi, &eta));
      EXPECT_NEAR(eta, eta_want, 1e-6 * eta_want);
      // Snell: the tangential part of wi is -wo's / eta, in the plane of incidence
      EXPECT_NEAR(wi.x, -wo.x / eta_want, 2e-6);
      EXPECT_NEAR(wi.y, 0.0, 1e-6);
      EXPECT_NEAR(glm::length(wi), 1.0, 1e-6);
      if (c >= 0) tangential[c] = std::fabs(wi.x);
    }
    // Red (lowest index) bends least entering, blue most; the reverse leaving
    if (entering) {
      EXPECT_GT(tangential[0] - tangential[1], 1e-3);
      EXPECT_GT(tangential[1] - tangential[2], 1e-3);
    } else {
      EXPECT_LT(tangential[0] - tangential[1], -1e-3);
      EXPECT_LT(tangential[1] - tangential[2], -1e-3);
    }
  }
}

// A material of dispersion 0 samples and evaluates, at every channel, bit for bit what the
// program without CD_FEATURE_DISPERSION (the kernel of a scene without dispersion) gives
TEST(Dispersion, DispersionZeroIsTheMaterialWithoutTheFeature) {
  KernelRig& r = dispersion_rig();
  KernelRig& plain = kernel_rig("pocl");
  const size_t n = 4096;
  dev::Material cases[] = {material(0.0, 1.0, 1.5, 0.0), material(0.3, 1.0, 1.5, 0.0), material(0.4, 0.0, 1.5, 0.0),
                           material(0.2, 0.6, 1.8, 0.0)};
  for (size_t ci = 0; ci < std::size(cases); ++ci)
    for (double z : {0.9, 0.3, -0.6}) {
      glm::dvec3 wo = sphere_direction(z, 0.6);
      auto out = plain.output<cl_float4>(3 * n);
      auto info = plain.output<cl_uint4>(n);
      plain.run("test_bsdf_sample", n, plain.input(std::vector<dev::Material>{cases[ci]}), f4(kUp), f4(kUp),
                f4(kTangent), f4(wo), cl_uint(5), out, info);
      std::vector<cl_float4> want = out.read();
      for (int c = -1; c < 3; ++c) {
        SCOPED_TRACE("case " + std::to_string(ci) + ", wo.z " + std::to_string(z) + ", channel " + std::to_string(c));
        std::vector<cl_float4> got = sample(r, cases[ci], c, kUp, wo, n, 5u);
        EXPECT_EQ(std::memcmp(got.data(), want.data(), want.size() * sizeof(cl_float4)), 0);
      }
    }
}

namespace {

json dispersive_glass(double dispersion, bool volume, double roughness = 0.0) {
  json ext = {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
              {"KHR_materials_dispersion", {{"dispersion", dispersion}}}};
  if (volume) ext["KHR_materials_volume"] = {{"thicknessFactor", 1.0}};
  return {{"pbrMetallicRoughness",
           {{"baseColorFactor", {1, 1, 1, 1}}, {"metallicFactor", 0.0}, {"roughnessFactor", roughness}}},
          {"extensions", ext}};
}

}  // namespace

// The loader reads the factor; only a refracting volume with dispersion > 0 turns the feature on
TEST(Dispersion, LoaderAndSceneFeature) {
  Scene s = load_scene(furnace_sphere(dispersive_glass(0.5, true)), "dispersion-solid.gltf");
  EXPECT_FLOAT_EQ(s.materials.at(0).dispersion, 0.5f);
  EXPECT_TRUE(s.features().dispersion);
  EXPECT_FALSE(load_scene(furnace_sphere(dispersive_glass(0.5, false)), "dispersion-thin.gltf").features().dispersion);
  EXPECT_FALSE(load_scene(furnace_sphere(dispersive_glass(0.0, true)), "dispersion-zero.gltf").features().dispersion);
}

// White furnace: a smooth dispersive glass sphere under a uniform background of 1 is
// invisible: each channel's image mean is 1 within 4 standard errors, although each path
// through the glass carries one channel (x 3). A rough one too under bsdf (nee is
// heavy-tailed on near-delta glass), within the 0.012 of the rough glass's energy
// compensation (tests/render/material_render_test.cpp)
class DispersionFurnace : public ::testing::TestWithParam<Strategy> {};

TEST_P(DispersionFurnace, DispersiveGlassIsInvisible) {
  for (double roughness : {0.0, 0.2}) {
    if (roughness > 0.0 && GetParam() == Strategy::Nee) continue;
    SCOPED_TRACE("roughness " + std::to_string(roughness));
    double tolerance = roughness > 0.0 ? 0.012 : 1e-5;
    Scene scene = load_scene(furnace_sphere(dispersive_glass(3.0, true, roughness)), "dispersion-furnace.gltf");
    ASSERT_TRUE(scene.features().dispersion);
    Film f = render_film(scene, GetParam(), 16, 16, 256, 1000, 3);
    for (int c = 0; c < 3; ++c) {
      Estimate e = region_mean(f, c, 0, f.width, 0, f.height);
      EXPECT_LT(e.standard_error, 0.03) << "too noisy to test anything";
      EXPECT_NEAR(e.mean, 1.0, 4.0 * e.standard_error + tolerance) << "channel " << c << " SE " << e.standard_error;
    }
    EXPECT_EQ(f.dropped_samples(), 0u);
  }
}

INSTANTIATE_TEST_SUITE_P(Pocl, DispersionFurnace, ::testing::Values(Strategy::Nee, Strategy::Bsdf),
                         [](const auto& info) { return std::string(strategy_name(info.param)); });

}  // namespace candela::test
