// The sample scheduler: a scene compiled once, rendered by several device workers that
// take disjoint ranges of sample indices, gives the single-worker image.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "gltf_loader.hpp"
#include "renderer.hpp"
#include "test_support.hpp"

namespace candela::test {

// Two workers on PoCL (two contexts, one thread each) against one: the RNG is keyed by
// sample index, so the merged film equals the single one up to the rounding of the merge
TEST(Scheduler, TwoWorkersGiveTheSingleWorkerImage) {
  auto scene = std::make_shared<const CompiledScene>(compile_scene(load_gltf(scene_path("cornell-box/cornell-box.gltf"))));
  RenderSettings settings;
  settings.width = settings.height = 24;
  settings.seed = 3;
  settings.launch_seconds = 1e-3;  // many small ranges, so both workers get some
  DeviceEntry device = pocl_device();
  Film one = Renderer(device, scene, settings).render(0, 40).film;

  DeviceRenderer a(device, *scene, settings), b(device, *scene, settings);
  RenderResult two = render_samples({&a, &b}, 0, 40);
  EXPECT_EQ(two.spp, 40u);
  EXPECT_FALSE(two.partial_pass);
  Film fa = a.film(), fb = b.film();
  EXPECT_GT(fa.samples(0), 0.0f) << "the first worker took no range";
  EXPECT_GT(fb.samples(0), 0.0f) << "the second worker took no range";
  for (size_t i = 0; i < one.pixels(); ++i) {
    ASSERT_EQ(two.film.samples(i), 40.0f) << "pixel " << i;
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(two.film.pixel(i)[c], one.pixel(i)[c], 1e-4f * (1.0f + one.pixel(i)[c])) << "pixel " << i;
      EXPECT_NEAR(two.film.m2[4 * i + c], one.m2[4 * i + c], 1e-3f * (1.0f + one.m2[4 * i + c])) << "pixel " << i;
    }
  }
}

// A time limit with two workers still ends with every pixel sampled at least once
TEST(Scheduler, TimeLimitWithTwoWorkersKeepsWholeRanges) {
  auto scene = std::make_shared<const CompiledScene>(compile_scene(load_gltf(scene_path("cornell-box/cornell-box.gltf"))));
  RenderSettings settings;
  settings.width = settings.height = 16;
  DeviceEntry device = pocl_device();
  DeviceRenderer a(device, *scene, settings), b(device, *scene, settings);
  RenderResult r = render_samples({&a, &b}, 0, 0, 0.3);
  EXPECT_GE(r.spp, 1u);
  for (size_t i = 0; i < r.film.pixels(); ++i) ASSERT_GE(r.film.samples(i), float(r.spp)) << "pixel " << i;
}

}  // namespace candela::test
