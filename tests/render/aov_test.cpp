// The AOVs (cl/integrator/aov.cl, render/aov.hpp) and the transparent background on
// analytic scenes, on PoCL and rusticl: a diffuse quad's albedo is its base colour and its
// normal the plane's, a sphere's depth the ray-sphere distance, a mirror shows the albedo of
// what it reflects; alpha is exactly 1 on an opaque quad and 0 on the background. The beauty
// of the AOV kernel is the default kernel's, bit for bit.
#include <gtest/gtest.h>

#include <cmath>

#include "base/error.hpp"
#include "render/aov.hpp"
#include "render/renderer.hpp"
#include "support/gltf_builder.hpp"
#include "support/scenes.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

using nlohmann::json;

// A glTF material of base colour c, metallic 0, no specular layer: a Lambertian
json diffuse(glm::vec3 c) {
  return {{"pbrMetallicRoughness", {{"baseColorFactor", {c.x, c.y, c.z, 1.0}}, {"metallicFactor", 0.0}}},
          {"extensions", {{"KHR_materials_specular", {{"specularFactor", 0.0}}}}}};
}

// The AOVs of pixel i: albedo rgb, alpha, normal xyz, depth
glm::vec3 albedo(const Film& f, size_t i) { return {f.aov[8 * i], f.aov[8 * i + 1], f.aov[8 * i + 2]}; }
float alpha(const Film& f, size_t i) { return f.aov[8 * i + 3]; }
glm::vec3 normal(const Film& f, size_t i) { return {f.aov[8 * i + 4], f.aov[8 * i + 5], f.aov[8 * i + 6]}; }
float depth(const Film& f, size_t i) { return f.aov[8 * i + 7]; }

constexpr int kSize = 16;
const glm::vec3 kColour(0.2f, 0.5f, 0.8f);

RenderSettings aov_settings() {
  RenderSettings s;
  s.width = s.height = kSize;
  s.aov = true;
  return s;
}

// A quad (default: a Lambertian of kColour) in z = 0 facing +z across [x0, x1] x [-10, 10],
// seen from (0, 0, 3) (yfov 0.5: the view spans |x|, |y| < 3 tan 0.25 there), under a
// uniform background of 1
Scene quad_scene(float x0, float x1, const std::string& file, const json& material = diffuse(kColour)) {
  GltfBuilder g;
  int m = g.add("materials", material);
  g.add_node({{"mesh", g.add_mesh({quad_primitive({{x0, -10, 0}, {x1, -10, 0}, {x1, 10, 0}, {x0, 10, 0}}, m)})}});
  g.add_camera(glm::vec3(0.0f, 0.0f, 3.0f), glm::vec3(0.0f), 0.5f);
  g.set_background(glm::vec3(1.0f));
  return load_scene(g, file);
}

// Pixel i's depth in a view from (0, 0, 3) toward the plane z = 0 (yfov 0.5): the distance
// along the ray through the pixel, 3 / cos of its angle, lies between its values at the
// pixel's corners and centre (it is convex in the film offset)
void expect_plane_depth(const Film& f, size_t i) {
  const float half = 3.0f * std::tan(0.25f);  // of the view at z = 0
  float px = float(i % kSize), py = float(i / kSize), lo = INFINITY, hi = 0.0f;
  for (float dx : {0.0f, 0.5f, 1.0f})
    for (float dy : {0.0f, 0.5f, 1.0f}) {
      float x = (2.0f * (px + dx) / kSize - 1.0f) * half, y = (2.0f * (py + dy) / kSize - 1.0f) * half;
      float d = std::sqrt(9.0f + x * x + y * y);
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
  EXPECT_GE(depth(f, i), lo - 1e-4f) << "pixel " << i;
  EXPECT_LE(depth(f, i), hi + 1e-4f) << "pixel " << i;
}

class Aov : public ::testing::TestWithParam<const char*> {
 protected:
  void SetUp() override { CANDELA_DEVICE_OR_SKIP(GetParam(), device_); }
  std::string file(const std::string& name) const { return "aov-" + name + "-" + GetParam() + ".gltf"; }
  DeviceEntry device_;
};

TEST_P(Aov, DiffuseQuadShowsItsBaseColourNormalAndDepth) {
  Scene s = quad_scene(-10, 10, file("quad"));
  RenderSettings settings = aov_settings();
  Film f = scene_renderer(device_, s, settings).render(0, 16).film;
  ASSERT_EQ(f.aov.size(), f.pixels() * 8);
  for (size_t i = 0; i < f.pixels(); ++i) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(albedo(f, i)[c], kColour[c], 1e-5) << "pixel " << i;
    EXPECT_NEAR(normal(f, i).x, 0.0f, 1e-5);
    EXPECT_NEAR(normal(f, i).y, 0.0f, 1e-5);
    EXPECT_NEAR(normal(f, i).z, 1.0f, 1e-5);
    EXPECT_EQ(alpha(f, i), 1.0f);
    expect_plane_depth(f, i);
  }
  // The beauty is the default kernel's, bit for bit; the kernel of one pixel per work-item
  // computes the same AOVs
  RenderSettings plain = settings;
  plain.aov = false;
  Film g = scene_renderer(device_, s, plain).render(0, 16).film;
  EXPECT_TRUE(g.aov.empty());
  EXPECT_EQ(f.mean, g.mean);
  EXPECT_EQ(f.m2, g.m2);
  settings.packets = false;
  Film h = scene_renderer(device_, s, settings).render(0, 16).film;
  for (size_t k = 0; k < f.aov.size(); ++k) EXPECT_NEAR(h.aov[k], f.aov[k], 1e-5) << "value " << k;
}

TEST_P(Aov, SphereDepthIsTheRaySphereDistance) {
  Scene s = load_scene(sphere_in_view(diffuse(kColour)), file("sphere"));
  Film f = scene_renderer(device_, s, aov_settings()).render(0, 64).film;
  // sphere_in_view's camera: at (0, 0.3, 2) toward the origin, yfov 0.6; radius 0.5
  const glm::vec3 eye(0.0f, 0.3f, 2.0f), forward = glm::normalize(-eye);
  const glm::vec3 right = glm::normalize(glm::cross(forward, glm::vec3(0, 1, 0))), up = glm::cross(right, forward);
  const float t = std::tan(0.3f);
  auto distance = [&](float fx, float fy) {  // along the ray through film position (fx, fy); -1: none
    glm::vec3 d =
        glm::normalize(forward + (2.0f * fx / kSize - 1.0f) * t * right + (1.0f - 2.0f * fy / kSize) * t * up);
    float b = glm::dot(eye, d), c = glm::dot(eye, eye) - 0.25f, disc = b * b - c;
    return disc > 0.0f ? -b - std::sqrt(disc) : -1.0f;
  };
  int checked = 0;
  for (size_t i = 0; i < f.pixels(); ++i) {
    float px = float(i % kSize), py = float(i / kSize), lo = INFINITY, hi = 0.0f;
    for (float dx : {0.0f, 0.5f, 1.0f})
      for (float dy : {0.0f, 0.5f, 1.0f}) {
        float d = distance(px + dx, py + dy);
        lo = std::min(lo, d < 0.0f ? -INFINITY : d);
        hi = std::max(hi, d);
      }
    if (!(lo > 0.0f)) {
      if (hi < 0.0f) {
        EXPECT_EQ(depth(f, i), 0.0f) << "pixel " << i << " sees only the background";
      }
      continue;  // an edge pixel
    }
    // The mesh (3 subdivisions) lies within 0.004 of the sphere
    EXPECT_GE(depth(f, i), lo - 4e-3f) << "pixel " << i;
    EXPECT_LE(depth(f, i), hi + 4e-3f) << "pixel " << i;
    // The shading normal points from the centre to the hit
    glm::vec3 n = normal(f, i);
    EXPECT_NEAR(glm::length(n), 1.0f, 0.02f) << "pixel " << i;
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

TEST_P(Aov, MirrorShowsTheAlbedoOfWhatItReflects) {
  // A mirror in z = 0 facing the camera at (0, 0, 3); behind the camera a quad of kColour
  // facing it, at z = 5, which every reflected ray meets
  GltfBuilder g;
  // (a smooth measured conductor: its kernel builds in a fraction of the glTF mixture's time on
  // rusticl, and a mirror's albedo is what it reflects whatever its reflectance)
  int mirror = g.add("materials", {{"pbrMetallicRoughness", {{"roughnessFactor", 0.0}}},
                                   {"extras", {{"candela", {{"conductor", "silver"}}}}}});
  int wall = g.add("materials", diffuse(kColour));
  g.add_node({{"mesh", g.add_mesh({quad_primitive({{-2, -2, 0}, {2, -2, 0}, {2, 2, 0}, {-2, 2, 0}}, mirror),
                                   quad_primitive({{-10, -10, 5}, {-10, 10, 5}, {10, 10, 5}, {10, -10, 5}}, wall)})}});
  g.add_camera(glm::vec3(0.0f, 0.0f, 3.0f), glm::vec3(0.0f), 0.5f);
  g.set_background(glm::vec3(1.0f));
  Scene s = load_scene(g, file("mirror"));
  Film f = scene_renderer(device_, s, aov_settings()).render(0, 8).film;
  for (size_t i = 0; i < f.pixels(); ++i) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(albedo(f, i)[c], kColour[c], 1e-5) << "pixel " << i;
    EXPECT_NEAR(normal(f, i).z, -1.0f, 1e-5) << "the wall's normal, pixel " << i;
    expect_plane_depth(f, i);  // the camera ray's: the mirror's distance
  }
}

TEST_P(Aov, TransparentBackgroundHasExactAlpha) {
  // The quad covers the view left of the middle of column 8
  const float half = 3.0f * std::tan(0.25f), edge = (2.0f * 8.5f / kSize - 1.0f) * half;
  Scene s = quad_scene(-10, edge, file("half"));
  RenderSettings settings = aov_settings();
  settings.aov = false;
  settings.transparent = true;  // computes the AOVs too
  Film f = scene_renderer(device_, s, settings).render(0, 64).film;
  ASSERT_EQ(f.aov.size(), f.pixels() * 8);
  double lit = 0.0;
  for (size_t i = 0; i < f.pixels(); ++i) {
    size_t x = i % kSize;
    if (x < 8) {
      EXPECT_EQ(alpha(f, i), 1.0f) << "pixel " << i;
      lit += f.pixel(i).y / (8.0 * kSize);
    } else if (x > 8) {
      EXPECT_EQ(alpha(f, i), 0.0f) << "pixel " << i;
      EXPECT_EQ(f.pixel(i), glm::vec3(0.0f)) << "the environment is left out, pixel " << i;
      for (int c = 0; c < 3; ++c) EXPECT_EQ(albedo(f, i)[c], 1.0f) << "the background of 1, pixel " << i;
    } else {
      EXPECT_NEAR(alpha(f, i), 0.5f, 0.1f) << "the edge column, pixel " << i;
    }
  }
  // The environment still lights the quad: a Lambertian under radiance 1 shows its albedo
  EXPECT_NEAR(lit, kColour.y, 0.03);
}

// Films of disjoint sample ranges merge their AOVs by samples taken (kept and dropped)
TEST(AovFilm, MergeWeighsBySamplesTaken) {
  Film a(1, 1), b(1, 1);
  a.mean[3] = 3.0f;  // 3 kept, 1 dropped: 4 taken
  a.m2[3] = 1.0f;
  b.mean[3] = 12.0f;
  a.aov.assign(8, 1.0f);
  b.aov.assign(8, 0.0f);
  b.aov[7] = 6.0f;
  Film m = merge_films(a, b);
  ASSERT_EQ(m.aov.size(), 8u);
  EXPECT_FLOAT_EQ(m.aov[0], 4.0f / 16.0f);
  EXPECT_FLOAT_EQ(m.aov[7], (4.0f + 12.0f * 6.0f) / 16.0f);
  EXPECT_FLOAT_EQ(m.samples_taken(0), 16.0f);
  b.aov.clear();
  EXPECT_TRUE(merge_films(a, b).aov.empty());  // only films that both hold them
}

TEST(AovNames, ListsAndOutputs) {
  EXPECT_EQ(parse_aov_list("albedo,spp"), aov_bit(candela::Aov::Albedo) | aov_bit(candela::Aov::Spp));
  EXPECT_EQ(aov_list_text(parse_aov_list("spp,normal,depth")), "normal,depth,spp");
  EXPECT_EQ(aov_list_text(0), "none");
  EXPECT_THROW(parse_aov_list("albedo,"), Error);
  EXPECT_THROW(parse_aov_list("colour"), Error);
  EXPECT_FALSE(aovs_need_kernel(aov_bit(candela::Aov::Spp)));
  OutputSpec o = parse_output("dir/n.png:normal");
  EXPECT_EQ(o.path, "dir/n.png");
  EXPECT_EQ(o.aov, aov_bit(candela::Aov::Normal));
  EXPECT_EQ(parse_output("a:b/out.png").path, "a:b/out.png");  // a colon in a folder
  EXPECT_EQ(parse_output("out.png").aov, 0u);
  EXPECT_THROW(parse_output("out.png:colour"), Error);
  EXPECT_THROW(parse_output("out.exr:normal"), Error);  // an EXR holds them all
}

// On PoCL only: its kernel (the glTF mixture's glass with AOVs and a transparent background)
// is a cold build of many minutes on rusticl, and the alpha logic it checks is the same code
// that TransparentBackgroundHasExactAlpha runs there
class AovOnPocl : public Aov {};

TEST_P(AovOnPocl, SmoothGlassIsPartlyTransparent) {
  // Thin-walled smooth white glass filling the view: a path reflects (alpha 1, the white
  // background's radiance) or passes straight through to the environment (alpha 0, left
  // out), so alpha is the glass's reflectance and equals the image's value on average
  json glass = {
      {"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 1}}, {"metallicFactor", 0.0}, {"roughnessFactor", 0.0}}},
      {"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}}}}};
  Scene s = quad_scene(-10, 10, file("glass"), glass);
  RenderSettings settings = aov_settings();
  settings.transparent = true;
  Film f = scene_renderer(device_, s, settings).render(0, 64).film;
  double a = 0.0, r = 0.0;
  for (size_t i = 0; i < f.pixels(); ++i) {
    a += alpha(f, i) / double(f.pixels());
    r += f.pixel(i).y / double(f.pixels());
    expect_plane_depth(f, i);
  }
  EXPECT_GT(a, 0.02);  // about 2F / (1 + F), F = 0.04 at normal incidence
  EXPECT_LT(a, 0.15);
  EXPECT_NEAR(r, a, 0.005);
}

INSTANTIATE_TEST_SUITE_P(Devices, Aov, ::testing::Values("pocl", "rusticl"),
                         [](const auto& info) { return std::string(info.param); });
INSTANTIATE_TEST_SUITE_P(Devices, AovOnPocl, ::testing::Values("pocl"),
                         [](const auto& info) { return std::string(info.param); });

}  // namespace
}  // namespace candela::test
