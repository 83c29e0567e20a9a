// Anisotropic lobes (KHR_materials_anisotropy) never produce a non-finite sample: the real
// bsdf_at / bsdf_sample / bsdf_eval (tests/bsdf/test_anisotropy.cl) on PoCL and rusticl at
// the shading points a mesh can produce: roughness 0 with anisotropy (alpha_b clamped to
// GGX_DELTA_ALPHA), zero, NaN, infinite and normal-parallel tangents, TANGENT.w of 0 or NaN,
// an anisotropy texture whose direction is zero, and directions down to 1e-38 above the
// horizon. Every sample weight f |cos| / pdf and every eval is finite, and the weights of
// the reflection lobes stay below 1 (VNDF sampling: G2 / G1 <= 1, F <= 1, no table bound).
#include <gtest/gtest.h>

#include <cmath>
#include <glm/glm.hpp>
#include <limits>

#include "support/kernels.hpp"

namespace candela::test {
namespace {

// Samples per configuration: rusticl (llvmpipe) runs a quarter of PoCL's, being about 5x slower
constexpr size_t kSamples = 1 << 15;
size_t samples_on(const std::string& device) { return device == "rusticl" ? kSamples / 4 : kSamples; }
constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

dev::Material anisotropic(unsigned type, double metallic, double roughness, double strength,
                          double transmission = 0.0) {
  dev::Material m{};
  m.type = type;
  for (int c = 0; c < 4; ++c) m.base_color[c] = 0.9f;
  m.normal_scale = 1.0f;
  for (dev::TextureRef& t : m.textures) {
    t.index = NO_TEXTURE;
    t.m[0] = t.m[4] = 1.0f;
  }
  if (type == MATERIAL_GLTF) {
    m.params.gltf.ior = 1.5f;
    for (float& s : m.params.gltf.specular_color) s = 1.0f;
    m.params.gltf.specular = 1.0f;
    m.params.gltf.metallic = float(metallic);
    m.params.gltf.roughness = float(roughness);
    m.params.gltf.transmission = float(transmission);
    m.params.gltf.anisotropy_strength = float(strength);
    m.params.gltf.anisotropy_rotation = 0.7f;
  } else {
    const float eta[3] = {0.143f, 0.375f, 1.442f}, k[3] = {3.983f, 2.386f, 1.603f};  // gold
    for (int c = 0; c < 3; ++c) {
      m.params.conductor.eta[c] = eta[c];
      m.params.conductor.k[c] = k[c];
    }
    m.params.conductor.roughness = float(roughness);
    m.params.conductor.anisotropy_strength = float(strength);
    m.params.conductor.anisotropy_rotation = 0.7f;
  }
  return m;
}

struct Case {
  const char* name;
  dev::Material material;
  bool reflection_only;  // weights <= 1
};

std::vector<Case> cases() {
  return {
      {"metal r0 s0.5", anisotropic(MATERIAL_GLTF, 1.0, 0.0, 0.5), true},
      {"metal r0 s1", anisotropic(MATERIAL_GLTF, 1.0, 0.0, 1.0), true},
      {"metal r0.02 s0.3", anisotropic(MATERIAL_GLTF, 1.0, 0.02, 0.3), true},
      {"metal r0.3 s1", anisotropic(MATERIAL_GLTF, 1.0, 0.3, 1.0), true},
      {"conductor r0 s0.8", anisotropic(MATERIAL_CONDUCTOR, 1.0, 0.0, 0.8), true},
      {"plastic r0 s0.6", anisotropic(MATERIAL_GLTF, 0.0, 0.0, 0.6), false},
      {"glass r0 s0.7", anisotropic(MATERIAL_GLTF, 0.0, 0.0, 0.7, 1.0), false},
  };
}

struct Tangent {
  const char* name;
  cl_float4 t;
};
const Tangent kTangents[] = {
    {"unit", {{1.0f, 0.0f, 0.0f, 1.0f}}},     {"zero", {{0.0f, 0.0f, 0.0f, 1.0f}}},
    {"along n", {{0.0f, 0.0f, 1.0f, 1.0f}}},  {"tiny", {{1e-30f, 1e-30f, 0.0f, 1.0f}}},
    {"nan", {{kNan, 0.0f, 0.0f, 1.0f}}},      {"inf", {{kInf, 1.0f, 0.0f, -1.0f}}},
    {"w = 0", {{0.3f, 0.8f, 0.1f, 0.0f}}},    {"w = nan", {{0.3f, 0.8f, 0.1f, kNan}}},
    {"w = -1", {{0.0f, -1.0f, 0.2f, -1.0f}}},
};

// Directions of wo: ordinary, grazing down to 1e-7, and from below (a transmitting lobe's back face)
std::vector<cl_float4> wos() {
  std::vector<cl_float4> w;
  for (double z : {0.9, 0.5, 0.1, 1e-2, 1e-3, 1e-5, 1e-7, -0.7, -1e-4})
    for (double phi : {0.0, 1.1, 2.5, 4.0}) {
      double r = std::sqrt(1.0 - z * z);
      w.push_back({{float(r * std::cos(phi)), float(r * std::sin(phi)), float(z), 0.0f}});
    }
  return w;
}

// The anisotropy texture: 2 x 1 texels, (0, 0, 255) and (255, 255, 255), clamped: halfway
// between their centres (u = 0.5) the direction (rg * 2 - 1) is exactly zero, at u = 0 it is
// (-1, -1), and blue (the strength) is 1 everywhere
struct AnisotropyTexture {
  cl::Buffer textures, texels, srgb;
  explicit AnisotropyTexture(KernelRig& r) {
    dev::TextureInfo info{0u, 2u, 1u, WRAP_CLAMP | (WRAP_CLAMP << 8)};
    dev::Texel8 t[2] = {{0, 0, 255, 255}, {255, 255, 255, 255}};
    std::vector<float> s(256);
    for (int i = 0; i < 256; ++i) s[i] = dev::srgb_to_linear(i / 255.0f);
    textures = cl::Buffer(r.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof info, &info);
    texels = cl::Buffer(r.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof t, t);
    srgb = cl::Buffer(r.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, s.size() * sizeof(float), s.data());
  }
};

struct Outcome {
  size_t non_finite = 0;
  double max_weight = 0.0;
};

Outcome run(KernelRig& r, const AnisotropyTexture& tex, const dev::Material& m, cl_float4 tangent, cl_float2 uv,
            size_t n, cl_uint seed) {
  std::vector<cl_float4> w = wos();
  cl::Buffer materials(r.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof m, const_cast<dev::Material*>(&m));
  cl::Buffer wo_buf(r.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, w.size() * sizeof(cl_float4), w.data());
  cl::Buffer out(r.context, CL_MEM_WRITE_ONLY, 2 * n * sizeof(cl_float4));
  cl::Kernel k(r.program, "test_anisotropy_weights");
  cl_float4 grazing = {{1e-3f, 1e-6f, 1e-20f, 1e-38f}};
  int a = 0;
  k.setArg(a++, materials);
  k.setArg(a++, tex.textures);
  k.setArg(a++, tex.texels);
  k.setArg(a++, tex.srgb);
  k.setArg(a++, tangent);
  k.setArg(a++, uv);
  k.setArg(a++, wo_buf);
  k.setArg(a++, cl_uint(w.size()));
  k.setArg(a++, grazing);
  k.setArg(a++, seed);
  k.setArg(a++, out);
  r.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(n));
  std::vector<cl_float4> o(2 * n);
  r.queue.enqueueReadBuffer(out, CL_TRUE, 0, o.size() * sizeof(cl_float4), o.data());
  Outcome res;
  for (size_t i = 0; i < n; ++i) {
    const cl_float4 &s = o[2 * i], &e = o[2 * i + 1];
    if (s.s[3] != 1.0f || e.s[3] != 1.0f) ++res.non_finite;
    for (int c = 0; c < 3; ++c)
      if (std::isfinite(s.s[c])) res.max_weight = std::max(res.max_weight, double(s.s[c]));
  }
  return res;
}

class AnisotropyIsFinite : public ::testing::TestWithParam<const char*> {};

TEST_P(AnisotropyIsFinite, AtEveryShadingPoint) {
  CANDELA_RIG_OR_SKIP(GetParam(), r);
  AnisotropyTexture tex(r);
  for (const Case& c : cases()) {
    for (int textured = 0; textured < 3; ++textured) {
      dev::Material m = c.material;
      cl_float2 uv = {{0.5f, 0.5f}};  // zero direction
      if (textured) m.textures[TEX_ANISOTROPY].index = 0;
      if (textured == 2) uv = {{0.0f, 0.5f}};  // direction (-1, -1)
      for (const Tangent& t : kTangents) {
        SCOPED_TRACE(std::string(c.name) + ", tangent " + t.name + (textured ? ", textured" : "") +
                     (textured == 1 ? " (zero direction)" : ""));
        Outcome o = run(r, tex, m, t.t, uv, samples_on(GetParam()), 11u);
        EXPECT_EQ(o.non_finite, 0u);
        if (c.reflection_only) {
          EXPECT_LE(o.max_weight, 1.0 + 1e-3);
        }
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Devices, AnisotropyIsFinite, ::testing::Values("pocl", "rusticl"),
                         [](const auto& info) { return std::string(info.param); });

}  // namespace
}  // namespace candela::test
