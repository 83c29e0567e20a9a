// The sample scheduler: a scene compiled once, rendered by several device workers that
// take disjoint ranges of sample indices, gives the single-worker image.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "base/error.hpp"
#include "gltf/gltf_loader.hpp"
#include "render/renderer.hpp"
#include "support/test_support.hpp"

namespace candela::test {

// Two workers on PoCL (two contexts, one thread each) against one: the RNG is keyed by
// sample index, so the merged film equals the single one up to the rounding of the merge
TEST(Scheduler, TwoWorkersGiveTheSingleWorkerImage) {
  Scene loaded = load_gltf(scene_path("cornell-box/cornell-box.gltf"));
  auto scene = std::make_shared<const CompiledScene>(compile_scene(loaded));
  RenderSettings settings;
  settings.width = settings.height = 24;
  settings.seed = 3;
  settings.launch_seconds = 1e-3;  // many small ranges, so both workers get some
  DeviceEntry device = pocl_device();
  Film one = Renderer(device, scene, scene_camera(loaded, settings), settings).render(0, 40).film;

  DeviceRenderer a(device, *scene, scene_camera(loaded, settings), settings),
      b(device, *scene, scene_camera(loaded, settings), settings);
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
  Scene loaded = load_gltf(scene_path("cornell-box/cornell-box.gltf"));
  auto scene = std::make_shared<const CompiledScene>(compile_scene(loaded));
  RenderSettings settings;
  settings.width = settings.height = 16;
  DeviceEntry device = pocl_device();
  DeviceRenderer a(device, *scene, scene_camera(loaded, settings), settings),
      b(device, *scene, scene_camera(loaded, settings), settings);
  RenderResult r = render_samples({&a, &b}, 0, 0, 0.3);
  EXPECT_GE(r.spp, 1u);
  for (size_t i = 0; i < r.film.pixels(); ++i) ASSERT_GE(r.film.samples(i), float(r.spp)) << "pixel " << i;
}

// Renderer on a list of devices (the same PoCL device twice: two workers): the image of
// the single-device render, the shares of the samples adding up to all of them, and the
// progress reporting each worker's samples
TEST(Scheduler, RendererOnTwoDevicesReportsEachShare) {
  Scene loaded = load_gltf(scene_path("cornell-box/cornell-box.gltf"));
  auto scene = std::make_shared<const CompiledScene>(compile_scene(loaded));
  RenderSettings settings;
  settings.width = settings.height = 16;
  settings.seed = 5;
  settings.launch_seconds = 1e-3;
  DeviceEntry device = pocl_device();
  Film one = Renderer(device, scene, scene_camera(loaded, settings), settings).render(4, 24).film;

  Renderer two({device, device}, scene, scene_camera(loaded, settings), settings);
  ASSERT_EQ(two.worker_count(), 2u);
  std::vector<double> last;
  RenderResult r = two.render(4, 24, 0.0, [&](const RenderProgress& p) { last = p.worker_spp; });
  EXPECT_EQ(r.spp, 24u);
  ASSERT_EQ(r.worker_samples.size(), 2u);
  EXPECT_GT(r.worker_samples[0], 0u);
  EXPECT_GT(r.worker_samples[1], 0u);
  EXPECT_EQ(r.worker_samples[0] + r.worker_samples[1], uint64_t(24) * 16 * 16);
  ASSERT_EQ(last.size(), 2u);
  EXPECT_DOUBLE_EQ(last[0] + last[1], 24.0);
  for (size_t i = 0; i < one.pixels(); ++i) {
    ASSERT_EQ(r.film.samples(i), 24.0f) << "pixel " << i;
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(r.film.pixel(i)[c], one.pixel(i)[c], 1e-4f * (1.0f + one.pixel(i)[c])) << "pixel " << i;
  }
  EXPECT_THROW(Renderer(std::vector<DeviceEntry>{}, scene, scene_camera(loaded, settings), settings), Error);
}

}  // namespace candela::test
