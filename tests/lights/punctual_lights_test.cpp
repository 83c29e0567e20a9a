// KHR_lights_punctual: point, spot and directional lights.
//  - Renders (the real render path, max depth 1) of a Lambertian plane under one light
//    against closed forms: a I cos / (pi r^2) for a point light, the extension's spot cone
//    and range window, a E cos / pi and a hard shadow for a directional light. Each pixel's
//    expected value is the box filter's mean over the pixel (a fine midpoint rule on the
//    host), checked within 5 measured standard errors (the jitter's noise) plus float
//    rounding.
//  - lights_sample on delta lights (is_delta, pdf = pmf, lights_pdf = 0, the incident
//    quantity) through tests/lights/test_lights.cl; light powers against numerical integrals.
//  - The loader: positions, directions, units, cones, node transforms, malformed lights.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <glm/gtc/quaternion.hpp>

#include "base/error.hpp"
#include "compile/scene_compiler.hpp"
#include "gltf/gltf_loader.hpp"
#include "render/renderer.hpp"
#include "support/reference.hpp"
#include "support/scenes.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

using nlohmann::json;

// ---------------------------------------------------------------------------------------
// Closed forms (double precision, from the extension's text)

// The recommended range window: clamp(1 - (d / range)^4, 0, 1); range 0 = infinite
double range_window(double range, double d) {
  if (range <= 0.0) return 1.0;
  return std::clamp(1.0 - std::pow(d / range, 4.0), 0.0, 1.0);
}

// The spot profile at angle `angle` from the axis: t^2, t linear in the cosine from
// cos(outer) (0) to cos(inner) (1)
double spot_profile(double inner, double outer, double angle) {
  double co = std::cos(outer), ci = std::cos(inner);
  double t = std::clamp((std::cos(angle) - co) / std::max(0.001, ci - co), 0.0, 1.0);
  return t * t;
}

// ---------------------------------------------------------------------------------------
// A Lambertian plane z = 0 (albedo a, facing +z) seen by a camera, under one light

constexpr float kAlbedo = 0.6f;

Scene plane_scene(const PunctualLightDesc& light) {
  Scene s;
  MaterialDesc lambert;
  lambert.type = MATERIAL_DIFFUSE;
  lambert.base_color = glm::vec4(kAlbedo, kAlbedo, kAlbedo, 1.0f);
  s.materials.push_back(lambert);
  const float h = 50.0f;
  add_polygon(&s, {{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}}, 0);
  s.punctual_lights.push_back(light);
  return s;
}

// Radiance leaving the plane at p toward the camera (rgb)
using Shade = std::function<glm::dvec3(const glm::dvec3& p)>;

// The host twin of camera_ray (cl/camera/camera.cl) through continuous pixel (px, py)
struct View {
  dev::Camera cam;
  int size;
  View(const CameraDesc& c, int n) : cam(make_device_camera(c, n, n)), size(n) {}
  glm::dvec3 origin() const { return {cam.origin[0], cam.origin[1], cam.origin[2]}; }
  glm::dvec3 dir(double px, double py) const {
    double x = 2.0 * px / size - 1.0, y = 1.0 - 2.0 * py / size;
    glm::dvec3 f(cam.forward[0], cam.forward[1], cam.forward[2]), r(cam.right[0], cam.right[1], cam.right[2]),
        u(cam.up[0], cam.up[1], cam.up[2]);
    return glm::normalize(f + x * r + y * u);
  }
  // Where the ray through (px, py) meets the plane z = 0; false if it does not
  bool hit(double px, double py, glm::dvec3* p) const {
    glm::dvec3 o = origin(), d = dir(px, py);
    if (!(d.z < 0.0)) return false;
    *p = o + (-o.z / d.z) * d;
    return true;
  }
  // Sub-pixel points (midpoint rule, k x k) of pixel (x, y)
  template <typename F>
  void for_each_subpixel(int x, int y, int k, F fn) const {
    for (int j = 0; j < k; ++j)
      for (int i = 0; i < k; ++i) fn(x + (i + 0.5) / k, y + (j + 0.5) / k);
  }
  // The box filter's mean of `shade` over pixel (x, y); *variance gets the variance of
  // one jittered sample, from which the standard error of n samples follows
  glm::dvec3 expected(int x, int y, const Shade& shade, glm::dvec3* variance = nullptr, int k = 24) const {
    glm::dvec3 sum(0.0), sum2(0.0);
    for_each_subpixel(x, y, k, [&](double px, double py) {
      glm::dvec3 p, v(0.0);
      if (hit(px, py, &p)) v = shade(p);
      sum += v;
      sum2 += v * v;
    });
    glm::dvec3 mean = sum / double(k * k);
    if (variance) *variance = glm::max(sum2 / double(k * k) - mean * mean, glm::dvec3(0.0));
    return mean;
  }
  // Whether `pred` holds at every sub-pixel point's plane hit (and its corners)
  bool all(int x, int y, const std::function<bool(const glm::dvec3&)>& pred) const {
    bool ok = true;
    for_each_subpixel(x, y, 8, [&](double px, double py) {
      glm::dvec3 p;
      ok = ok && hit(px, py, &p) && pred(p);
    });
    for (int c = 0; c < 4; ++c) {
      glm::dvec3 p;
      ok = ok && hit(x + (c & 1), y + (c >> 1), &p) && pred(p);
    }
    return ok;
  }
};

class PunctualRender : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override { CANDELA_DEVICE_OR_SKIP(GetParam(), device_); }

  Film render(Scene scene, const View& view, const CameraDesc& cam, uint32_t spp) {
    scene.camera = cam;
    RenderSettings settings;
    settings.width = settings.height = view.size;
    settings.max_depth = 1;  // direct light only
    settings.seed = 7;
    return scene_renderer(device_, scene, settings).render(0, spp).film;
  }

  // Pixel (x, y) against its expected value within 5 standard errors of the jitter's noise
  // (the larger of the measured one and the one the closed form gives: samples can miss a
  // sliver of light at a cone's or shadow's edge), and float rounding on the device
  void expect_pixel(const Film& f, const View& view, int x, int y, const Shade& shade, uint32_t spp) {
    glm::dvec3 var;
    glm::dvec3 e = view.expected(x, y, shade, &var);
    size_t i = size_t(y) * view.size + x;
    for (int c = 0; c < 3; ++c) {
      double m = f.pixel(i)[c], se_measured = std::sqrt(double(f.variance_of_mean(i)[c]));
      double se = std::max(se_measured, std::sqrt(var[c] / spp));
      EXPECT_NEAR(m, e[c], 5.0 * se + 2e-4 * e[c] + 1e-7)
          << "pixel " << x << "," << y << " channel " << c << " se " << se_measured << " (model "
          << std::sqrt(var[c] / spp) << ")";
      if (se > 0.0) max_z_ = std::max(max_z_, std::fabs(m - e[c]) / se);
    }
  }

  // Every pixel against its expected value
  void compare(const Film& f, const View& view, const Shade& shade, uint32_t spp) {
    for (int y = 0; y < view.size; ++y)
      for (int x = 0; x < view.size; ++x) expect_pixel(f, view, x, y, shade, spp);
    EXPECT_EQ(f.dropped_samples(), 0u);
  }

  void TearDown() override {
    if (max_z_ > 0.0) std::printf("  largest |measured - expected| / standard error: %.2f\n", max_z_);
  }

  double max_z_ = 0.0;

  DeviceEntry device_;
};

CameraDesc camera(glm::vec3 eye, glm::vec3 at, float yfov, glm::vec3 up = {0, 0, 1}) {
  CameraDesc c;
  c.position = eye;
  c.forward = glm::normalize(at - eye);
  c.up = up;
  c.yfov = yfov;
  return c;
}

// A point light of intensity I at height d: L = a I cos(theta) / (pi r^2), colour x intensity
TEST_P(PunctualRender, PointLightOverPlaneFollowsInverseSquareAndCosine) {
  PunctualLightDesc l;
  l.type = PunctualType::Point;
  l.position = {0.0f, 0.0f, 1.0f};
  l.color = {1.0f, 0.5f, 0.25f};
  l.intensity = 5.0f;
  CameraDesc cam = camera({0.3f, -2.0f, 1.5f}, {0.5f, 0.5f, 0.0f}, 0.9f);
  View view(cam, 16);
  Shade shade = [&](const glm::dvec3& p) {
    glm::dvec3 to_light = glm::dvec3(l.position) - p;
    double r2 = glm::dot(to_light, to_light), cos_theta = to_light.z / std::sqrt(r2);
    return glm::dvec3(l.color) * (kAlbedo * l.intensity * cos_theta / (kPi * r2));
  };
  Film f = render(plane_scene(l), view, cam, 64);
  compare(f, view, shade, 64);
}

// A spot light pointing down: full inside the inner cone, 0 outside the outer cone, the
// extension's smooth curve between
TEST_P(PunctualRender, SpotConeFollowsTheExtensionsFalloff) {
  PunctualLightDesc l;
  l.type = PunctualType::Spot;
  l.position = {0.0f, 0.0f, 1.0f};
  l.direction = {0.0f, 0.0f, -1.0f};
  l.intensity = 3.0f;
  l.inner_cone = 0.3f;
  l.outer_cone = 0.6f;
  CameraDesc cam = camera({0.0f, 0.0f, 3.0f}, {0.0f, 0.0f, 0.0f}, 0.8f, {0, 1, 0});
  View view(cam, 24);
  auto angle = [&](const glm::dvec3& p) {
    glm::dvec3 d = glm::normalize(p - glm::dvec3(l.position));
    return std::acos(std::clamp(-d.z, -1.0, 1.0));
  };
  auto full = [&](const glm::dvec3& p) {  // the point light's value, no cone
    glm::dvec3 to_light = glm::dvec3(l.position) - p;
    double r2 = glm::dot(to_light, to_light);
    return kAlbedo * l.intensity * (to_light.z / std::sqrt(r2)) / (kPi * r2);
  };
  Shade shade = [&](const glm::dvec3& p) {
    return glm::dvec3(full(p) * spot_profile(l.inner_cone, l.outer_cone, angle(p)));
  };
  Film f = render(plane_scene(l), view, cam, 64);
  compare(f, view, shade, 64);
  // Pixels wholly inside the inner cone are at full intensity, wholly outside the outer
  // cone exactly 0, and those wholly between strictly between
  int inside = 0, outside = 0, between = 0;
  for (int y = 0; y < view.size; ++y)
    for (int x = 0; x < view.size; ++x) {
      double m = f.pixel(size_t(y) * view.size + x).x;
      if (view.all(x, y, [&](const glm::dvec3& p) { return angle(p) > l.outer_cone; })) {
        EXPECT_EQ(m, 0.0) << "pixel " << x << "," << y << " is outside the outer cone";
        ++outside;
      } else if (view.all(x, y, [&](const glm::dvec3& p) { return angle(p) < l.inner_cone; })) {
        glm::dvec3 e = view.expected(x, y, [&](const glm::dvec3& p) { return glm::dvec3(full(p)); });
        double se = std::sqrt(double(f.variance_of_mean(size_t(y) * view.size + x).x));
        EXPECT_NEAR(m, e.x, 5.0 * se + 2e-4 * e.x) << "pixel " << x << "," << y << " is inside the inner cone";
        ++inside;
      } else if (view.all(x, y, [&](const glm::dvec3& p) {
                   return angle(p) > l.inner_cone + 0.02 && angle(p) < l.outer_cone - 0.02;
                 })) {
        glm::dvec3 e = view.expected(x, y, [&](const glm::dvec3& p) { return glm::dvec3(full(p)); });
        EXPECT_GT(m, 0.0);
        EXPECT_LT(m, 0.98 * e.x);
        ++between;
      }
    }
  EXPECT_GE(inside, 4);
  EXPECT_GE(outside, 20);
  EXPECT_GE(between, 8);
}

// Range: exactly 0 beyond it; within it the recommended window times the inverse square
TEST_P(PunctualRender, RangeCutsOffWithTheRecommendedWindow) {
  PunctualLightDesc l;
  l.type = PunctualType::Point;
  l.position = {0.0f, 0.0f, 0.5f};
  l.intensity = 2.0f;
  l.range = 1.2f;
  CameraDesc cam = camera({0.0f, 0.0f, 3.0f}, {0.0f, 0.0f, 0.0f}, 0.9f, {0, 1, 0});
  View view(cam, 20);
  auto dist = [&](const glm::dvec3& p) { return glm::length(glm::dvec3(l.position) - p); };
  Shade shade = [&](const glm::dvec3& p) {
    double r = dist(p), cos_theta = l.position.z / r;
    return glm::dvec3(kAlbedo * l.intensity * cos_theta * range_window(l.range, r) / (kPi * r * r));
  };
  Film f = render(plane_scene(l), view, cam, 64);
  compare(f, view, shade, 64);
  int beyond = 0;
  for (int y = 0; y < view.size; ++y)
    for (int x = 0; x < view.size; ++x)
      if (view.all(x, y, [&](const glm::dvec3& p) { return dist(p) > l.range * 1.001; })) {
        EXPECT_EQ(f.pixel(size_t(y) * view.size + x).x, 0.0f) << "pixel " << x << "," << y;
        ++beyond;
      }
  EXPECT_GE(beyond, 20);
}

// A directional light at angle theta to the plane's normal: L = a E cos(theta) / pi, and a
// blocker casts a hard shadow (exactly 0 in the umbra)
TEST_P(PunctualRender, DirectionalLightGivesECosineAndHardShadows) {
  const double theta = 0.5;
  PunctualLightDesc l;
  l.type = PunctualType::Directional;
  l.direction = glm::vec3(-std::sin(theta), 0.0, -std::cos(theta));  // travels down and to -x
  l.intensity = 2.5f;
  l.color = {0.8f, 1.0f, 0.6f};
  Scene s = plane_scene(l);
  // A 0.6 x 0.6 blocker at height 1 over x = 1: its shadow is offset by -tan(theta)
  const double bx = 1.0, half = 0.3, bz = 1.0;
  add_polygon(&s,
              {{float(bx - half), -float(half), float(bz)},
               {float(bx + half), -float(half), float(bz)},
               {float(bx + half), float(half), float(bz)},
               {float(bx - half), float(half), float(bz)}},
              0);
  CameraDesc cam = camera({0.0f, -3.0f, 2.5f}, {0.3f, 0.0f, 0.0f}, 0.6f);
  View view(cam, 20);
  glm::dvec3 to_light = -glm::dvec3(l.direction);
  auto shadowed = [&](const glm::dvec3& p) {
    glm::dvec3 q = p + ((bz - p.z) / to_light.z) * to_light;  // where the ray to the light crosses z = bz
    return std::fabs(q.x - bx) < half && std::fabs(q.y) < half;
  };
  // The plane's normal is +z: cos(theta) = to_light.z
  glm::dvec3 lit = glm::dvec3(l.color) * (kAlbedo * l.intensity * to_light.z / kPi);
  Shade shade = [&](const glm::dvec3& p) { return shadowed(p) ? glm::dvec3(0.0) : lit; };
  Film f = render(s, view, cam, 64);
  // Pixels that see the blocker are left out of the plane's comparison
  int umbra = 0, open = 0;
  for (int y = 0; y < view.size; ++y)
    for (int x = 0; x < view.size; ++x) {
      glm::vec3 m = f.pixel(size_t(y) * view.size + x);
      // A sub-pixel ray that meets the blocker's plane z = bz inside it sees the blocker
      auto sees_plane = [&](const glm::dvec3& p) {
        glm::dvec3 o = view.origin(), d = glm::normalize(p - o);
        glm::dvec3 q = o + ((bz - o.z) / d.z) * d;
        return !(std::fabs(q.x - bx) < half && std::fabs(q.y) < half);
      };
      if (!view.all(x, y, sees_plane)) continue;
      if (view.all(x, y, shadowed)) {
        EXPECT_EQ(m, glm::vec3(0.0f)) << "pixel " << x << "," << y << " is in the umbra";
        ++umbra;
      } else if (view.all(x, y, [&](const glm::dvec3& p) { return !shadowed(p); })) {
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(m[c], lit[c], 2e-4 * lit[c]) << "pixel " << x << "," << y;
        ++open;
      } else {
        expect_pixel(f, view, x, y, shade, 64);  // the shadow's edge crosses the pixel
      }
    }
  EXPECT_GE(umbra, 4);
  EXPECT_GE(open, 100);
}

INSTANTIATE_TEST_SUITE_P(Devices, PunctualRender, kernel_devices(), DeviceParamName());

// Under --strategy bsdf no sampled ray finds a punctual light: the image is black
TEST(PunctualLights, ContributeNothingUnderBsdfStrategy) {
  PunctualLightDesc l;
  l.position = {0.0f, 0.0f, 1.0f};
  Scene s = plane_scene(l);
  s.camera = camera({0.0f, -2.0f, 1.5f}, {0.0f, 0.0f, 0.0f}, 0.8f);
  EXPECT_TRUE(s.has_light());
  EXPECT_EQ(s.punctual_light_count(), 1u);
  RenderSettings settings;
  settings.width = settings.height = 8;
  settings.strategy = Strategy::Bsdf;
  Renderer r = scene_renderer(pocl_device(), s, settings);
  EXPECT_EQ(r.lights(), 1u);
  EXPECT_EQ(image_mean(r.render(0, 16).film).mean, 0.0);
}

// ---------------------------------------------------------------------------------------
// lights_sample / lights_pdf on delta lights (tests/lights/test_lights.cl)

constexpr unsigned kOk = 1, kDelta = 16, kAtInfinity = 8, kShadowClear = 4;

TEST(PunctualLights, SampleIsDeltaWithPmfAndLightsPdfIsZero) {
  const KernelRig& rig = kernel_rig("pocl");
  Scene s = plane_scene({});
  s.punctual_lights.clear();
  PunctualLightDesc point, spot, sun;
  point.position = {0.5f, -0.2f, 1.5f};
  point.intensity = 4.0f;
  point.range = 3.0f;
  spot.type = PunctualType::Spot;
  spot.position = {-0.4f, 0.3f, 2.0f};
  spot.direction = glm::normalize(glm::vec3(0.2f, -0.1f, -1.0f));
  spot.intensity = 9.0f;
  spot.inner_cone = 0.1f;
  spot.outer_cone = 0.5f;
  sun.type = PunctualType::Directional;
  sun.direction = glm::normalize(glm::vec3(0.3f, 0.4f, -1.0f));
  sun.intensity = 2.0f;
  s.punctual_lights = {point, spot, sun};
  CompiledScene c = compile_scene(s);
  ASSERT_EQ(c.buffers.lights.size(), 3u);
  SceneOnDevice sd(rig, c);

  const size_t n = 4096;
  const glm::dvec3 p(0.1, 0.05, 1e-3), normal(0.0, 0.0, 1.0);
  auto out = rig.output<cl_float4>(2 * n);
  // p, n, transmits, seed, check (evaluate lights_pdf and trace the rays)
  rig.run("test_lights_sample", n, sd, f4(p), f4({0.0, 0.0, 1.0}), cl_uint(0), cl_uint(11), cl_uint(1), out);
  std::vector<cl_float4> raw = out.read();
  // The selection probability of each light at p (the light tree's for the point and the spot)
  auto sel_out = rig.output<float>(3);
  rig.run("test_lights_select_pmf", 3, sd, rig.input(std::vector<cl_float4>{f4(p)}),
          rig.input(std::vector<cl_float4>{f4({0.0, 0.0, 1.0})}), sel_out);
  std::vector<float> sel = sel_out.read();
  EXPECT_NEAR(double(sel[0]) + sel[1] + sel[2], 1.0, 1e-6);

  std::vector<size_t> count(3, 0);
  for (size_t i = 0; i < n; ++i) {
    glm::dvec3 wi(raw[2 * i].s[0], raw[2 * i].s[1], raw[2 * i].s[2]);
    double pdf = raw[2 * i].s[3], radiance = raw[2 * i + 1].s[0], pdf_eval = raw[2 * i + 1].s[1];
    unsigned light = unsigned(raw[2 * i + 1].s[2]), flags = unsigned(raw[2 * i + 1].s[3]);
    ASSERT_LT(light, 3u);
    ++count[light];
    ASSERT_TRUE(flags & kOk) << "light " << light;
    EXPECT_TRUE(flags & kDelta);
    EXPECT_EQ(pdf_eval, 0.0) << "lights_pdf of a delta light";
    EXPECT_NEAR(pdf, sel[light], 1e-6 * sel[light]) << "a delta sample's pdf is the selection probability";
    // The incident quantity and its direction
    glm::dvec3 w_expected;
    double e_expected;
    if (light == 2) {
      w_expected = -glm::dvec3(sun.direction);
      e_expected = sun.intensity;
      EXPECT_TRUE(flags & kAtInfinity);
    } else {
      const PunctualLightDesc& pl = light == 0 ? point : spot;
      glm::dvec3 to = glm::dvec3(pl.position) - p;
      double r = glm::length(to);
      w_expected = to / r;
      e_expected = pl.intensity / (r * r) * range_window(pl.range, r);
      if (light == 1)
        e_expected *= spot_profile(spot.inner_cone, spot.outer_cone,
                                   std::acos(glm::dot(-w_expected, glm::dvec3(spot.direction))));
      EXPECT_FALSE(flags & kAtInfinity);
      EXPECT_TRUE(flags & kShadowClear) << "the shadow ray ends at the light";
    }
    EXPECT_NEAR(glm::length(wi - w_expected), 0.0, 1e-5) << "light " << light;
    EXPECT_NEAR(radiance, e_expected, 1e-5 * e_expected) << "light " << light;
  }
  // Every light is picked, about as often as its selection pmf at p says
  for (size_t l = 0; l < 3; ++l) {
    double pmf = sel[l], sd_count = std::sqrt(n * pmf * (1.0 - pmf));
    EXPECT_NEAR(double(count[l]), n * pmf, 5.0 * sd_count + 1.0) << "light " << l;
  }
}

// Selection power: point 4 pi I, spot the integral of its profile, directional pi r^2 E
TEST(PunctualLights, LightPowerIntegratesTheEmission) {
  PunctualLightDesc point;
  point.intensity = 3.0f;
  auto power_of = [&](const PunctualLightDesc& l, double radius) {
    Scene one = plane_scene(l);
    CompiledScene c = compile_scene(one);
    EXPECT_EQ(c.buffers.lights.size(), 1u);
    return light_power(c.buffers.lights[0], c.buffers, 1.0, radius);
  };
  EXPECT_NEAR(power_of(point, 1.0), 4.0 * kPi * 3.0, 1e-4);
  // Spots: the profile integrated over the sphere by the midpoint rule in the cosine
  for (auto cone : {std::pair{0.0, 0.7853982}, {0.3, 0.6}, {0.5, 0.5005}, {0.0, 1.5707963}, {1.2, 1.5707963}}) {
    PunctualLightDesc spot;
    spot.type = PunctualType::Spot;
    spot.intensity = 2.0f;
    spot.color = {0.5f, 0.5f, 0.5f};
    spot.inner_cone = float(cone.first);
    spot.outer_cone = float(cone.second);
    const int m = 1 << 20;
    double integral = 0.0;
    for (int i = 0; i < m; ++i) {
      double c = -1.0 + 2.0 * (i + 0.5) / m;
      integral += spot_profile(spot.inner_cone, spot.outer_cone, std::acos(c));
    }
    integral *= 2.0 * kPi * 2.0 / m;
    EXPECT_NEAR(power_of(spot, 1.0), 1.0 * integral, 2e-4 * integral) << cone.first << " " << cone.second;
  }
  PunctualLightDesc sun;
  sun.type = PunctualType::Directional;
  sun.intensity = 4.0f;
  EXPECT_NEAR(power_of(sun, 2.0), kPi * 4.0 * 4.0, 1e-4);
  // Black lights are left out of the light list
  PunctualLightDesc black;
  black.intensity = 0.0f;
  EXPECT_TRUE(compile_scene(plane_scene(black)).buffers.lights.empty());
  EXPECT_FALSE(plane_scene(black).has_light());
}

// ---------------------------------------------------------------------------------------
// Loader

// A quad under the given lights (the extension's "lights" array) and light nodes
Scene load_with_lights(const json& lights, const std::vector<json>& light_nodes) {
  GltfBuilder g;
  g.add_node({{"mesh", g.add_mesh({quad_primitive({{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, -1)})}});
  g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  g.doc["extensions"]["KHR_lights_punctual"]["lights"] = lights;
  for (const json& n : light_nodes) g.add_node(n);
  return load_gltf_from_memory(g.document().dump(), "");
}

json light_node(int light) { return {{"extensions", {{"KHR_lights_punctual", {{"light", light}}}}}}; }

void expect_vec(const glm::vec3& a, const glm::vec3& b, float tol = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

TEST(PunctualLoader, ReadsPositionDirectionIntensityAndCone) {
  json lights = json::parse(R"([
    {"type": "point", "color": [1, 0.5, 0.25], "intensity": 7, "range": 4},
    {"type": "spot", "intensity": 3, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.4}},
    {"type": "directional", "intensity": 2}])");
  json point = light_node(0), spot = light_node(1), sun = light_node(2);
  point["translation"] = {1, 2, 3};
  spot["translation"] = {0, 0, 2};
  Scene s = load_with_lights(lights, {point, spot, sun});
  ASSERT_EQ(s.punctual_lights.size(), 3u);
  const PunctualLightDesc& p = s.punctual_lights[0];
  EXPECT_EQ(p.type, PunctualType::Point);
  expect_vec(p.position, {1, 2, 3});
  expect_vec(p.color, {1, 0.5f, 0.25f});
  EXPECT_FLOAT_EQ(p.intensity, float(7.0 / kLumensPerWatt));  // candela to W/sr
  EXPECT_FLOAT_EQ(p.range, 4.0f);
  const PunctualLightDesc& sp = s.punctual_lights[1];
  EXPECT_EQ(sp.type, PunctualType::Spot);
  expect_vec(sp.position, {0, 0, 2});
  expect_vec(sp.direction, {0, 0, -1});  // untransformed: down -Z
  EXPECT_FLOAT_EQ(sp.inner_cone, 0.2f);
  EXPECT_FLOAT_EQ(sp.outer_cone, 0.4f);
  EXPECT_FLOAT_EQ(sp.range, 0.0f);  // infinite
  const PunctualLightDesc& d = s.punctual_lights[2];
  EXPECT_EQ(d.type, PunctualType::Directional);
  expect_vec(d.direction, {0, 0, -1});
  expect_vec(d.color, {1, 1, 1});  // the default colour
  EXPECT_TRUE(s.has_light());
  for (const std::string& w : s.warnings) EXPECT_EQ(w.find("KHR_lights_punctual"), std::string::npos) << w;
}

// The node's rotation turns the spot (and its parent's transform places it); scale does
// not change the cone or the intensity
TEST(PunctualLoader, NodeTransformRotatesASpotLight) {
  json lights = json::parse(R"([{"type": "spot", "intensity": 5, "spot": {"outerConeAngle": 0.5}}])");
  // Rotation by 90 degrees about +x takes -Z to +Y
  glm::quat q = glm::angleAxis(float(kPi / 2), glm::vec3(1, 0, 0));
  json child = light_node(0);
  child["rotation"] = {q.x, q.y, q.z, q.w};
  child["scale"] = {2, 2, 2};
  GltfBuilder g;
  g.add_node({{"mesh", g.add_mesh({quad_primitive({{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, -1)})}});
  g.doc["extensions"]["KHR_lights_punctual"]["lights"] = lights;
  int c = g.add("nodes", child);
  g.add_node({{"translation", {1, 0, 0}}, {"children", {c}}});
  g.doc["scenes"][0]["nodes"] = {0, c + 1};
  Scene s = load_gltf_from_memory(g.document().dump(), "");
  ASSERT_EQ(s.punctual_lights.size(), 1u);
  const PunctualLightDesc& l = s.punctual_lights[0];
  expect_vec(l.position, {1, 0, 0});
  expect_vec(l.direction, {0, 1, 0});
  EXPECT_NEAR(glm::length(l.direction), 1.0f, 1e-6f);
  EXPECT_FLOAT_EQ(l.intensity, float(5.0 / kLumensPerWatt));
  EXPECT_FLOAT_EQ(l.outer_cone, 0.5f);
  EXPECT_FLOAT_EQ(l.inner_cone, 0.0f);
}

// What the extension says must not be is an error naming the problem; what it says
// should not be, a warning
TEST(PunctualLoader, MalformedLightsAreClearErrors) {
  auto error_of = [](const json& lights, const json& node) -> std::string {
    try {
      load_with_lights(lights, {node});
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  auto one = [](const char* text) { return json::parse(text); };
  EXPECT_NE(error_of(one(R"([{"type": "point", "intensity": -1}])"), light_node(0)).find("intensity"),
            std::string::npos);
  EXPECT_NE(
      error_of(one(R"([{"type": "spot", "spot": {"innerConeAngle": 0.5, "outerConeAngle": 0.4}}])"), light_node(0))
          .find("cone"),
      std::string::npos);
  EXPECT_NE(error_of(one(R"([{"type": "spot", "spot": {"outerConeAngle": 2.0}}])"), light_node(0)).find("cone"),
            std::string::npos);
  EXPECT_NE(error_of(one(R"([{"type": "spot", "spot": {"innerConeAngle": -0.1}}])"), light_node(0)).find("cone"),
            std::string::npos);
  EXPECT_NE(error_of(one(R"([{"type": "point", "range": -2}])"), light_node(0)).find("range"), std::string::npos);
  EXPECT_NE(error_of(one(R"([{"type": "area"}])"), light_node(0)).find("type"), std::string::npos);
  EXPECT_NE(error_of(one(R"([{"type": "point", "color": [1, -1, 0]}])"), light_node(0)).find("color"),
            std::string::npos);
  // The node's light: missing, out of range, not a number
  json no_index = {{"extensions", {{"KHR_lights_punctual", json::object()}}}};
  EXPECT_NE(error_of(one(R"([{"type": "point"}])"), no_index).find("no light index"), std::string::npos);
  EXPECT_NE(error_of(one(R"([{"type": "point"}])"), light_node(3)).find("missing"), std::string::npos);
  json bad_index = {{"extensions", {{"KHR_lights_punctual", {{"light", "zero"}}}}}};
  EXPECT_NE(error_of(one(R"([{"type": "point"}])"), bad_index).find("no light index"), std::string::npos);
  // A degenerate transform leaves a spot without a direction
  json flat = light_node(0);
  flat["scale"] = {0, 0, 0};
  EXPECT_NE(error_of(one(R"([{"type": "spot"}])"), flat).find("direction"), std::string::npos);
  // A point light needs no direction, so the same transform is fine for it
  EXPECT_EQ(error_of(one(R"([{"type": "point"}])"), flat), "");
  // A spot light may leave out its `spot` object: the default cone applies
  Scene defaults = load_with_lights(one(R"([{"type": "spot"}])"), {light_node(0)});
  ASSERT_EQ(defaults.punctual_lights.size(), 1u);
  EXPECT_FLOAT_EQ(defaults.punctual_lights[0].inner_cone, 0.0f);
  EXPECT_FLOAT_EQ(defaults.punctual_lights[0].outer_cone, float(kPi / 4));
  // range on a directional light: ignored with a warning
  Scene s = load_with_lights(one(R"([{"type": "directional", "range": 3}])"), {light_node(0)});
  ASSERT_EQ(s.punctual_lights.size(), 1u);
  EXPECT_EQ(s.punctual_lights[0].range, 0.0f);
  bool warned = false;
  for (const std::string& w : s.warnings) warned |= w.find("range") != std::string::npos;
  EXPECT_TRUE(warned);
}

}  // namespace
}  // namespace candela::test
