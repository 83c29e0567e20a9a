// Whole renders with known answers, checked within measured standard errors, on PoCL
// and (when installed) on Mesa's rusticl.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstdio>

#include "base/error.hpp"
#include "gltf/gltf_loader.hpp"
#include "render/renderer.hpp"
#include "support/scenes.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

RenderResult render_scene(const DeviceEntry& device, const std::string& scene_file, Strategy s, int size, uint32_t spp,
                          uint32_t max_depth = 1000, uint32_t seed = 1) {
  Scene scene = load_gltf(scene_path(scene_file));
  RenderSettings settings;
  settings.width = settings.height = size;
  settings.strategy = s;
  settings.max_depth = max_depth;
  settings.seed = seed;
  return render_result(scene, settings, spp, device);
}

using DeviceStrategy = std::tuple<std::string, Strategy>;

class FurnaceTest : public ::testing::TestWithParam<DeviceStrategy> {};

// The image averages to radiance 1 within 4 standard errors, which are small enough to matter
void expect_unit_radiance(const RenderResult& r, Strategy s) {
  Estimate e = image_mean(r.film);
  EXPECT_LT(e.standard_error, 0.01) << "too noisy to test anything";
  // (plus float rounding: albedo-1 paths have no variance left to hide it)
  EXPECT_NEAR(e.mean, 1.0, 4.0 * e.standard_error + 1e-6) << strategy_name(s) << " SE " << e.standard_error;
  EXPECT_EQ(r.film.dropped_samples(), 0u);
}

}  // namespace

// Camera inside a closed sphere of albedo a = 0.5 emitting Le = 0.5: L = Le / (1 - a) = 1
TEST_P(FurnaceTest, ClosedEmissiveSphereGivesLeOverOneMinusAlbedo) {
  DeviceEntry device;
  CANDELA_DEVICE_OR_SKIP(std::get<0>(GetParam()), device);
  Strategy s = std::get<1>(GetParam());
  expect_unit_radiance(render_scene(device, "furnace/closed-sphere.gltf", s, 24, 256), s);
}

// Objects of albedo 1 under a constant background of 1 are invisible: L = 1 everywhere
TEST_P(FurnaceTest, WhiteObjectsUnderWhiteBackgroundAreInvisible) {
  DeviceEntry device;
  CANDELA_DEVICE_OR_SKIP(std::get<0>(GetParam()), device);
  Strategy s = std::get<1>(GetParam());
  RenderResult r = render_scene(device, "furnace/white-objects.gltf", s, 24, 128);
  expect_unit_radiance(r, s);
  // And pixel by pixel, over 4x4 blocks
  for (int by = 0; by < 24; by += 4)
    for (int bx = 0; bx < 24; bx += 4) {
      Estimate b = region_mean(r.film, 1, bx, bx + 4, by, by + 4);
      EXPECT_NEAR(b.mean, 1.0, 5.0 * b.standard_error + 1e-5) << "block " << bx << "," << by;
    }
}

INSTANTIATE_TEST_SUITE_P(Devices, FurnaceTest,
                         ::testing::Combine(kernel_devices(), ::testing::Values(Strategy::Nee, Strategy::Bsdf)),
                         [](const auto& info) {
                           return std::get<0>(info.param) + "_" + strategy_name(std::get<1>(info.param));
                         });

class CornellTest : public ::testing::TestWithParam<std::string> {};

// Next-event estimation and BSDF sampling estimate the same image: compare 8x8 blocks
TEST_P(CornellTest, StrategiesAgreeWithinStandardError) {
  DeviceEntry device;
  CANDELA_DEVICE_OR_SKIP(GetParam(), device);
  const int size = 32;
  RenderResult nee = render_scene(device, "cornell-box/cornell-box.gltf", Strategy::Nee, size, 128, 8);
  RenderResult bsdf = render_scene(device, "cornell-box/cornell-box.gltf", Strategy::Bsdf, size, 512, 8, 2);
  double max_z = 0.0;
  double chi2 = 0.0;
  int blocks = 0;
  for (int by = 0; by < size; by += 8)
    for (int bx = 0; bx < size; bx += 8)
      for (int c = 0; c < 3; ++c) {
        Estimate a = region_mean(nee.film, c, bx, bx + 8, by, by + 8);
        Estimate b = region_mean(bsdf.film, c, bx, bx + 8, by, by + 8);
        double se = std::sqrt(a.standard_error * a.standard_error + b.standard_error * b.standard_error);
        double z = (a.mean - b.mean) / se;
        max_z = std::max(max_z, std::fabs(z));
        chi2 += z * z;
        ++blocks;
        EXPECT_LT(std::fabs(z), 4.5) << "block " << bx << "," << by << " channel " << c << ": nee " << a.mean
                                     << " bsdf " << b.mean << " se " << se;
      }
  // The sum of squared z-scores is chi-square with `blocks` dof: mean 48, sd ~10
  EXPECT_LT(chi2, blocks + 5.0 * std::sqrt(2.0 * blocks)) << "max |z| " << max_z;
  Estimate whole_nee = image_mean(nee.film), whole_bsdf = image_mean(bsdf.film);
  EXPECT_GT(whole_nee.mean, 0.05) << "the Cornell box must not be black";
  EXPECT_LT(whole_nee.standard_error, 0.02 * whole_nee.mean);
  EXPECT_LT(whole_bsdf.standard_error, 0.05 * whole_bsdf.mean);
}

INSTANTIATE_TEST_SUITE_P(Devices, CornellTest, kernel_devices(), DeviceParamName());

// A small light hovering just above a floor near the origin: shadow rays toward it must
// not hit the light itself, so NEE and BSDF sampling agree there too
TEST(Render, StrategiesAgreeForALightCloseToASurface) {
  GltfBuilder g = floor_under_square_light(0.01f, 0.05f, 5);
  g.add_camera({0.0f, 0.25f, 0.3f}, {0, 0, 0}, 0.5f);
  Scene scene = load_scene(g, "near-light.gltf");
  RenderSettings settings;
  settings.width = settings.height = 16;
  settings.max_depth = 4;
  Renderer nee = scene_renderer(pocl_device(), scene, settings);
  settings.strategy = Strategy::Bsdf;
  settings.seed = 5;
  Renderer bsdf = scene_renderer(pocl_device(), scene, settings);
  Film a = nee.render(0, 64).film, b = bsdf.render(0, 256).film;
  Estimate ea = image_mean(a), eb = image_mean(b);
  double se = std::sqrt(ea.standard_error * ea.standard_error + eb.standard_error * eb.standard_error);
  EXPECT_GT(ea.mean, 0.01);
  EXPECT_NEAR(ea.mean, eb.mean, 4.0 * se) << "nee " << ea.mean << " bsdf " << eb.mean;
}

// An emissive texture (bright left half, black right half) on a light above a floor:
// light sampling must look up the texture where it samples, so NEE and BSDF sampling
// agree block by block (a mirrored lookup would light the wrong side of the floor)
TEST(Render, EmissiveTextureIsSampledWhereTheLightIsSampled) {
  std::string dir = ::testing::TempDir();
  unsigned char px[6] = {255, 255, 255, 0, 0, 0};
  auto out = OIIO::ImageOutput::create(dir + "emit.png");
  ASSERT_TRUE(out && out->open(dir + "emit.png", OIIO::ImageSpec(2, 1, 3, OIIO::TypeDesc::UINT8)));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, px));
  out->close();
  GltfBuilder g = floor_under_square_light(0.3f, 0.25f, 4);
  g.doc["materials"][1]["emissiveTexture"] = {{"index", 0}};
  g.add("images", {{"uri", "emit.png"}});
  g.add("samplers", {{"magFilter", 9729}, {"wrapS", 33071}, {"wrapT", 33071}});
  g.add("textures", {{"source", 0}, {"sampler", 0}});
  g.add_camera({0.0f, 1.2f, 0.01f}, {0, 0, 0}, 1.2f);
  Scene scene = load_scene(g, "emissive-texture.gltf");
  ASSERT_NE(scene.materials[1].texture(TEX_EMISSION).index, NO_TEXTURE);
  RenderSettings settings;
  settings.width = settings.height = 16;
  settings.max_depth = 2;
  Film nee = scene_renderer(pocl_device(), scene, settings).render(0, 128).film;
  settings.strategy = Strategy::Bsdf;
  settings.seed = 9;
  Film bsdf = scene_renderer(pocl_device(), scene, settings).render(0, 1024).film;
  double left = 0.0, right = 0.0;
  for (int by = 0; by < 16; by += 4)
    for (int bx = 0; bx < 16; bx += 4) {
      Estimate a = region_mean(nee, 1, bx, bx + 4, by, by + 4);
      Estimate b = region_mean(bsdf, 1, bx, bx + 4, by, by + 4);
      double se = std::sqrt(a.standard_error * a.standard_error + b.standard_error * b.standard_error);
      EXPECT_NEAR(a.mean, b.mean, 4.5 * se + 1e-6) << "block " << bx << "," << by;
      (bx < 8 ? left : right) += a.mean;
    }
  // The camera looks down with +x to the right: the lit half of the floor differs from the dark
  EXPECT_GT(std::fabs(left - right), 0.2 * (left + right)) << "left " << left << " right " << right;
}

// A time limit shorter than one pass still completes the first pass, so there is always
// an image with every pixel sampled
TEST(Render, TimeLimitShorterThanOnePassStillRendersOneSample) {
  Scene scene = load_gltf(scene_path("cornell-box/cornell-box.gltf"));
  RenderSettings settings;
  settings.width = settings.height = 32;
  settings.launch_seconds = 1e-9;  // one work-group's pixels per launch
  RenderResult r = scene_renderer(pocl_device(), scene, settings).render(0, 0, 1e-9);
  EXPECT_EQ(r.spp, 1u);
  EXPECT_FALSE(r.partial_pass);
  for (size_t i = 0; i < r.film.pixels(); ++i) ASSERT_EQ(r.film.samples(i), 1.0f) << "pixel " << i;
}

// A scene too large for the device's biggest buffer fails with a message naming the
// buffer and both sizes, before anything is launched
TEST(Render, BufferLargerThanTheDeviceAllowsIsAClearError) {
  DeviceEntry device = pocl_device();
  device.max_alloc = 1024;  // pretend the device takes at most 1 KiB per buffer
  Scene scene = load_gltf(scene_path("furnace/closed-sphere.gltf"));
  RenderSettings settings;
  settings.width = settings.height = 8;
  try {
    Renderer r = scene_renderer(device, scene, settings);
    FAIL() << "no error";
  } catch (const Error& e) {
    std::string msg = e.what();
    EXPECT_NE(msg.find("MiB"), std::string::npos) << msg;
    EXPECT_NE(msg.find("allows"), std::string::npos) << msg;
  }
}

// On CPU devices the camera rays go in packets of eight (CD_PACKETS); every sample is the
// one-pixel-per-work-item kernel's, but for a pixel whose camera ray meets two triangles
// within rounding of one distance (the packet may test them in another order). An odd size
// leaves partial packets; the materials scene has textures and alpha-tested cut-outs, the
// cloud a medium. The packets draw the film positions' numbers and a pinhole camera's ray
// directions in SIMD lanes; the tent and Gaussian filters map the numbers lane by lane, a
// lens or an orthographic camera makes its rays lane by lane, the independent sampler
// draws lane by lane: the Cornell box is rendered with each of those too.
TEST(Packets, SameSamplesAsOnePixelPerWorkItem) {
  DeviceEntry device = pocl_device();
  enum Variant { kDefault, kTent, kGaussian, kThinLens, kOrthographic, kIndependent };
  struct Case {
    const char* name;
    Variant variant;
  };
  for (Case c :
       {Case{"cornell-box/cornell-box.gltf", kDefault}, Case{"materials/materials.gltf", kDefault},
        Case{"volumes/cloud.gltf", kDefault}, Case{"cornell-box/cornell-box.gltf", kTent},
        Case{"cornell-box/cornell-box.gltf", kGaussian}, Case{"cornell-box/cornell-box.gltf", kThinLens},
        Case{"cornell-box/cornell-box.gltf", kOrthographic}, Case{"cornell-box/cornell-box.gltf", kIndependent}}) {
    const char* name = c.name;
    Scene scene = load_gltf(scene_path(name));
    RenderSettings settings;
    settings.width = 37;
    settings.height = 23;
    settings.seed = 7;
    if (c.variant == kTent) settings.filter = PixelFilter::Tent;
    if (c.variant == kGaussian) settings.filter = PixelFilter::Gaussian;
    if (c.variant == kIndependent) settings.sampler = Sampler::Independent;
    if (c.variant == kThinLens || c.variant == kOrthographic) {
      ASSERT_TRUE(scene.camera.has_value()) << name;
      if (c.variant == kThinLens) scene.camera->aperture_radius = 0.05f;
      if (c.variant == kOrthographic) scene.camera->projection = Projection::Orthographic;
    }
    settings.launch_seconds = 1e-3;  // several launches; the 851 pixels end in a partial packet
    Film packets = scene_renderer(device, scene, settings).render(0, 3).film;
    settings.packets = false;
    Film single = scene_renderer(device, scene, settings).render(0, 3).film;
    ASSERT_EQ(packets.mean.size(), single.mean.size());
    size_t differ = 0, pixels = packets.mean.size() / 4;
    for (size_t i = 0; i < pixels; ++i) {
      bool same = true;
      for (int ch = 0; ch < 4; ++ch) same = same && packets.mean[4 * i + ch] == single.mean[4 * i + ch];
      differ += !same;
    }
    std::printf("%s (variant %d): %zu of %zu pixels differ with packets\n", name, int(c.variant), differ, pixels);
    EXPECT_LE(differ, pixels / 200) << name << " (variant " << int(c.variant) << "): pixels whose samples differ";
    double sum = 0.0;
    for (size_t i = 0; i < pixels; ++i) sum += packets.mean[4 * i];
    EXPECT_GT(sum, 0.0) << name << " (variant " << int(c.variant) << "): a black image";
  }
}

// The CLI's renderer frees the compiled scene's host arrays as it uploads them, and a CPU
// device takes the BVH's arrays over as its buffers instead of copying them: the same image
// as a renderer that copies every array (as library users' renderers do)
TEST(Render, ReleasedHostArraysGiveTheSameImage) {
  DeviceEntry device = pocl_device();
  for (const char* name : {"cornell-box/cornell-box.gltf", "materials/materials.gltf"}) {
    Scene loaded = load_gltf(scene_path(name));
    RenderSettings settings;
    settings.width = 40;
    settings.height = 30;
    settings.seed = 3;
    auto kept = std::make_shared<const CompiledScene>(compile_scene(loaded));
    auto released = std::make_shared<CompiledScene>(compile_scene(loaded));
    Renderer copying({device}, kept, scene_camera(loaded, settings), settings);
    Renderer adopting({device}, released, scene_camera(loaded, settings), settings, true);
    EXPECT_EQ(copying.worker().adopted_buffers(), 0u) << name;
    EXPECT_EQ(adopting.worker().adopted_buffers(), 2u) << name << ": the BVH's nodes and triangles";
    EXPECT_TRUE(released->buffers.bvh_nodes.empty() && released->buffers.bvh_tris.empty()) << name;
    EXPECT_FALSE(kept->buffers.bvh_nodes.empty()) << name;
    Film a = copying.render(0, 4).film, b = adopting.render(0, 4).film;
    EXPECT_EQ(a.mean, b.mean) << name;
    EXPECT_EQ(a.m2, b.m2) << name;
    double sum = 0.0;
    for (size_t i = 0; i < b.mean.size(); i += 4) sum += b.mean[i];
    EXPECT_GT(sum, 0.0) << name << ": a black image";
  }
}

TEST(Determinism, SameSeedSameImageWhateverTheLaunchSplit) {
  DeviceEntry device = pocl_device();
  Scene scene = load_gltf(scene_path("cornell-box/cornell-box.gltf"));
  RenderSettings settings;
  settings.width = settings.height = 24;
  settings.seed = 42;
  Renderer one = scene_renderer(device, scene, settings);
  Film a = one.render(0, 12).film;
  Renderer two = scene_renderer(device, scene, settings);
  two.render(0, 5);
  two.render(5, 4);
  Film b = two.render(9, 3).film;
  EXPECT_EQ(a.mean, b.mean);
  EXPECT_EQ(a.m2, b.m2);

  // Tiny launches: every launch covers one work-group of pixels and one sample
  RenderSettings tiny = settings;
  tiny.launch_seconds = 1e-9;
  Film d = scene_renderer(device, scene, tiny).render(0, 12).film;
  EXPECT_EQ(a.mean, d.mean);
  EXPECT_EQ(a.m2, d.m2);

  settings.seed = 43;
  Renderer other = scene_renderer(device, scene, settings);
  Film c = other.render(0, 12).film;
  EXPECT_NE(a.mean, c.mean) << "a different seed must give a different image";
}

TEST(Determinism, FilmsOfDisjointSampleRangesMergeToTheWholeRender) {
  DeviceEntry device = pocl_device();
  Scene scene = load_gltf(scene_path("cornell-box/cornell-box.gltf"));
  RenderSettings settings;
  settings.width = settings.height = 16;
  Film whole = scene_renderer(device, scene, settings).render(0, 16).film;
  Film first = scene_renderer(device, scene, settings).render(0, 6).film;
  Film second = scene_renderer(device, scene, settings).render(6, 10).film;
  Film merged = merge_films(first, second);
  for (size_t i = 0; i < whole.mean.size(); ++i) {
    EXPECT_NEAR(merged.mean[i], whole.mean[i], 1e-4f * (1.0f + std::fabs(whole.mean[i])));
    EXPECT_NEAR(merged.m2[i], whole.m2[i], 1e-3f * (1.0f + std::fabs(whole.m2[i])));
  }
}

TEST(Render, DirectLightingOnlyAtMaxDepthOneIsDarkerThanFullTransport) {
  DeviceEntry device = pocl_device();
  Estimate direct = image_mean(render_scene(device, "cornell-box/cornell-box.gltf", Strategy::Nee, 16, 64, 1).film);
  Estimate full = image_mean(render_scene(device, "cornell-box/cornell-box.gltf", Strategy::Nee, 16, 64, 16).film);
  Estimate emitted = image_mean(render_scene(device, "cornell-box/cornell-box.gltf", Strategy::Nee, 16, 4, 0).film);
  EXPECT_LT(emitted.mean, direct.mean);
  EXPECT_LT(direct.mean + 5 * direct.standard_error, full.mean);
}

}  // namespace candela::test
