// The clearcoat's own normal (KHR_materials_clearcoat clearcoatNormalTexture) and the diffuse
// transmission (KHR_materials_diffuse_transmission) of the glTF BSDF (cl/bsdf/gltf/), on
// PoCL and rusticl, through the real dispatch (tests/bsdf/test_gltf_layers.cl): the coat's
// specular peak follows the coat's normal map while the base's does not (and, as the
// extension says, a base normal map leaves the coat alone); sampling against the pdf
// (chi-square, sampled f and pdf equal to bsdf_eval's) with distinct normals and with diffuse
// transmission on; a white furnace (white base, transmission colour 1: the BSDF integrates
// to 1 over the sphere); the reflection / transmission split (1 - d) : d; a factor of 0 gives
// bit for bit the material of a kernel built without CD_FEATURE_DIFFUSE_TRANSMISSION; the EON
// diffuse base (KHR_materials_diffuse_roughness) in a white furnace, and its factor 0 bit for
// bit the material without CD_FEATURE_DIFFUSE_ROUGHNESS.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <glm/glm.hpp>

#include "bsdf/bsdf_checks.hpp"
#include "device/energy.hpp"
#include "device/kernel_sources.hpp"
#include "device/program_cache.hpp"

namespace candela::test {
namespace {

// Samples per configuration on PoCL (samples_on: a quarter on rusticl)
constexpr size_t kLayerSamples = 1 << 18;

// Texture 0 of the test scene: one texel, a tangent-space normal tilted by kTilt degrees
// toward +x (the tangent), as RGBA8
constexpr double kTilt = 12.0;

struct Layer {
  double metallic = 0.0, roughness = 0.4, specular = 1.0, transmission = 0.0;
  glm::dvec3 base{1.0};
  double coat = 0.0, coat_roughness = 0.3;
  bool coat_normal = false, base_normal = false;  // texture 0 in those slots
  double diffuse_transmission = 0.0;
  glm::dvec3 dt_color{1.0};
  glm::dvec3 sheen{0.0};
  double diffuse_roughness = 0.0;
};

dev::Material material(const Layer& l) {
  dev::Material m = gltf(l.base, l.metallic, l.roughness, l.transmission);
  if (l.coat_normal) m.textures[TEX_CLEARCOAT_NORMAL].index = 0;
  if (l.base_normal) m.textures[TEX_NORMAL].index = 0;
  dev::GltfMaterial& g = m.params.gltf;
  g.specular = float(l.specular);
  g.clearcoat = float(l.coat);
  g.clearcoat_roughness = float(l.coat_roughness);
  g.clearcoat_normal_scale = 1.0f;
  for (int c = 0; c < 3; ++c) g.sheen_color[c] = float(l.sheen[c]);
  g.sheen_roughness = 0.5f;
  for (int c = 0; c < 3; ++c) g.diffuse_transmission_color[c] = float(l.dt_color[c]);
  g.diffuse_transmission = float(l.diffuse_transmission);
  g.diffuse_roughness = float(l.diffuse_roughness);
  return m;
}

// The texel of texture 0, and the normal the kernel decodes from it (2 c / 255 - 1)
struct Texel {
  unsigned char rgba[4];
  glm::dvec3 normal() const {
    glm::dvec3 n(2.0 * rgba[0] / 255.0 - 1.0, 2.0 * rgba[1] / 255.0 - 1.0, 2.0 * rgba[2] / 255.0 - 1.0);
    return glm::normalize(n);
  }
};
Texel tilted() {
  double a = kTilt * kPi / 180.0;
  auto enc = [](double v) { return (unsigned char)std::lround((v + 1.0) * 0.5 * 255.0); };
  return {{enc(std::sin(a)), enc(0.0), enc(std::cos(a)), 255}};
}

// The program's buffers for material 0: texture 0 (tilted()) and the GGX albedo table
struct LayerScene {
  cl::Buffer textures, texels, ggx;
  LayerScene(KernelRig& r, const cl::Program& program, const std::string& cache_file) {
    dev::TextureInfo info{};
    info.width = info.height = 1;
    info.flags = WRAP_CLAMP | (WRAP_CLAMP << 8);
    Texel t = tilted();
    textures = cl::Buffer(r.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof info, &info);
    texels = cl::Buffer(r.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof t.rgba, t.rgba);
    ggx = ggx_albedo_table(r.context, r.queue, program, cache_file).buffer;
  }
};

// test_layers_sample: 3 float4 per sample (test_bsdf_sample_record)
std::vector<cl_float4> sample(KernelRig& r, const cl::Program& program, const LayerScene& sc, const dev::Material& m,
                              cl_uint use_ggx, glm::dvec3 wo, size_t n, cl_uint seed) {
  return flat_sample(r, program, "test_layers_sample", wo, n, seed, r.input(std::vector<dev::Material>{m}), sc.textures,
                     sc.texels, sc.ggx, use_ggx);
}

// test_layers_eval: (f, pdf) per pair
std::vector<cl_float4> eval(KernelRig& r, const cl::Program& program, const LayerScene& sc, const dev::Material& m,
                            cl_uint use_ggx, const std::vector<cl_float4>& pairs) {
  return flat_eval(r, program, "test_layers_eval", pairs, r.input(std::vector<dev::Material>{m}), sc.textures,
                   sc.texels, sc.ggx, use_ggx);
}

// For each case seen from each wo (cosine z, azimuth phi): bsdf_sample agrees with bsdf_eval
// and bsdf_pdf; the pdf integrates to 1 over the sphere less what fails; chi-square of the
// sampled directions against the pdf (check_sphere_sampling, each cell integrated on 12 x 12
// midpoints, 6 x 6 on rusticl), alpha = 1e-3 over all of them with the Sidak correction
void check_sampling(KernelRig& r, const std::string& device, const std::vector<Layer>& cases,
                    const std::vector<double>& wo_z, double phi) {
  LayerScene sc(r, r.program, r.program_cache_file);
  bool fast = device == "rusticl";
  double alpha = sidak_alpha(1e-3, int(cases.size() * wo_z.size()));
  for (size_t c = 0; c < cases.size(); ++c)
    for (double z : wo_z) {
      SCOPED_TRACE("case " + std::to_string(c) + ", wo.z " + std::to_string(z));
      dev::Material m = material(cases[c]);
      glm::dvec3 wo = sphere_direction(z, phi);
      check_sphere_sampling(
          sample(r, r.program, sc, m, 1u, wo, samples_on(device, kLayerSamples), 11u), wo,
          [&](const std::vector<cl_float4>& pairs) { return eval(r, r.program, sc, m, 1u, pairs); }, fast ? 6 : 12,
          alpha);
    }
}

// Mean and standard error of the sample weights f |cos| / pdf per channel, split by the side
// of the sampled direction
struct Split {
  glm::dvec3 reflected{0.0}, transmitted{0.0}, r_err{0.0}, t_err{0.0};
};
Split split(const std::vector<cl_float4>& s) {
  size_t n = s.size() / 3;
  glm::dvec3 sum[2] = {glm::dvec3(0.0), glm::dvec3(0.0)}, sum2[2] = {glm::dvec3(0.0), glm::dvec3(0.0)};
  for (size_t i = 0; i < n; ++i) {
    const cl_float4 &a = s[3 * i], &f = s[3 * i + 1];
    if (a.s[3] == 0.0f) continue;
    int side = a.s[2] > 0.0f ? 0 : 1;
    for (int c = 0; c < 3; ++c) {
      double w = double(f.s[c]) * std::fabs(a.s[2]) / a.s[3];
      sum[side][c] += w;
      sum2[side][c] += w * w;
    }
  }
  Split out;
  for (int c = 0; c < 3; ++c) {
    out.reflected[c] = sum[0][c] / n;
    out.transmitted[c] = sum[1][c] / n;
    out.r_err[c] = std::sqrt(std::max(0.0, sum2[0][c] / n - out.reflected[c] * out.reflected[c]) / n);
    out.t_err[c] = std::sqrt(std::max(0.0, sum2[1][c] / n - out.transmitted[c] * out.transmitted[c]) / n);
  }
  return out;
}

// f wi.z (what the BSDF reflects toward wi per unit solid angle of incident light) along the
// plane of incidence: wi at polar angles -89..89 degrees toward +x, wo at -30 degrees
constexpr double kWoDeg = 30.0;
glm::dvec3 in_plane(double deg) {
  double a = deg * kPi / 180.0;
  return {std::sin(a), 0.0, std::cos(a)};
}
const std::vector<double>& scan_angles() {
  static const std::vector<double> angles = [] {
    std::vector<double> a;
    for (int k = -890; k <= 890; ++k) a.push_back(0.1 * k);
    return a;
  }();
  return angles;
}
std::vector<double> projected_f(KernelRig& r, const LayerScene& sc, const dev::Material& m) {
  glm::dvec3 wo = in_plane(-kWoDeg);
  std::vector<cl_float4> pairs;
  for (double d : scan_angles()) {
    pairs.push_back(f4(wo));
    pairs.push_back(f4(in_plane(d)));
  }
  std::vector<cl_float4> ev = eval(r, r.program, sc, m, 1u, pairs);
  std::vector<double> out;
  for (size_t i = 0; i < ev.size(); ++i)
    out.push_back(std::max({ev[i].s[0], ev[i].s[1], ev[i].s[2]}) * in_plane(scan_angles()[i]).z);
  return out;
}
size_t peak(const std::vector<double>& v) { return size_t(std::max_element(v.begin(), v.end()) - v.begin()); }
double peak_deg(const std::vector<double>& v) { return scan_angles()[peak(v)]; }
// The polar angle (in the plane, toward +x) of wo's mirror image about the decoded normal
double mirror_deg(glm::dvec3 n) {
  glm::dvec3 wo = in_plane(-kWoDeg), r = 2.0 * glm::dot(wo, n) * n - wo;
  return std::atan2(r.x, r.z) * 180.0 / kPi;
}

class ClearcoatNormal : public ::testing::TestWithParam<const char*> {};
class DiffuseTransmission : public ::testing::TestWithParam<const char*> {};

// A smooth coat (roughness 0.1) tilted by its normal map: its peak moves to wo's mirror image
// about the coat's normal, 2 x 12 degrees away; the rough base specular lobe under it stays at
// the mirror image about the shading normal. A base normal map without a coat normal map moves
// the base's peak and leaves the coat's at the unmapped normal's
TEST_P(ClearcoatNormal, CoatPeakFollowsTheCoatNormalAndTheBaseStays) {
  CANDELA_RIG_OR_SKIP(GetParam(), r);
  LayerScene sc(r, r.program, r.program_cache_file);
  double tilted_deg = mirror_deg(tilted().normal()), flat_deg = kWoDeg;
  ASSERT_NEAR(tilted_deg, kWoDeg + 2.0 * kTilt, 0.5);
  Layer coat_only;
  coat_only.base = glm::dvec3(0.0);
  coat_only.specular = 0.0;
  coat_only.coat = 1.0;
  coat_only.coat_roughness = 0.1;
  Layer full = coat_only;
  full.specular = 1.0;  // the base: its specular lobe alone
  full.roughness = 0.3;
  for (bool coat_normal : {false, true}) {
    SCOPED_TRACE(coat_normal ? "coat normal map" : "no normal map");
    Layer c = coat_only, f = full;
    c.coat_normal = f.coat_normal = coat_normal;
    std::vector<double> coat = projected_f(r, sc, material(c)), all = projected_f(r, sc, material(f)), base;
    for (size_t i = 0; i < all.size(); ++i) base.push_back(all[i] - coat[i]);
    EXPECT_NEAR(peak_deg(coat), coat_normal ? tilted_deg : flat_deg, 0.5);
    EXPECT_NEAR(peak_deg(base), flat_deg, 1.0);
    // The base lobe is broad, the coat's narrow: the coat dominates at its own peak
    size_t at = peak(coat);
    EXPECT_GT(coat[at], 2.0 * base[at]);
  }
  // The base's normal map moves the base, not the coat (the coat has no normal map of its own)
  Layer c = coat_only, f = full;
  c.base_normal = f.base_normal = true;
  std::vector<double> coat = projected_f(r, sc, material(c)), all = projected_f(r, sc, material(f)), base;
  for (size_t i = 0; i < all.size(); ++i) base.push_back(all[i] - coat[i]);
  EXPECT_NEAR(peak_deg(coat), flat_deg, 0.5);
  EXPECT_NEAR(peak_deg(base), tilted_deg, 3.0);
}

// Sampling with distinct coat and base normals (and with diffuse transmission under a tilted
// coat): chi-square against the pdf, sampled f and pdf equal to bsdf_eval's
TEST_P(ClearcoatNormal, SamplingMatchesThePdfWithDistinctNormals) {
  CANDELA_RIG_OR_SKIP(GetParam(), r);
  std::vector<Layer> cases(4);
  cases[0].coat = 1.0;
  cases[0].coat_roughness = 0.3;
  cases[0].coat_normal = true;
  cases[1] = cases[0];
  cases[1].metallic = 1.0;
  cases[1].roughness = 0.5;
  cases[1].base = glm::dvec3(0.9, 0.6, 0.3);
  cases[2] = cases[0];
  cases[2].coat_normal = false;
  cases[2].base_normal = true;
  cases[3] = cases[0];
  cases[3].diffuse_transmission = 0.6;
  cases[3].coat = 0.7;
  check_sampling(r, GetParam(), cases, {0.8, 0.35}, 2.8);
}

TEST_P(DiffuseTransmission, SamplingMatchesThePdf) {
  CANDELA_RIG_OR_SKIP(GetParam(), r);
  std::vector<Layer> cases(4);
  cases[0].diffuse_transmission = 0.5;
  cases[0].dt_color = glm::dvec3(0.9, 0.5, 0.2);
  cases[1] = cases[0];
  cases[1].diffuse_transmission = 1.0;
  cases[1].specular = 0.0;
  cases[2] = cases[0];
  cases[2].transmission = 0.5;
  cases[2].roughness = 0.3;
  cases[3] = cases[0];
  cases[3].sheen = glm::dvec3(0.8, 0.7, 0.6);
  cases[3].coat = 0.5;
  std::vector<double> wo_z = {0.8, 0.3};
  if (std::string(GetParam()) != "rusticl") wo_z.push_back(0.05);
  check_sampling(r, GetParam(), cases, wo_z, 0.4);
}

// White furnace: white base, factor 0.5, colour white, with the specular layer (the GGX
// albedo table bound) or without one: all the light comes back, reflected or transmitted
TEST_P(DiffuseTransmission, WhiteFurnaceIntegratesToOne) {
  CANDELA_RIG_OR_SKIP(GetParam(), r);
  LayerScene sc(r, r.program, r.program_cache_file);
  size_t n = samples_on(GetParam(), kLayerSamples);
  for (double specular : {0.0, 1.0})
    for (double rough : {0.2, 0.7})
      for (double z : {0.9, 0.5, 0.15}) {
        SCOPED_TRACE("specular " + std::to_string(specular) + ", roughness " + std::to_string(rough) + ", wo.z " +
                     std::to_string(z));
        Layer l;
        l.diffuse_transmission = 0.5;
        l.specular = specular;
        l.roughness = rough;
        Split s = split(sample(r, r.program, sc, material(l), 1u, sphere_direction(z, 1.0), n, 5u));
        for (int c = 0; c < 3; ++c) {
          double total = s.reflected[c] + s.transmitted[c], err = s.r_err[c] + s.t_err[c];
          // Without a specular layer every weight is exactly 1; the albedo table's
          // interpolation leaves a few 1e-3 with one
          EXPECT_NEAR(total, 1.0, 4.0 * err + (specular > 0.0 ? 1e-2 : 1e-4));
        }
      }
}

// Without a specular layer a white base splits the light (1 - d) : d, the transmitted part
// tinted by the colour; with one, the transmitted light is d times the full factor's
TEST_P(DiffuseTransmission, ReflectionAndTransmissionSplitByTheFactor) {
  CANDELA_RIG_OR_SKIP(GetParam(), r);
  LayerScene sc(r, r.program, r.program_cache_file);
  size_t n = samples_on(GetParam(), kLayerSamples);
  glm::dvec3 color(1.0, 0.5, 0.25);
  for (double z : {0.9, 0.3}) {
    glm::dvec3 wo = sphere_direction(z, 2.0);
    for (double d : {0.25, 0.5, 0.8}) {
      SCOPED_TRACE("factor " + std::to_string(d) + ", wo.z " + std::to_string(z));
      Layer l;
      l.specular = 0.0;
      l.diffuse_transmission = d;
      l.dt_color = color;
      Split s = split(sample(r, r.program, sc, material(l), 1u, wo, n, 9u));
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(s.reflected[c], 1.0 - d, 4.0 * s.r_err[c] + 1e-4);
        EXPECT_NEAR(s.transmitted[c], d * color[c], 4.0 * s.t_err[c] + 1e-4);
      }
      Layer spec = l, full = l;
      spec.specular = full.specular = 1.0;
      full.diffuse_transmission = 1.0;
      Split a = split(sample(r, r.program, sc, material(spec), 1u, wo, n, 9u));
      Split b = split(sample(r, r.program, sc, material(full), 1u, wo, n, 10u));
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(a.transmitted[c], d * b.transmitted[c], 4.0 * (a.t_err[c] + d * b.t_err[c]) + 1e-4);
    }
  }
}

// bsdf_sample of each case at wo.z 0.9, 0.3 and 0.01, and bsdf_eval at the sampled directions,
// bit for bit what the test program built with `option` (a feature compiled out) gives
void expect_same_without_feature(KernelRig& r, const char* device, const std::string& option,
                                 const std::vector<Layer>& cases) {
  ProgramBuild plain =
      build_program(r.context, r.device, test_program_source(), std::string(kTestProgramOptions) + " " + option);
  LayerScene sc(r, r.program, r.program_cache_file), sp(r, plain.program, plain.cache_file);
  size_t n = samples_on(device, kLayerSamples) / 8;
  for (size_t ci = 0; ci < cases.size(); ++ci) {
    dev::Material m = material(cases[ci]);
    for (double z : {0.9, 0.3, 0.01}) {
      SCOPED_TRACE("case " + std::to_string(ci) + ", wo.z " + std::to_string(z));
      glm::dvec3 wo = sphere_direction(z, 0.6);
      std::vector<cl_float4> a = sample(r, r.program, sc, m, 1u, wo, n, 5u),
                             b = sample(r, plain.program, sp, m, 1u, wo, n, 5u);
      EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(cl_float4)), 0);
      std::vector<cl_float4> pairs;
      for (size_t i = 0; i < n; ++i) {
        pairs.push_back(f4(wo));
        pairs.push_back(a[3 * i].s[3] > 0.0f ? a[3 * i] : f4(sphere_direction(-0.5, 0.1 * double(i))));
      }
      std::vector<cl_float4> ea = eval(r, r.program, sc, m, 1u, pairs), eb = eval(r, plain.program, sp, m, 1u, pairs);
      EXPECT_EQ(std::memcmp(ea.data(), eb.data(), ea.size() * sizeof(cl_float4)), 0);
    }
  }
}

// Factor 0: bsdf_sample and bsdf_eval give bit for bit what the program built with
// CD_FEATURE_DIFFUSE_TRANSMISSION=0 (the kernel of a scene without it) gives
TEST_P(DiffuseTransmission, FactorZeroIsTheMaterialWithoutTheFeature) {
  CANDELA_RIG_OR_SKIP(GetParam(), r);
  std::vector<Layer> cases(4);
  cases[1].metallic = 1.0;
  cases[2].transmission = 1.0;
  cases[2].roughness = 0.1;
  cases[3].coat = 1.0;
  cases[3].coat_normal = true;
  expect_same_without_feature(r, GetParam(), "-DCD_FEATURE_DIFFUSE_TRANSMISSION=0", cases);
}

class DiffuseRoughness : public ::testing::TestWithParam<const char*> {};

// White furnace of the EON base (KHR_materials_diffuse_roughness): alone it reflects 1 at
// every angle; under the specular layer (GGX albedo table bound) at least 0.98 and no more
// than the Lambertian base (whose furnace the layering keeps at 1): the layer's transmittance
// to the base is normalized for a Lambertian base, and EON sends more of its light toward
// grazing angles, where the layer lets less out (1 % less at roughness 1 and wo.z 0.15)
TEST_P(DiffuseRoughness, WhiteFurnaceConservesEnergy) {
  CANDELA_RIG_OR_SKIP(GetParam(), r);
  LayerScene sc(r, r.program, r.program_cache_file);
  size_t n = samples_on(GetParam(), kLayerSamples);
  for (double specular : {0.0, 1.0})
    for (double dr : {0.5, 1.0})
      for (double z : {0.9, 0.5, 0.15}) {
        SCOPED_TRACE("specular " + std::to_string(specular) + ", diffuse roughness " + std::to_string(dr) + ", wo.z " +
                     std::to_string(z));
        Layer eon, lambert;
        eon.specular = lambert.specular = specular;
        eon.diffuse_roughness = dr;
        Split a = split(sample(r, r.program, sc, material(eon), 1u, sphere_direction(z, 1.0), n, 5u));
        Split b = split(sample(r, r.program, sc, material(lambert), 1u, sphere_direction(z, 1.0), n, 5u));
        for (int c = 0; c < 3; ++c) {
          if (specular == 0.0) {
            EXPECT_NEAR(a.reflected[c], 1.0, 4.0 * a.r_err[c] + 1e-4);
          } else {
            EXPECT_GE(a.reflected[c], 0.98 - 4.0 * a.r_err[c]);
            EXPECT_LE(a.reflected[c], b.reflected[c] + 4.0 * (a.r_err[c] + b.r_err[c]) + 1e-3);
          }
        }
      }
}

// Factor 0: bsdf_sample and bsdf_eval give bit for bit what the program built with
// CD_FEATURE_DIFFUSE_ROUGHNESS=0 gives
TEST_P(DiffuseRoughness, FactorZeroIsTheMaterialWithoutTheFeature) {
  CANDELA_RIG_OR_SKIP(GetParam(), r);
  std::vector<Layer> cases(3);
  cases[0].base = glm::dvec3(0.8, 0.5, 0.2);
  cases[1].metallic = 1.0;
  cases[2].coat = 1.0;
  expect_same_without_feature(r, GetParam(), "-DCD_FEATURE_DIFFUSE_ROUGHNESS=0", cases);
}

INSTANTIATE_TEST_SUITE_P(Devices, ClearcoatNormal, ::testing::Values("pocl", "rusticl"),
                         [](const auto& info) { return std::string(info.param); });
INSTANTIATE_TEST_SUITE_P(Devices, DiffuseTransmission, ::testing::Values("pocl", "rusticl"),
                         [](const auto& info) { return std::string(info.param); });
INSTANTIATE_TEST_SUITE_P(Devices, DiffuseRoughness, ::testing::Values("pocl", "rusticl"),
                         [](const auto& info) { return std::string(info.param); });

}  // namespace
}  // namespace candela::test
