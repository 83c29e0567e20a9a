// The samplers of cl/core/rng.cl (test kernels in tests/core/test_sampler.cl): uniformity per
// dimension and per pair, stratification (every prefix of 2^m samples of a Sobol pair is a
// (0,m,2)-net), decorrelation between pixels, pairs and seeds, the interface's dimension
// layout, and a render whose error at 256 spp the Sobol sampler must clearly beat.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "render/renderer.hpp"
#include "support/scenes.hpp"
#include "support/stats.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

constexpr int kSobol = 0, kIndependent = 1;

// Dimensions [0, dims) of samples [sample_begin, sample_begin + samples) of pixels
// [pixel_begin, pixel_begin + pixels): out[((p * samples) + s) * dims + d]
std::vector<cl_uint> draw(const KernelRig& rig, int which, cl_uint pixel_begin, size_t pixels, cl_uint sample_begin,
                          cl_uint samples, cl_uint seed, cl_uint dims) {
  size_t items = pixels * samples;
  auto out = rig.output<cl_uint>(items * dims);
  rig.run("test_sampler_draw", items, cl_uint(which), pixel_begin, sample_begin, samples, seed, dims, out);
  return out.read();
}

// Points (x[i * stride], y[i * stride]) for i in [begin, begin + 2^m): a (0,m,2)-net in
// base 2, i.e. every elementary interval [a 2^-k, (a + 1) 2^-k) x [b 2^-(m-k), (b + 1) 2^-(m-k))
// holds exactly one point, for every k = 0..m. Returns a description of the first failure.
std::string net_failure(const cl_uint* x, const cl_uint* y, size_t stride, size_t begin, int m) {
  size_t n = size_t(1) << m;
  for (int k = 0; k <= m; ++k) {
    std::vector<int> count(n, 0);
    for (size_t i = begin; i < begin + n; ++i) {
      uint64_t cx = k == 0 ? 0 : x[i * stride] >> (32 - k);
      uint64_t cy = k == m ? 0 : y[i * stride] >> (32 - (m - k));
      if (++count[(cx << (m - k)) | cy] > 1)
        return "m " + std::to_string(m) + ", intervals 2^-" + std::to_string(k) + " x 2^-" + std::to_string(m - k) +
               ": two points in one";
    }
  }
  return "";
}

// Chi-square p-value of the joint distribution of (a[i], b[i]) on a g x g grid of equal cells
double joint_p_value(const std::vector<double>& a, const std::vector<double>& b, int g) {
  std::vector<double> observed(g * g, 0.0), expected(g * g, double(a.size()) / (g * g));
  for (size_t i = 0; i < a.size(); ++i) observed[int(a[i] * g) * g + int(b[i] * g)] += 1.0;
  return chi_square_test(observed, expected).p_value;
}

double to_unit(cl_uint x) { return (x >> 8) * 0x1.0p-24; }

class SamplerTest : public DeviceTest {};

}  // namespace

// Every dimension is uniform: across many pixels at one sample index (where the numbers
// behave as independent draws) and over all samples of fewer pixels; pairs of dimensions
// too, across pixels. Chi-square at alpha = 0.01 with Sidak over all the tests here.
TEST_P(SamplerTest, EveryDimensionAndPairIsUniform) {
  const cl_uint dims = 12;
  const int bins = 64, g = 24;
  const int tests = 2 * dims + dims / 2;
  const double alpha = sidak_alpha(0.01, tests);
  std::vector<cl_uint> across = draw(rig(), kSobol, 1000, 1 << 18, 3, 1, 11, dims);
  std::vector<cl_uint> within = draw(rig(), kSobol, 0, 256, 0, 1024, 11, dims);
  for (const auto* v : {&across, &within})
    for (cl_uint d = 0; d < dims; ++d) {
      size_t n = v->size() / dims;
      std::vector<double> observed(bins, 0.0), expected(bins, double(n) / bins);
      for (size_t i = 0; i < n; ++i) observed[(*v)[i * dims + d] >> 26] += 1.0;
      ChiSquare r = chi_square_test(observed, expected);
      EXPECT_GT(r.p_value, alpha) << "dimension " << d << (v == &across ? " across pixels" : " within pixels")
                                  << ": chi2 " << r.statistic << " dof " << r.dof;
    }
  for (cl_uint d = 0; d < dims; d += 2) {
    std::vector<double> x, y;
    for (size_t i = 0; i < across.size() / dims; ++i) {
      x.push_back(to_unit(across[i * dims + d]));
      y.push_back(to_unit(across[i * dims + d + 1]));
    }
    EXPECT_GT(joint_p_value(x, y, g), alpha) << "pair " << d / 2 << " across pixels";
  }
}

// Stratification: the first 2^m samples of every pair of dimensions form a (0,m,2)-net
// for every m up to 12 (so the order is progressive), and so does every later aligned
// block of 2^8 samples; for several pixels, pairs and seeds. The independent sampler's
// points are not nets (the check can fail).
TEST_P(SamplerTest, EveryPrefixOfEveryPairIsANet) {
  const cl_uint dims = 128, samples = 4096;
  for (cl_uint seed : {0u, 9u})
    for (cl_uint pixel : {0u, 1u, 77u, 123456u}) {
      std::vector<cl_uint> v = draw(rig(), kSobol, pixel, 1, 0, samples, seed, dims);
      for (cl_uint pair : {0u, 1u, 2u, 3u, 17u, 63u}) {
        const cl_uint* x = &v[2 * pair];
        const cl_uint* y = &v[2 * pair + 1];
        for (int m = 0; m <= 12; ++m) {
          std::string f = net_failure(x, y, dims, 0, m);
          ASSERT_EQ(f, "") << "seed " << seed << " pixel " << pixel << " pair " << pair;
        }
        for (size_t block = 1; block < samples >> 8; ++block) {
          std::string f = net_failure(x, y, dims, block << 8, 8);
          ASSERT_EQ(f, "") << "block " << block << " seed " << seed << " pixel " << pixel << " pair " << pair;
        }
      }
    }
  std::vector<cl_uint> v = draw(rig(), kIndependent, 5, 1, 0, 256, 0, 2);
  EXPECT_NE(net_failure(&v[0], &v[1], 2, 0, 8), "") << "independent numbers are no net";
}

// Within its stratum, each of a pixel's first 2^m points is jittered independently (Owen
// scrambling randomizes every digit below the stratum): the offsets frac(2^m x) of one
// pixel's 16 samples have variance 1/12, for both coordinates of several pairs, averaged
// over 512 pixels (SE 0.0009 for the mean). A shifted lattice (one offset shared by all
// strata, what the first coordinate was before it had its own scramble) has variance 0.
TEST_P(SamplerTest, PointsAreJitteredWithinTheirStrata) {
  const int m = 4;
  const cl_uint dims = 8, samples = 1u << m, pixels = 512;
  std::vector<cl_uint> v = draw(rig(), kSobol, 300, pixels, 0, samples, 5, dims);
  for (cl_uint d = 0; d < dims; ++d) {
    double sum_var = 0.0;
    for (cl_uint p = 0; p < pixels; ++p) {
      double s1 = 0.0, s2 = 0.0;
      for (cl_uint i = 0; i < samples; ++i) {
        double offset = double(cl_uint(v[(p * samples + i) * dims + d] << m)) * 0x1.0p-32;
        s1 += offset;
        s2 += offset * offset;
      }
      sum_var += (s2 - s1 * s1 / samples) / (samples - 1);
    }
    double mean_var = sum_var / pixels;
    EXPECT_NEAR(mean_var, 1.0 / 12.0, 0.006)
        << "dimension " << d << " (coordinate " << d % 2 << " of pair " << d / 2 << ")";
  }
}

// Different pixels, seeds, pairs, and the two coordinates of different pairs are
// decorrelated: the joint distribution of one dimension against another over 2^16
// sample indices of one pixel is uniform on a 16 x 16 grid. A dimension against itself
// is rejected (the check can fail).
TEST_P(SamplerTest, PixelsPairsAndSeedsAreDecorrelated) {
  const cl_uint dims = 8, samples = 1 << 16;
  const cl_uint a = 4242;
  auto dim = [&](cl_uint pixel, cl_uint seed, cl_uint d) {
    std::vector<cl_uint> v = draw(rig(), kSobol, pixel, 1, 0, samples, seed, dims);
    std::vector<double> u(samples);
    for (cl_uint i = 0; i < samples; ++i) u[i] = to_unit(v[i * dims + d]);
    return u;
  };
  std::map<std::string, std::pair<std::vector<double>, std::vector<double>>> cases = {
      {"pixel a vs a + 1, dimension 0", {dim(a, 3, 0), dim(a + 1, 3, 0)}},
      {"pixel a vs a + 128, dimension 1", {dim(a, 3, 1), dim(a + 128, 3, 1)}},
      {"seed 3 vs seed 4, dimension 0", {dim(a, 3, 0), dim(a, 4, 0)}},
      {"dimension 0 vs 2", {dim(a, 3, 0), dim(a, 3, 2)}},
      {"dimension 1 vs 2", {dim(a, 3, 1), dim(a, 3, 2)}},
      {"dimension 0 vs 3", {dim(a, 3, 0), dim(a, 3, 3)}},
      {"dimension 1 vs 7", {dim(a, 3, 1), dim(a, 3, 7)}},
  };
  const double alpha = sidak_alpha(0.01, int(cases.size()));
  for (const auto& [name, xy] : cases) EXPECT_GT(joint_p_value(xy.first, xy.second, 16), alpha) << name;
  std::vector<double> same = dim(a, 3, 0);
  EXPECT_LT(joint_p_value(same, same, 16), 1e-6);
}

// The interface the integrator calls: 1D draws (rng_next, rng_next_uint) take the
// consecutive dimensions of the even pairs, rng_next_2d the next odd pair. The calls of
// two path vertices land on the dimensions below, every 2D point is a net over the samples,
// and floats are the top 24 bits of the dimension, below 1.
TEST_P(SamplerTest, InterfaceLaysDimensionsOutInPairs) {
  enum Op : cl_uint { kFloat = 0, kUint = 1, kPoint = 2 };
  // pixel position, then twice: light selection, light point, BSDF component and
  // direction, roulette
  const std::vector<cl_uint> ops = {kFloat, kFloat, kUint,  kPoint, kFloat, kPoint,
                                    kFloat, kUint,  kPoint, kFloat, kPoint, kFloat};
  // 1D draws 0, 1, 2, ... are dimensions 0, 1, 4, 5, 8, 9, ...; 2D draws are (2, 3), (6, 7), ...
  const std::vector<cl_uint> dim_of = {0, 1, 4, 2, 3, 5, 6, 7, 8, 9, 10, 11, 12, 14, 15, 13};
  const std::vector<size_t> points = {3, 6, 10, 13};  // outputs where a 2D point starts
  const cl_uint outputs = cl_uint(dim_of.size()), dims = 16, samples = 1024, pixels = 3;
  auto out = rig().output<float>(pixels * samples * outputs);
  rig().run("test_sampler_interface", pixels * samples, cl_uint(40), cl_uint(0), samples, cl_uint(21), rig().input(ops),
            cl_uint(ops.size()), outputs, out);
  std::vector<float> got = out.read();
  std::vector<cl_uint> want = draw(rig(), kSobol, 40, pixels, 0, samples, 21, dims);
  for (size_t i = 0; i < pixels * samples; ++i)
    for (cl_uint d = 0; d < outputs; ++d) {
      ASSERT_LT(got[i * outputs + d], 1.0f);
      ASSERT_EQ(got[i * outputs + d], float(to_unit(want[i * dims + dim_of[d]]))) << "sample " << i << " output " << d;
    }
  for (size_t p = 0; p < pixels; ++p)
    for (size_t o : points) {
      const cl_uint* base = &want[p * samples * dims + dim_of[o]];
      ASSERT_EQ(dim_of[o] % 2, 0u);
      ASSERT_EQ(dim_of[o + 1], dim_of[o] + 1);
      EXPECT_EQ(net_failure(base, base + 1, dims, 0, 10), "") << "pixel " << p << " output " << o;
    }
}

// The same numbers on every device
TEST_P(SamplerTest, SameNumbersAsPocl) {
  if (GetParam() == "pocl") GTEST_SKIP() << "the reference device itself";
  for (int which : {kSobol, kIndependent})
    EXPECT_EQ(draw(rig(), which, 7, 64, 100, 64, 5, 40), draw(kernel_rig("pocl"), which, 7, 64, 100, 64, 5, 40))
        << which;
}

// The CPU packets' eight-lane draw of a pair (rng_sobol_pair8) is rng_sobol_pair's, lane
// for lane and bit for bit: random pixels (consecutive ones too), samples, pairs and seeds
TEST_P(SamplerTest, EightLanePairsAreTheScalarPairs) {
  const size_t groups = 4096;
  std::vector<cl_uint> pixels(8 * groups), samples(groups);
  uint64_t state = 0x9e3779b97f4a7c15ull;
  auto next = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return cl_uint(state >> 32);
  };
  for (size_t g = 0; g < groups; ++g) {
    cl_uint first = next() % (1u << 22);
    for (size_t l = 0; l < 8; ++l) pixels[8 * g + l] = g % 2 == 0 ? first + cl_uint(l) : next();
    samples[g] = g % 4 < 2 ? cl_uint(g % 64) : next();
  }
  cl::Buffer pixel_buf = rig().input(pixels), sample_buf = rig().input(samples);
  for (cl_uint seed : {0u, 7u, 0xfffffffeu})
    for (cl_uint pair : {0u, 1u, 2u, 77u}) {
      auto out = rig().output<cl_uint>(groups);
      rig().run("test_sampler_pair8", groups, pixel_buf, sample_buf, seed, pair, out);
      std::vector<cl_uint> same = out.read();
      EXPECT_EQ(std::count(same.begin(), same.end(), 1u), long(groups)) << "seed " << seed << " pair " << pair;
    }
}

INSTANTIATE_TEST_SUITE_P(Devices, SamplerTest, kernel_devices(), DeviceParamName());

// A diffuse floor under a square area light, with a small occluder between them casting a
// soft shadow, direct lighting only. Against a 4096-spp Sobol reference (another seed),
// the image's relMSE (epsilon 0.01) at 16, 64 and 256 spp, mean of two seeds, for both
// samplers: Sobol's at 256 spp must be well below the independent sampler's.
TEST(SamplerConvergence, SobolBeatsIndependentOnAnAreaLitFloor) {
  const float h = 0.6f, s = 0.2f, o = 0.08f, oh = 0.3f;
  GltfBuilder g = floor_under_square_light(h, s, 4, {quad_facing_up(o, oh, 0)});  // an occluder of the floor's material
  g.add_camera({0.0f, 1.3f, 1.1f}, {0, 0, 0}, 0.9f);
  Scene scene = load_scene(g, "sampler-floor.gltf");

  const int size = 32;
  auto render = [&](Sampler sampler, uint32_t seed, uint32_t spp) {
    RenderSettings settings;
    settings.width = settings.height = size;
    settings.max_depth = 1;
    settings.sampler = sampler;
    settings.seed = seed;
    return scene_renderer(pocl_device(), scene, settings).render(0, spp).film;
  };
  Film reference = render(Sampler::Sobol, 1000, 4096);
  std::map<std::pair<Sampler, uint32_t>, double> err;
  for (Sampler sampler : {Sampler::Independent, Sampler::Sobol})
    for (uint32_t spp : {16u, 64u, 256u}) {
      double e = 0.0;
      for (uint32_t seed : {1u, 2u}) e += 0.5 * rel_mse(render(sampler, seed, spp), reference);
      err[{sampler, spp}] = e;
      std::printf("[ relMSE   ] %-11s %3u spp: %.3e\n", sampler == Sampler::Sobol ? "sobol" : "independent", spp, e);
    }
  // The independent sampler's error falls as 1/N (within noise), so the test sees real error
  double independent_gain = err[{Sampler::Independent, 16}] / err[{Sampler::Independent, 256}];
  EXPECT_NEAR(independent_gain, 16.0, 5.0);
  auto at = [&](Sampler sampler, uint32_t spp) { return err[std::make_pair(sampler, spp)]; };
  double ratio = at(Sampler::Sobol, 256) / at(Sampler::Independent, 256);
  std::printf("[ relMSE   ] sobol / independent at 256 spp: %.3f\n", ratio);
  EXPECT_LT(ratio, 0.7);
  EXPECT_LT(at(Sampler::Sobol, 64), at(Sampler::Independent, 64));
}

}  // namespace candela::test
