// The sheen layer of KHR_materials_sheen (cl/bsdf/sheen.cl, the Charlie lobe of Estevez &
// Kulla 2017, and its albedo scaling in cl/bsdf/gltf/sheen.cl) on PoCL and rusticl: the lobe against
// a host evaluation of the formula; the device-computed albedo table against a host
// quadrature; sampling of sheen materials (bsdf_sample agrees with bsdf_eval / bsdf_pdf, the
// pdf integrates to 1, chi-square of the sampled directions); a white furnace (albedo <= 1,
// and the albedo scaling lowers it); and a sheen colour of 0 gives bit for bit the material
// of a kernel built without CD_FEATURE_SHEEN.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <glm/glm.hpp>

#include "bsdf/bsdf_checks.hpp"
#include "device/energy.hpp"
#include "device/kernel_sources.hpp"
#include "device/program_cache.hpp"
#include "device/sheen_albedo.hpp"

namespace candela::test {
namespace {

// Samples per configuration on PoCL: rusticl (llvmpipe) runs a quarter of them (samples_on),
// being about 5x slower
constexpr size_t kSheenSamples = 1 << 18;

// Host Charlie lobe with colour 1 (Estevez & Kulla 2017; the extension's visibility term)
double ref_l(double x, double alpha) {
  double t = (1.0 - alpha) * (1.0 - alpha);
  double a = 21.5473 + (25.3245 - 21.5473) * t, b = 3.82987 + (3.32435 - 3.82987) * t;
  double c = 0.19823 + (0.16801 - 0.19823) * t, d = -1.97760 + (-1.27393 + 1.97760) * t;
  double e = -4.32054 + (-4.85967 + 4.32054) * t;
  return a / (1.0 + b * std::pow(x, c)) + d * x + e;
}
double ref_lambda(double c, double alpha) {
  return c < 0.5 ? std::exp(ref_l(c, alpha)) : std::exp(2.0 * ref_l(0.5, alpha) - ref_l(1.0 - c, alpha));
}
double ref_alpha(double r) { return std::max(r * r, 1e-3); }
double ref_sheen(double alpha, glm::dvec3 wo, glm::dvec3 wi) {
  if (wo.z <= 0.0 || wi.z <= 0.0) return 0.0;
  glm::dvec3 h = glm::normalize(wo + wi);
  double sin2 = std::max(1.0 - h.z * h.z, 0.0);
  double d = (2.0 + 1.0 / alpha) * std::pow(sin2, 0.5 / alpha) / (2.0 * kPi);
  return d / ((1.0 + ref_lambda(wo.z, alpha) + ref_lambda(wi.z, alpha)) * 4.0 * wo.z * wi.z);
}

// E(mu) of the host lobe: midpoint rule in (t, phi), cos theta_i = t^2, phi over (0, pi)
double ref_albedo(double mu, double r, int n) {
  glm::dvec3 wo(std::sqrt(std::max(0.0, 1.0 - mu * mu)), 0.0, mu);
  double sum = 0.0, alpha = ref_alpha(r);
  for (int a = 0; a < n; ++a) {
    double t = (a + 0.5) / n, z = t * t, s = std::sqrt(std::max(0.0, 1.0 - z * z));
    for (int b = 0; b < 4 * n; ++b) {
      double phi = kPi * (b + 0.5) / (4 * n);
      sum += ref_sheen(alpha, wo, {s * std::cos(phi), s * std::sin(phi), z}) * z * 2.0 * t;
    }
  }
  return sum * 2.0 * kPi / (double(n) * 4 * n);
}

// A glTF material: white base colour unless given, specular 1, ior 1.5, the sheen colour and roughness
dev::Material material(double metallic, double roughness, glm::dvec3 sheen, double sheen_roughness,
                       double transmission = 0.0, double coat = 0.0, glm::dvec3 base = glm::dvec3(1.0),
                       double specular = 1.0) {
  dev::Material m = gltf(base, metallic, roughness, transmission);
  dev::GltfMaterial& g = m.params.gltf;
  g.specular = float(specular);
  g.clearcoat = float(coat);
  g.clearcoat_roughness = 0.3f;
  for (int c = 0; c < 3; ++c) g.sheen_color[c] = float(sheen[c]);
  g.sheen_roughness = float(sheen_roughness);
  return m;
}

struct Sampled {
  std::vector<cl_float4> out;  // 3 per sample (test_sheen_sample)
};

// test_sheen_sample: 3 float4 per sample (test_bsdf_sample_record)
Sampled sample(KernelRig& r, const cl::Program& program, const AlbedoTables& t, const dev::Material& m, cl_uint tables,
               glm::dvec3 wo, size_t n, cl_uint seed) {
  return {flat_sample(r, program, "test_sheen_sample", wo, n, seed, r.input(std::vector<dev::Material>{m}), t.ggx,
                      t.sheen, tables)};
}

// test_sheen_eval: (f, pdf) per pair
std::vector<cl_float4> eval(KernelRig& r, const cl::Program& program, const AlbedoTables& t, const dev::Material& m,
                            cl_uint tables, const std::vector<cl_float4>& pairs) {
  return flat_eval(r, program, "test_sheen_eval", pairs, r.input(std::vector<dev::Material>{m}), t.ggx, t.sheen,
                   tables);
}

class Sheen : public ::testing::TestWithParam<const char*> {};

TEST_P(Sheen, LobeMatchesTheFormula) {
  CANDELA_RIG_OR_SKIP(GetParam(), r);
  std::vector<cl_float4> pairs;
  std::vector<double> want;
  for (double rough : {0.0, 0.1, 0.3, 0.5, 0.8, 1.0})
    for (double zo : {0.95, 0.6, 0.2, 0.02})
      for (double zi : {0.9, 0.5, 0.1, 0.01})
        for (double phi : {0.0, 1.3, 2.9}) {
          glm::dvec3 wo = sphere_direction(zo, 0.0), wi = sphere_direction(zi, phi);
          pairs.push_back(f4(wo, ref_alpha(rough)));
          pairs.push_back(f4(wi));
          want.push_back(ref_sheen(ref_alpha(rough), wo, wi));
        }
  size_t n = want.size();
  cl::Buffer in(r.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, pairs.size() * sizeof(cl_float4), pairs.data());
  cl::Buffer out(r.context, CL_MEM_WRITE_ONLY, n * sizeof(float));
  cl::Kernel k(r.program, "test_sheen_lobe");
  k.setArg(0, in);
  k.setArg(1, out);
  r.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(n));
  std::vector<float> got(n);
  r.queue.enqueueReadBuffer(out, CL_TRUE, 0, n * sizeof(float), got.data());
  for (size_t i = 0; i < n; ++i) EXPECT_NEAR(got[i], want[i], 2e-3 * want[i] + 1e-6) << "pair " << i;
}

TEST_P(Sheen, AlbedoTableMatchesAHostQuadrature) {
  CANDELA_RIG_OR_SKIP(GetParam(), r);
  cl::Buffer table = sheen_albedo_table(r.context, r.queue, r.program, "").buffer;
  std::vector<float> t(SHEEN_ALBEDO_SIZE);
  r.queue.enqueueReadBuffer(table, CL_TRUE, 0, t.size() * sizeof(float), t.data());
  for (float e : t) {
    EXPECT_GE(e, 0.0f);
    EXPECT_TRUE(std::isfinite(e));
  }
  // E exceeds 1 only toward grazing angles (6.1 at mu = 1e-3, r = 0); nodes at mu = (i / last)^2
  for (int i = 10; i < SHEEN_ALBEDO_N; ++i)
    for (int j = 0; j < SHEEN_ALBEDO_N; ++j) EXPECT_LE(t[j * SHEEN_ALBEDO_N + i], 1.0f) << i << ", " << j;
  const int last = SHEEN_ALBEDO_N - 1;
  // Nodes: the table itself; between them: the bilinear lookup
  for (int i : {0, 1, 4, 16, last})
    for (int j : {0, 3, 10, 20, last}) {
      double mu = std::max(double(i * i) / (last * last), 1e-3), rough = double(j) / last,
             want = ref_albedo(mu, rough, 128);
      EXPECT_NEAR(t[j * SHEEN_ALBEDO_N + i], want, 1e-3 + 1e-3 * want) << "mu " << mu << ", r " << rough;
    }
  std::vector<cl_float2> q;
  for (double mu : {0.02, 0.33, 0.71})
    for (double rough : {0.55, 0.93}) q.push_back({{float(mu), float(rough)}});
  cl::Buffer qb(r.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, q.size() * sizeof(cl_float2), q.data());
  cl::Buffer out(r.context, CL_MEM_WRITE_ONLY, q.size() * sizeof(float));
  cl::Kernel k(r.program, "test_sheen_albedo_lookup");
  k.setArg(0, table);
  k.setArg(1, qb);
  k.setArg(2, out);
  r.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(q.size()));
  std::vector<float> got(q.size());
  r.queue.enqueueReadBuffer(out, CL_TRUE, 0, got.size() * sizeof(float), got.data());
  for (size_t i = 0; i < q.size(); ++i)
    EXPECT_NEAR(got[i], ref_albedo(q[i].s[0], q[i].s[1], 128), 1e-2) << "mu " << q[i].s[0] << ", r " << q[i].s[1];
}

struct SampledCase {
  const char* name;
  dev::Material m;
};
std::vector<SampledCase> sampled_cases() {
  glm::dvec3 sheen(0.9, 0.6, 0.3);
  return {
      {"sheen alone r0.5", material(0.0, 0.5, sheen, 0.5, 0.0, 0.0, glm::dvec3(0.0), 0.0)},
      {"sheen r0.2 over plastic r0.4", material(0.0, 0.4, sheen, 0.2)},
      {"sheen r0.9 over metal r0.3", material(1.0, 0.3, sheen, 0.9)},
      {"sheen r0.6 over coated plastic", material(0.0, 0.5, sheen, 0.6, 0.0, 1.0)},
      {"sheen r0.4 over rough glass", material(0.0, 0.3, sheen, 0.4, 1.0)},
  };
}

// bsdf_sample agrees with bsdf_eval and bsdf_pdf; the mixture pdf integrates to 1 over the
// sphere less what the GGX lobes send below the horizon (samples that fail); a chi-square test
// of the sampled directions against the pdf in equal-area cells
TEST_P(Sheen, SamplingMatchesThePdf) {
  CANDELA_RIG_OR_SKIP(GetParam(), r);
  AlbedoTables t(r, r.program, r.program_cache_file);
  // rusticl (llvmpipe) integrates the pdf on a coarser grid and leaves out grazing wo, whose
  // narrow lobes need the fine one
  bool fast = std::string(GetParam()) == "rusticl";
  const int sub = fast ? 6 : 16;
  std::vector<SampledCase> cases = sampled_cases();
  std::vector<double> wo_z = {0.8, 0.3};
  if (!fast) wo_z.push_back(0.05);
  double alpha = sidak_alpha(1e-3, int(cases.size() * wo_z.size()));
  for (const SampledCase& c : cases)
    for (double z : wo_z) {
      SCOPED_TRACE(std::string(c.name) + ", wo.z " + std::to_string(z));
      glm::dvec3 wo = sphere_direction(z, 0.4);
      size_t n = samples_on(GetParam(), kSheenSamples);
      check_sphere_sampling(
          sample(r, r.program, t, c.m, 3u, wo, n, 7u).out, wo,
          [&](const std::vector<cl_float4>& pairs) { return eval(r, r.program, t, c.m, 3u, pairs); }, sub, alpha);
    }
}

// Mean and standard error of the sample weights' largest channel
struct Albedo {
  double mean = 0.0, err = 0.0;
};
Albedo albedo(const Sampled& s) {
  size_t n = s.out.size() / 3;
  double sum = 0.0, sum2 = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const cl_float4 &a = s.out[3 * i], &f = s.out[3 * i + 1];
    if (a.s[3] == 0.0f) continue;
    double w = 0.0;
    for (int c = 0; c < 3; ++c) {
      // delta samples carry f = weight / cos and pdf = the choice's probability
      double cos = std::fabs(a.s[2]);
      w = std::max(w, double(f.s[c]) * cos / a.s[3]);
    }
    sum += w;
    sum2 += w * w;
  }
  Albedo out;
  out.mean = sum / n;
  out.err = std::sqrt(std::max(0.0, sum2 / n - out.mean * out.mean) / n);
  return out;
}

// White furnace: white base, sheen colour 1; the albedo (largest channel) stays <= 1 (at
// grazing angles and low sheen roughness too, where the Charlie lobe alone exceeds 1), and
// without the sheen table (no albedo scaling) a sheen over white Lambert exceeds what it has
// with it
TEST_P(Sheen, WhiteFurnaceStaysAtMostOne) {
  CANDELA_RIG_OR_SKIP(GetParam(), r);
  AlbedoTables t(r, r.program, r.program_cache_file);
  size_t n = samples_on(GetParam(), kSheenSamples) / 4;
  for (double sr : {0.0, 0.3, 0.7, 1.0})
    for (double z : {0.9, 0.4, 0.1, 0.02}) {
      glm::dvec3 wo = sphere_direction(z, 1.0);
      struct {
        const char* name;
        dev::Material m;
      } cases[] = {
          {"lambert", material(0.0, 0.5, glm::dvec3(1.0), sr, 0.0, 0.0, glm::dvec3(1.0), 0.0)},
          {"plastic r0.2", material(0.0, 0.2, glm::dvec3(1.0), sr)},
          {"plastic r0 (mirror)", material(0.0, 0.0, glm::dvec3(1.0), sr)},
          {"metal r1", material(1.0, 1.0, glm::dvec3(1.0), sr)},
          {"coated plastic r0.6", material(0.0, 0.6, glm::dvec3(1.0), sr, 0.0, 1.0)},
          {"glass r0.3", material(0.0, 0.3, glm::dvec3(1.0), sr, 1.0)},
      };
      for (const auto& c : cases) {
        SCOPED_TRACE(std::string(c.name) + ", sheen r " + std::to_string(sr) + ", wo.z " + std::to_string(z));
        Albedo a = albedo(sample(r, r.program, t, c.m, 3u, wo, n, 3u));
        EXPECT_LE(a.mean, 1.0 + 4.0 * a.err + 2e-3);
        if (std::string(c.name) == "lambert" && sr >= 0.3 && z <= 0.4) {
          Albedo unscaled = albedo(sample(r, r.program, t, c.m, 1u, wo, n, 3u));
          EXPECT_GT(unscaled.mean, a.mean + 4.0 * (a.err + unscaled.err));
        }
      }
    }
}

// Sheen colour 0: bsdf_sample and bsdf_eval give bit for bit what the program built with
// CD_FEATURE_SHEEN=0 (the kernel of a scene without sheen) gives
TEST_P(Sheen, ColourZeroIsTheMaterialWithoutTheFeature) {
  CANDELA_RIG_OR_SKIP(GetParam(), r);
  ProgramBuild plain = build_program(r.context, r.device, test_program_source(),
                                     std::string(kTestProgramOptions) + " -DCD_FEATURE_SHEEN=0");
  AlbedoTables t(r, r.program, r.program_cache_file), tp(r, plain.program, plain.cache_file);
  dev::Material cases[] = {
      material(0.0, 0.4, glm::dvec3(0.0), 0.5),           material(1.0, 0.2, glm::dvec3(0.0), 0.5),
      material(0.0, 0.0, glm::dvec3(0.0), 0.5),           material(0.0, 0.1, glm::dvec3(0.0), 0.5, 1.0),
      material(0.0, 0.5, glm::dvec3(0.0), 0.5, 0.0, 1.0),
  };
  size_t n = samples_on(GetParam(), kSheenSamples) / 8;
  for (size_t ci = 0; ci < std::size(cases); ++ci) {
    const dev::Material& m = cases[ci];
    for (double z : {0.9, 0.3, 0.01}) {
      SCOPED_TRACE("case " + std::to_string(ci) + ", wo.z " + std::to_string(z));
      glm::dvec3 wo = sphere_direction(z, 0.6);
      Sampled a = sample(r, r.program, t, m, 3u, wo, n, 5u), b = sample(r, plain.program, tp, m, 3u, wo, n, 5u);
      EXPECT_EQ(std::memcmp(a.out.data(), b.out.data(), a.out.size() * sizeof(cl_float4)), 0);
      std::vector<cl_float4> pairs;
      for (size_t i = 0; i < n; ++i) {
        pairs.push_back(f4(wo));
        pairs.push_back(a.out[3 * i].s[3] > 0.0f ? a.out[3 * i] : f4(sphere_direction(-0.5, 0.1 * double(i))));
      }
      std::vector<cl_float4> ea = eval(r, r.program, t, m, 3u, pairs), eb = eval(r, plain.program, tp, m, 3u, pairs);
      EXPECT_EQ(std::memcmp(ea.data(), eb.data(), ea.size() * sizeof(cl_float4)), 0);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Devices, Sheen, ::testing::Values("pocl", "rusticl"),
                         [](const auto& info) { return std::string(info.param); });

}  // namespace
}  // namespace candela::test
