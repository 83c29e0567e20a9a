// A thin film (KHR_materials_iridescence) over glass whose index matches the air (ior 1), on
// PoCL and rusticl: the bare interface reflects nothing, the film (index 2, 300 nm) is a blue
// mirror (Airy: 0.30 at 450 nm, 0.14 at 550 nm, 0 at 600 nm at normal incidence). A nearly
// black tinted lens (sunglasses) under a white background shows the film's reflection, blue
// over red and green; a clear one is invisible in the furnace (what the film does not reflect
// it transmits).
#include <gtest/gtest.h>

#include "render/renderer.hpp"
#include "support/gltf_builder.hpp"
#include "support/scenes.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

using nlohmann::json;

// Transmission 1 over a base of ior 1, smooth, under a film of index 2 and 300 nm; thin-walled
// unless `volume`
json film_lens(double tint, bool volume) {
  json ext = {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
              {"KHR_materials_ior", {{"ior", 1.0}}},
              {"KHR_materials_iridescence",
               {{"iridescenceFactor", 1.0},
                {"iridescenceIor", 2.0},
                {"iridescenceThicknessMinimum", 300.0},
                {"iridescenceThicknessMaximum", 300.0}}}};
  if (volume) ext["KHR_materials_volume"] = {{"thicknessFactor", 1.0}};
  return {{"pbrMetallicRoughness",
           {{"baseColorFactor", {tint, tint, tint, 1.0}}, {"metallicFactor", 0.0}, {"roughnessFactor", 0.0}}},
          {"extensions", ext}};
}

class IridescentLens : public ::testing::TestWithParam<const char*> {};

// The sphere (radius 0.5, seen from 2 with a field of view of 0.6) covers the central 8 x 8
// pixels of a 16 x 16 image
TEST_P(IridescentLens, ReflectsBlueOverAnIndexMatchedBase) {
  DeviceEntry device;
  CANDELA_DEVICE_OR_SKIP(GetParam(), device);
  Scene s = load_scene(furnace_sphere(film_lens(0.009, false)), std::string("film-lens-") + GetParam() + ".gltf");
  EXPECT_TRUE(s.features().iridescence);
  Film f = render_film(s, Strategy::Nee, 16, 16, 64, 16, 3, device);
  Estimate r = region_mean(f, 0, 4, 12, 4, 12), g = region_mean(f, 1, 4, 12, 4, 12),
           b = region_mean(f, 2, 4, 12, 4, 12);
  std::printf("sphere's mean under a white background: %.4f %.4f %.4f\n", r.mean, g.mean, b.mean);
  // Without the film the lens passes 0.009^2 of the background: black
  EXPECT_GT(b.mean, 0.15) << "the film reflects";
  EXPECT_GT(b.mean, 1.5 * r.mean) << "a blue mirror";
  EXPECT_GT(b.mean, g.mean);
  EXPECT_EQ(f.dropped_samples(), 0u);
}

// A clear (white) lens with a volume: each crossing reflects the film's F and transmits 1 - F,
// so the sphere keeps the furnace's light, channel by channel (within the noise of choosing
// reflection by the channels' mean: weights F / mean(F) and (1 - F) / (1 - mean(F)))
TEST_P(IridescentLens, ClearLensConservesEnergyInTheFurnace) {
  DeviceEntry device;
  CANDELA_DEVICE_OR_SKIP(GetParam(), device);
  Scene s = load_scene(furnace_sphere(film_lens(1.0, true)), std::string("film-clear-") + GetParam() + ".gltf");
  Film f = render_film(s, Strategy::Bsdf, 16, 16, 256, 1000, 5, device);
  for (int c = 0; c < 3; ++c) {
    Estimate e = region_mean(f, c, 0, 16, 0, 16);
    EXPECT_LT(e.standard_error, 0.005) << "too noisy to test anything";
    EXPECT_NEAR(e.mean, 1.0, 4.0 * e.standard_error + 1e-5) << "channel " << c << ", SE " << e.standard_error;
  }
  EXPECT_EQ(f.dropped_samples(), 0u);
}

INSTANTIATE_TEST_SUITE_P(Devices, IridescentLens, ::testing::Values("pocl", "rusticl"),
                         [](const auto& info) { return std::string(info.param); });

}  // namespace
}  // namespace candela::test
