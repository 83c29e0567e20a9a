// The default light's rule (scene/default_light.hpp), the framing camera of scenes without
// one (scene/scene.hpp), and KHR_lights_punctual's photometric units (gltf/lights.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

#include "base/error.hpp"
#include "gltf/gltf_loader.hpp"
#include "scene/default_light.hpp"
#include "support/gltf_builder.hpp"

namespace candela::test {
namespace {

// An axis-aligned quad of `material` spanning [lo, hi] (one coordinate equal), facing `n`
void add_quad(Scene* s, glm::vec3 lo, glm::vec3 hi, glm::vec3 n, uint32_t material) {
  MeshDesc m;
  glm::vec3 a = lo, c = hi, b, d;
  if (lo.y == hi.y) {
    b = {hi.x, lo.y, lo.z};
    d = {lo.x, lo.y, hi.z};
  } else if (lo.z == hi.z) {
    b = {hi.x, lo.y, lo.z};
    d = {lo.x, hi.y, lo.z};
  } else {
    b = {lo.x, hi.y, lo.z};
    d = {lo.x, lo.y, hi.z};
  }
  m.positions = {a, b, c, d};
  glm::vec3 face = glm::cross(b - a, c - a);
  m.indices =
      glm::dot(face, n) > 0.0f ? std::vector<uint32_t>{0, 1, 2, 0, 2, 3} : std::vector<uint32_t>{0, 2, 1, 0, 3, 2};
  m.material = material;
  s->meshes.push_back(m);
}

MaterialDesc emitter(float radiance) {
  MaterialDesc m;
  m.emission = glm::vec3(radiance);
  return m;
}

// A 2 x 2 floor with a square emitter of side `side` and radiance `radiance` at height 1
Scene floor_under_light(float radiance, float side) {
  Scene s;
  s.materials = {MaterialDesc(), emitter(radiance)};
  add_quad(&s, {-1, 0, -1}, {1, 0, 1}, {0, 1, 0}, 0);
  add_quad(&s, {-side / 2, 1, -side / 2}, {side / 2, 1, side / 2}, {0, -1, 0}, 1);
  return s;
}

TEST(DefaultLight, OwnLightShareIsTheIrradianceRatio) {
  // A small emitter right above the floor's centre: at the median floor point (about
  // 0.7 from the centre) the irradiance is L A cos^2 / r^2 ~ L A / 1.5^2 * (1 / 1.5): ~ 0.004 L
  // for A = 0.01, against pi x 1 from an environment of radiance 1
  OwnLight own = own_light_share(floor_under_light(100.0f, 0.1f), 1.0);
  EXPECT_TRUE(own.lights);
  EXPECT_FALSE(own.mostly_emissive);
  EXPECT_GT(own.share, 0.05);
  EXPECT_LT(own.share, 0.3);
  // Ten times the radiance, ten times the share (the same points)
  OwnLight brighter = own_light_share(floor_under_light(1000.0f, 0.1f), 1.0);
  EXPECT_NEAR(brighter.share, 10.0 * own.share, 1e-6 * own.share);
}

TEST(DefaultLight, GlowingMaterialsAreNotLights) {
  // Emission no brighter than white is a glowing material: the studio lights the scene
  Scene glow = floor_under_light(1.0f, 0.5f);
  DefaultLightChoice c = choose_default_light(glow, DefaultLight::Auto, false, 0.5);
  EXPECT_TRUE(c.use_environment);
  EXPECT_FALSE(own_light_share(glow, 0.5).lights);
  // A bright light over the floor lights it: no studio
  DefaultLightChoice lit = choose_default_light(floor_under_light(50.0f, 0.5f), DefaultLight::Auto, false, 0.5);
  EXPECT_FALSE(lit.use_environment) << lit.reason;
  EXPECT_GT(lit.own_share, kOwnLightShareThreshold);
}

TEST(DefaultLight, AssetsMadeOfEmittersGetTheStudio) {
  // The floor is small next to a large bright emitter: the emitters are the asset
  Scene s = floor_under_light(50.0f, 3.0f);
  OwnLight own = own_light_share(s, 0.5);
  EXPECT_TRUE(own.mostly_emissive);
  EXPECT_TRUE(choose_default_light(s, DefaultLight::Auto, false, 0.5).use_environment);
}

TEST(DefaultLight, PunctualLightsCount) {
  Scene s = floor_under_light(0.0f, 0.1f);
  PunctualLightDesc sun;
  sun.type = PunctualType::Directional;
  sun.direction = {0, -1, 0};
  sun.intensity = 3.0f;  // W/m^2: about the studio's pi x 0.5 irradiance
  s.punctual_lights.push_back(sun);
  OwnLight own = own_light_share(s, 0.5);
  EXPECT_NEAR(own.share, 3.0 / (3.14159265 * 0.5), 1e-3);
  EXPECT_FALSE(choose_default_light(s, DefaultLight::Auto, false, 0.5).use_environment);
}

TEST(DefaultLight, ModesAndGivenLighting) {
  Scene dark = floor_under_light(0.0f, 0.1f);  // no light at all
  EXPECT_TRUE(choose_default_light(dark, DefaultLight::Auto, false, 0.5).use_environment);
  EXPECT_FALSE(choose_default_light(dark, DefaultLight::Off, false, 0.5).use_environment);
  EXPECT_FALSE(choose_default_light(dark, DefaultLight::Auto, true, 0.5).use_environment);
  EXPECT_FALSE(choose_default_light(dark, DefaultLight::On, true, 0.5).use_environment);
  Scene lit = floor_under_light(50.0f, 0.5f);
  EXPECT_TRUE(choose_default_light(lit, DefaultLight::On, false, 0.5).use_environment);
}

TEST(DefaultLight, AutomaticExposureBringsBrightOwnLightsToTheStudiosLevel) {
  // The share grows with the emitter's radiance, one to one (no occlusion in it): 64 times
  // the radiance is 6 stops darker, and the exposure is -log2(share) to 0.1 stop
  double base = choose_default_light(floor_under_light(100.0f, 0.1f), DefaultLight::Auto, false, 1.0).own_share;
  ASSERT_GT(base, 0.05);
  ASSERT_LT(base, 0.3);
  EXPECT_FALSE(
      automatic_exposure(choose_default_light(floor_under_light(100.0f, 0.1f), DefaultLight::Auto, false, 1.0)));
  for (float k : {64.0f, 256.0f, 4096.0f}) {
    DefaultLightChoice c = choose_default_light(floor_under_light(100.0f * k, 0.1f), DefaultLight::Auto, false, 1.0);
    EXPECT_NEAR(c.own_share, base * k, 1e-6 * base * k);
    std::optional<float> ev = automatic_exposure(c);
    ASSERT_TRUE(ev) << "share " << c.own_share;
    EXPECT_NEAR(*ev, -std::log2(base * k), 0.05 + 1e-6);
  }
  // Not above 4 times the studio (two stops over): the exposure stays 0
  float at_four = float(100.0 * 3.9 / base);
  EXPECT_FALSE(
      automatic_exposure(choose_default_light(floor_under_light(at_four, 0.1f), DefaultLight::Auto, false, 1.0)));
  // Nor when the scene's own environment, or the studio, lights it
  EXPECT_FALSE(automatic_exposure(choose_default_light(floor_under_light(1e6f, 0.1f), DefaultLight::Auto, true, 1.0)));
  EXPECT_FALSE(automatic_exposure(choose_default_light(floor_under_light(1e6f, 0.1f), DefaultLight::On, false, 1.0)));
}

// The exposure metered from the image: the log-average of its zones' mean luminance (64 x 64
// pixels: zones of 4 x 4) goes to middle grey (0.18), to 0.1 stop; black zones (a black
// background) and those under 1/1000 of the 99th percentile are left out, noise within a zone
// is averaged, a few bright highlights barely move it (they clip), and it is nullopt for a
// black image
TEST(DefaultLight, ImageExposureMapsTheZonesLogAverageToMiddleGrey) {
  const int w = 64, h = 64;
  auto image = [&](const std::function<float(int, int)>& at) {
    std::vector<float> v(size_t(w) * h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) v[size_t(y) * w + size_t(x)] = at(x, y);
    return v;
  };
  std::vector<float> grey = image([](int, int) { return 0.045f; });  // two stops under middle grey
  ASSERT_TRUE(image_exposure(grey, w, h));
  EXPECT_FLOAT_EQ(*image_exposure(grey, w, h), 2.0f);
  // Three quarters of the frame a black background, a pitch-black shadow, a non-finite pixel
  std::vector<float> quadrant = image([](int x, int y) { return x < 32 && y < 32 ? 0.045f : 0.0f; });
  quadrant[size_t(63) * w + 63] = 1e-7f;
  quadrant[0] = std::nanf("");
  EXPECT_FLOAT_EQ(*image_exposure(quadrant, w, h), 2.0f);
  // Noise: one pixel in 16 at 16 x 0.045, the others black, meters as 0.045 does
  std::vector<float> sparse = image([](int x, int y) { return x % 4 == 1 && y % 4 == 2 ? 16.0f * 0.045f : 0.0f; });
  EXPECT_FLOAT_EQ(*image_exposure(sparse, w, h), 2.0f);
  // Zones alternately 4x brighter and 4x darker than 0.72: the log-average is 0.72, -2 stops
  std::vector<float> checker = image([](int x, int y) { return (x / 4 + y / 4) % 2 ? 0.72f * 4.0f : 0.72f / 4.0f; });
  EXPECT_FLOAT_EQ(*image_exposure(checker, w, h), -2.0f);
  // Five emitters seen at radiance 1000 in one zone: under 0.1 stop darker
  std::vector<float> highlights = grey;
  for (int k = 0; k < 5; ++k) highlights[size_t(k)] = 1000.0f;
  EXPECT_GE(*image_exposure(highlights, w, h), 1.9f);
  EXPECT_FALSE(image_exposure(std::vector<float>(size_t(w) * h, 0.0f), w, h));
  EXPECT_FALSE(image_exposure({}, 0, 0));
  // Within [-20, 20] stops
  EXPECT_FLOAT_EQ(*image_exposure(std::vector<float>(size_t(w) * h, 1e12f), w, h), -20.0f);
}

// Where the eight corners of b project in the camera's image (x right, y up, in units of
// the half-extent of the view: inside the frame is |x|, |y| <= 1)
std::vector<glm::vec2> projected_corners(const CameraDesc& cam, const Bounds& b, float aspect) {
  glm::vec3 f = glm::normalize(cam.forward), r = glm::normalize(glm::cross(f, cam.up)), u = glm::cross(r, f);
  float ty = std::tan(0.5f * cam.yfov), tx = ty * aspect;
  std::vector<glm::vec2> out;
  for (int i = 0; i < 8; ++i) {
    glm::vec3 p(i & 1 ? b.hi.x : b.lo.x, i & 2 ? b.hi.y : b.lo.y, i & 4 ? b.hi.z : b.lo.z);
    glm::vec3 q = p - cam.position;
    float z = glm::dot(q, f);
    EXPECT_GT(z, 0.0f) << "corner " << i << " behind the camera";
    out.push_back({glm::dot(q, r) / (z * tx), glm::dot(q, u) / (z * ty)});
  }
  return out;
}

TEST(Framing, ThreeQuarterViewFillsTheFrameWithTheBounds) {
  for (float aspect : {1.0f, 2.0f, 0.5f}) {
    // A cube: seen from above and from the side, never face-on, and filling the frame
    Scene cube;
    cube.materials = {MaterialDesc()};
    add_quad(&cube, {-1, 0, -1}, {1, 0, 1}, {0, 1, 0}, 0);
    add_quad(&cube, {-1, 2, -1}, {1, 2, 1}, {0, 1, 0}, 0);
    CameraDesc cam = framing_camera(cube, aspect);
    glm::vec3 back = -glm::normalize(cam.forward);
    EXPECT_NEAR(std::asin(back.y) * 180.0 / 3.14159265, 20.0, 0.01);
    EXPECT_NEAR(std::atan2(back.x, back.z) * 180.0 / 3.14159265, 30.0, 0.01);
    float widest = 0.0f;
    for (glm::vec2 p : projected_corners(cam, cube.bounds(), aspect)) {
      EXPECT_LE(std::fabs(p.x), 0.951f);
      EXPECT_LE(std::fabs(p.y), 0.951f);
      widest = std::max({widest, std::fabs(p.x), std::fabs(p.y)});
    }
    EXPECT_GT(widest, 0.94f) << "the bounds should touch the margin";
  }
}

TEST(Framing, FlatScenesAreSeenFromHigherUp) {
  Scene plane;
  plane.materials = {MaterialDesc()};
  add_quad(&plane, {-5, 0, -5}, {5, 0, 5}, {0, 1, 0}, 0);
  CameraDesc cam = framing_camera(plane);
  EXPECT_NEAR(std::asin(-glm::normalize(cam.forward).y) * 180.0 / 3.14159265, 50.0, 0.01);
  for (glm::vec2 p : projected_corners(cam, plane.bounds(), 1.0f)) EXPECT_LE(std::fabs(p.y), 0.951f);
}

// A tetrahedron (not planar) with its base corner at `lo` and sides `size`
void add_tetrahedron(Scene* s, glm::vec3 lo, float size) {
  MeshDesc m;
  m.positions = {lo, lo + glm::vec3(size, 0, 0), lo + glm::vec3(0, size, 0), lo + glm::vec3(0, 0, size)};
  m.indices = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  s->meshes.push_back(m);
}

TEST(Framing, AnAssetOnAVastFloorFillsTheFrame) {
  // A 1-unit asset on a 100-unit ground plane: framed on the asset, the floor left out
  Scene scene;
  scene.materials = {MaterialDesc()};
  add_quad(&scene, {-50, 0, -50}, {50, 0, 50}, {0, 1, 0}, 0);
  add_tetrahedron(&scene, {0, 0, 0}, 1.0f);
  add_quad(&scene, {-1, 0, -1}, {0, 0, 0}, {0, 1, 0}, 0);  // a small flat part of the asset stays in
  size_t backdrops = 0;
  Bounds framed = framing_bounds(scene, &backdrops);
  EXPECT_EQ(backdrops, 1u);
  EXPECT_EQ(framed.lo, glm::vec3(-1, 0, -1));
  EXPECT_EQ(framed.hi, glm::vec3(1, 1, 1));
  CameraDesc cam = framing_camera(scene);
  float widest = 0.0f;
  for (glm::vec2 p : projected_corners(cam, framed, 1.0f)) widest = std::max({widest, std::fabs(p.x), std::fabs(p.y)});
  EXPECT_GT(widest, 0.94f) << "the asset should fill the frame";
  EXPECT_NEAR(std::asin(-glm::normalize(cam.forward).y) * 180.0 / 3.14159265, 20.0, 0.01) << "the asset is not flat";

  // A floor only 3 times the asset's size is part of the scene; so is a plane without a solid beside it
  Scene small_floor;
  small_floor.materials = {MaterialDesc()};
  add_quad(&small_floor, {-1.5f, 0, -1.5f}, {1.5f, 0, 1.5f}, {0, 1, 0}, 0);
  add_tetrahedron(&small_floor, {0, 0, 0}, 1.0f);
  EXPECT_EQ(framing_bounds(small_floor, &backdrops).lo, glm::vec3(-1.5f, 0, -1.5f));
  EXPECT_EQ(backdrops, 0u);
  Scene planes;
  planes.materials = {MaterialDesc()};
  add_quad(&planes, {-50, 0, -50}, {50, 0, 50}, {0, 1, 0}, 0);
  add_quad(&planes, {0, 0, 0}, {1, 0, 1}, {0, 1, 0}, 0);
  EXPECT_EQ(framing_bounds(planes, &backdrops).lo, glm::vec3(-50, 0, -50));
  EXPECT_EQ(backdrops, 0u);
  // Nor is a large flat panel above a small solid part: across its plane it does not span it
  Scene panel;
  panel.materials = {MaterialDesc()};
  add_quad(&panel, {2, 5, -10}, {2, 25, 10}, {1, 0, 0}, 0);
  add_tetrahedron(&panel, {0, 0, 0}, 1.0f);
  EXPECT_EQ(framing_bounds(panel, &backdrops).hi, glm::vec3(2, 25, 10));
  EXPECT_EQ(backdrops, 0u);
  // A wall behind it, spanning it, is a backdrop
  Scene wall;
  wall.materials = {MaterialDesc()};
  add_quad(&wall, {2, -1, -10}, {2, 19, 10}, {1, 0, 0}, 0);
  add_tetrahedron(&wall, {0, 0, 0}, 1.0f);
  EXPECT_EQ(framing_bounds(wall, &backdrops).hi, glm::vec3(1, 1, 1));
  EXPECT_EQ(backdrops, 1u);
}

// A glTF with one point light of `intensity` and, optionally, scene extras light_units
std::string point_light_gltf(double intensity, const char* units) {
  GltfBuilder g;
  float quad[4][3] = {{-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}};
  g.add_node({{"mesh", g.add_mesh({quad_primitive(quad, -1)})}});
  g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  g.doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}, {"intensity", intensity}}};
  g.add_node({{"translation", {0, 1, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  if (units) g.doc["scenes"][0]["extras"]["candela"]["light_units"] = units;
  return g.document().dump();
}

TEST(LightUnits, CandelaAndLuxAreReadBy683LumensPerWatt) {
  Scene photometric = load_gltf_from_memory(point_light_gltf(683.0 * 2.5, nullptr), "");
  ASSERT_EQ(photometric.punctual_lights.size(), 1u);
  EXPECT_EQ(photometric.light_units, LightUnits::Photometric);
  EXPECT_EQ(photometric.punctual_lights[0].intensity, 2.5f);  // exact: the division is in double
  Scene radiometric = load_gltf_from_memory(point_light_gltf(2.5, "radiometric"), "");
  EXPECT_EQ(radiometric.punctual_lights[0].intensity, 2.5f);
  // The command line's choice wins over the scene's
  LoadOptions options;
  options.light_units = LightUnits::Photometric;
  Scene overridden = load_gltf_from_memory(point_light_gltf(683.0, "radiometric"), "", options);
  EXPECT_EQ(overridden.punctual_lights[0].intensity, 1.0f);
  EXPECT_THROW(load_gltf_from_memory(point_light_gltf(1.0, "watts"), ""), Error);
}

}  // namespace
}  // namespace candela::test
