// Where each strategy fails (the lecture's point, without MIS): next-event estimation
// (nee), BSDF sampling (bsdf) and the per-vertex choice between them (auto) rendered to
// equal sample counts on scenes/lights/ and compared with a high-sample reference the
// test renders itself (another seed). relMSE = mean over pixels and channels of
// (x - r)^2 / (r^2 + 0.01).
//  - small-light: a small bright light over a diffuse floor: light sampling wins, and
//    auto, which light-samples at every diffuse vertex, is nee exactly;
//  - large-light-glossy: a large light over metal of alpha 0.0064: BSDF sampling wins,
//    and auto (BSDF sampling there) matches it;
//  - veach: plates of four roughnesses under lights of four sizes, direct light: auto
//    beats both.
// All three estimate the same image: their means agree with the reference's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "gltf_loader.hpp"
#include "renderer.hpp"
#include "test_support.hpp"

namespace candela::test {
namespace {

constexpr int kWidth = 96, kHeight = 64;

Film render(const Scene& scene, Strategy s, uint32_t spp, uint32_t max_depth, uint32_t seed) {
  RenderSettings settings;
  settings.width = kWidth;
  settings.height = kHeight;
  settings.strategy = s;
  settings.max_depth = max_depth;
  settings.seed = seed;
  return Renderer(pocl_device(), scene, settings).render(0, spp).film;
}

double rel_mse(const Film& f, const Film& ref) {
  double sum = 0.0;
  for (size_t i = 0; i < f.pixels(); ++i)
    for (int c = 0; c < 3; ++c) {
      double r = ref.pixel(i)[c], d = f.pixel(i)[c] - r;
      sum += d * d / (r * r + 0.01);
    }
  return sum / double(3 * f.pixels());
}

const char* name(Strategy s) { return s == Strategy::Nee ? "nee" : s == Strategy::Bsdf ? "bsdf" : "auto"; }

struct Errors {
  double nee = 0.0, bsdf = 0.0, automatic = 0.0;
};

// relMSE of each strategy summed over `seeds` renders of `spp` samples, and each image
// mean checked against the reference's (5 standard errors of the two, plus 1 %: the
// heavy-tailed strategy's error estimate is itself noisy)
Errors compare(const std::string& file, uint32_t max_depth, uint32_t spp, int seeds, Strategy ref_strategy,
               uint32_t ref_spp) {
  Scene scene = load_gltf(scene_path(file));
  Film ref = render(scene, ref_strategy, ref_spp, max_depth, 1000);
  Estimate ref_mean = image_mean(ref);
  Errors e;
  for (Strategy s : {Strategy::Nee, Strategy::Bsdf, Strategy::Auto})
    for (int k = 0; k < seeds; ++k) {
      Film f = render(scene, s, spp, max_depth, uint32_t(k + 1));
      double err = rel_mse(f, ref);
      (s == Strategy::Nee ? e.nee : s == Strategy::Bsdf ? e.bsdf : e.automatic) += err / seeds;
      Estimate m = image_mean(f);
      double se = std::hypot(m.standard_error, ref_mean.standard_error);
      EXPECT_NEAR(m.mean, ref_mean.mean, 5.0 * se + 0.01 * ref_mean.mean)
          << file << " " << name(s) << " seed " << k + 1 << " disagrees with the reference";
      EXPECT_TRUE(std::isfinite(err));
    }
  std::printf("%s (depth %u, %d x %u spp): relMSE nee %.5f, bsdf %.5f, auto %.5f\n", file.c_str(), max_depth, seeds,
              spp, e.nee, e.bsdf, e.automatic);
  return e;
}

}  // namespace

TEST(Strategies, SmallLightFavoursLightSampling) {
  Errors e = compare("lights/small-light.gltf", 4, 16, 2, Strategy::Nee, 1024);
  EXPECT_LT(3.0 * e.nee, e.bsdf);
  // Every vertex is diffuse: auto takes the same light samples as nee, number for number
  Scene scene = load_gltf(scene_path("lights/small-light.gltf"));
  Film a = render(scene, Strategy::Auto, 4, 4, 7), n = render(scene, Strategy::Nee, 4, 4, 7);
  EXPECT_EQ(a.mean, n.mean);
}

TEST(Strategies, LargeLightOnGlossyMetalFavoursBsdfSampling) {
  Errors e = compare("lights/large-light-glossy.gltf", 4, 16, 2, Strategy::Bsdf, 1024);
  EXPECT_LT(2.0 * e.bsdf, e.nee);
  EXPECT_LT(e.automatic, 1.3 * e.bsdf);
}

// Veach's layout under direct light: light sampling fails on the smooth plates, BSDF
// sampling on the rough ones and on the wall; auto takes the better one at each
TEST(Strategies, AutoBeatsBothOnVeachsPlates) {
  Errors e = compare("lights/veach.gltf", 1, 16, 4, Strategy::Auto, 1024);
  EXPECT_LT(e.automatic, e.nee);
  EXPECT_LT(e.automatic, e.bsdf);
}

}  // namespace candela::test
