// Display transforms (host/render/tonemap.*) against values of the published formulas,
// evaluated independently in double precision: Khronos PBR Neutral and AgX (Blender 4's
// base look in its polynomial form).
#include <gtest/gtest.h>

#include "base/error.hpp"
#include "render/tonemap.hpp"

namespace candela::test {
namespace {

void expect_near(glm::vec3 got, glm::vec3 want, float tol, const char* what) {
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], tol) << what << " channel " << k;
}

TEST(Tonemap, PbrNeutralMatchesThePublishedFormula) {
  // Below the compression start only the toe offset applies: 0.5 - 0.04, and near black
  // x - (x - 6.25 x^2) = 6.25 x^2
  expect_near(tonemap_pbr_neutral(glm::vec3(0.0f)), glm::vec3(0.0f), 1e-7f, "black");
  expect_near(tonemap_pbr_neutral(glm::vec3(0.02f)), glm::vec3(0.0025f), 1e-6f, "toe");
  expect_near(tonemap_pbr_neutral(glm::vec3(0.18f)), glm::vec3(0.14f), 1e-6f, "mid grey");
  expect_near(tonemap_pbr_neutral(glm::vec3(0.5f)), glm::vec3(0.46f), 1e-6f, "0.5");
  expect_near(tonemap_pbr_neutral(glm::vec3(1.0f)), glm::vec3(0.8690909f), 1e-5f, "white");
  expect_near(tonemap_pbr_neutral({2.0f, 1.0f, 0.5f}), {0.96f, 0.5340905f, 0.3211358f}, 1e-5f, "orange");
  expect_near(tonemap_pbr_neutral(glm::vec3(100.0f)), glm::vec3(0.9994208f), 1e-5f, "bright");
}

TEST(Tonemap, PbrNeutralIsContinuousAndMonotonic) {
  float previous = 0.0f;
  for (int i = 1; i < 50000; ++i) {
    float x = 0.001f * float(i);
    float y = tonemap_pbr_neutral(glm::vec3(x)).x;
    EXPECT_GE(y, previous - 1e-6f) << "at " << x;  // float rounding aside
    EXPECT_LT(y - previous, 0.01f) << "jump at " << x;
    EXPECT_LE(y, 1.0f);
    previous = y;
  }
}

TEST(Tonemap, AgxMatchesThePublishedFormula) {
  expect_near(tonemap_agx(glm::vec3(0.0f)), glm::vec3(0.0f), 1e-6f, "black");
  expect_near(tonemap_agx(glm::vec3(0.02f)), glm::vec3(0.0182322f), 2e-5f, "dark");
  // Mid grey comes out at display value 0.5 (sRGB-encoded): 0.2145 linear
  expect_near(tonemap_agx(glm::vec3(0.18f)), glm::vec3(0.2145191f), 2e-5f, "mid grey");
  expect_near(tonemap_agx(glm::vec3(1.0f)), glm::vec3(0.5901593f), 2e-5f, "white");
  expect_near(tonemap_agx({2.0f, 1.0f, 0.5f}), {0.765582f, 0.5909173f, 0.4645731f}, 2e-5f, "orange");
  expect_near(tonemap_agx(glm::vec3(100.0f)), glm::vec3(0.9968790f), 2e-5f, "bright");
}

TEST(Tonemap, ClampClipsAndEveryCurveMapsBadValuesToBlack) {
  expect_near(tonemap_apply(Tonemap::Clamp, {0.25f, 1.5f, 0.0f}), {0.25f, 1.0f, 0.0f}, 0.0f, "clamp");
  for (const auto& t : kTonemapNames) {
    expect_near(tonemap_apply(t.value, {NAN, -1.0f, 0.0f}), glm::vec3(0.0f), 1e-6f, t.name);
    EXPECT_EQ(parse_tonemap(t.name), t.value);
    EXPECT_STREQ(tonemap_name(t.value), t.name);
  }
  EXPECT_THROW(parse_tonemap("aces"), Error);
}

}  // namespace
}  // namespace candela::test
