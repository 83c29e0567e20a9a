// Environment maps (cl/lights/environment.cl, host/environment.cpp) on the real kernel code:
//  - chi-square of environment_sample directions against environment_pdf integrated over
//    cells in (cos theta, phi) about +Y (1M samples, cells with expected count < 5 pooled,
//    alpha = 0.01 with the Sidak correction over this file's chi-square tests); the
//    cells' integrals sum to 1; a pdf without the sin(theta) Jacobian is rejected;
//  - each sample's pdf and radiance against a host reference of the documented mapping
//    and of the CDFs;
//  - renders: a white sphere under a constant-valued map, a tiny bright sun under nee and
//    bsdf (same mean, far lower variance under nee), rotated maps seen directly;
//  - the glTF extras and the file loader.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <glm/glm.hpp>
#include <memory>

#include "base/error.hpp"
#include "compile/environment_distribution.hpp"
#include "compile/scene_compiler.hpp"
#include "gltf/gltf_loader.hpp"
#include "render/renderer.hpp"
#include "scene/environment.hpp"
#include "support/gltf_builder.hpp"
#include "support/reference.hpp"
#include "support/scenes.hpp"
#include "support/stats.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

constexpr size_t kSamples = 1 << 20;
constexpr int kChiSquareTests = 2 * 2;  // per device: sky and sun at two rotations
const double kAlpha = sidak_alpha(0.01, kChiSquareTests);

// A w x h float map whose texel (x, y) is rgb(x, y)
TextureDesc make_map(int w, int h, const std::function<glm::vec3(int, int)>& rgb) {
  TextureDesc t;
  t.width = w;
  t.height = h;
  t.nearest = true;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      glm::vec3 c = rgb(x, y);
      t.rgbaf.insert(t.rgbaf.end(), {c.x, c.y, c.z, 1.0f});
    }
  return t;
}

// Sky and sun: a gradient from a bright horizon to a bluish zenith, a dark ground, and a
// sun of 2 x 2 texels of radiance 400 (about half of the sampling weight)
TextureDesc sky_and_sun(int w, int h) {
  return make_map(w, h, [w, h](int x, int y) {
    if ((x == w / 8 || x == w / 8 + 1) && (y == h / 4 || y == h / 4 + 1)) return glm::vec3(400.0f, 380.0f, 350.0f);
    double cos_theta = std::cos(kPi * (y + 0.5) / h);
    if (cos_theta < 0.0) return glm::vec3(0.2f, 0.18f, 0.15f);
    float t = float(cos_theta);
    return glm::vec3(1.2f - 0.8f * t, 1.25f - 0.7f * t, 1.3f - 0.3f * t) * (1.0f + 0.3f * float(x % 5) / 4.0f);
  });
}

// Direction of (theta, phi) in the documented frame: theta from +Y, phi = atan2(-x, z)
glm::dvec3 direction(double theta, double phi) {
  return {-std::sin(theta) * std::sin(phi), std::cos(theta), std::sin(theta) * std::cos(phi)};
}
double phi_of(const glm::dvec3& d) {
  double phi = std::atan2(-d.x, d.z);
  return phi < 0.0 ? phi + 2.0 * kPi : phi;
}

// The documented mapping on the host: the texel a world direction sees under a rotation
// of `rotation` degrees; *edge gets the distance to the nearest texel edge in texels
glm::ivec2 host_texel(const glm::dvec3& d, int w, int h, double rotation, double* edge = nullptr) {
  double u = (phi_of(d) + rotation * kPi / 180.0) / (2.0 * kPi);
  u -= std::floor(u);
  double v = std::acos(std::clamp(d.y, -1.0, 1.0)) / kPi;
  double x = u * w, y = v * h;
  if (edge) *edge = std::min({x - std::floor(x), std::ceil(x) - x, y - std::floor(y), std::ceil(y) - y});
  return {std::clamp(int(x), 0, w - 1), std::clamp(int(y), 0, h - 1)};
}

// A scene of one small triangle far below (nothing in view) under `env`
Scene environment_only(const EnvironmentDesc& env) {
  Scene s;
  s.materials.resize(1);
  MeshDesc m;
  m.positions = {{0.0f, -100.0f, 0.0f}, {0.01f, -100.0f, 0.0f}, {0.0f, -100.0f, 0.01f}};
  m.indices = {0, 1, 2};
  s.meshes.push_back(m);
  s.environment = env;
  return s;
}

EnvironmentDesc env_of(TextureDesc map, float strength, float rotation) {
  EnvironmentDesc e;
  e.image = std::move(map);
  e.strength = strength;
  e.rotation = rotation;
  e.source = "test map";
  return e;
}

class EnvironmentKernels : public DeviceTest {
 protected:
  void use(const EnvironmentDesc& env) {
    compiled_ = compile_scene(environment_only(env));
    ASSERT_NE(compiled_.environment_light, NO_LIGHT);
    scene_ = std::make_unique<SceneOnDevice>(rig(), compiled_);
  }

  // out[2i] = (dir, pdf), out[2i+1] = (environment_pdf(dir), radiance)
  std::vector<cl_float4> sample(cl_uint seed, size_t n = kSamples) {
    auto out = rig().output<cl_float4>(2 * n);
    rig().run("test_environment_sample", n, *scene_, seed, out);
    return out.read();
  }

  // Integrals of environment_pdf over cells (cos0, cos1, phi0, phi1)
  std::vector<double> cell_probabilities(const std::vector<cl_float4>& cells, cl_uint mode, cl_uint sub = 8) {
    auto out = rig().output<float>(cells.size());
    rig().run("test_environment_pdf_cells", cells.size(), *scene_, sub, mode, rig().input(cells), out);
    std::vector<float> p = out.read();
    return std::vector<double>(p.begin(), p.end());
  }

  // Radiance that missed rays see along each direction
  std::vector<glm::vec3> radiance(const std::vector<glm::dvec3>& dirs) {
    std::vector<cl_float4> in;
    for (const auto& d : dirs) in.push_back(f4(d));
    auto out = rig().output<cl_float4>(in.size());
    rig().run("test_environment_radiance", in.size(), *scene_, rig().input(in), out);
    std::vector<glm::vec3> v;
    for (const auto& c : out.read()) v.push_back({c.s[0], c.s[1], c.s[2]});
    return v;
  }

  CompiledScene compiled_;
  std::unique_ptr<SceneOnDevice> scene_;
};

constexpr int kMapW = 32, kMapH = 16;

// Cells of half a texel in theta and phi (the map at rotation 0 or a multiple of a texel):
// the pdf x sin(theta) is constant on each, so the midpoint rule in (theta, phi) is exact,
// and a wrong density within texels shows
struct Cells {
  int n_theta = 2 * kMapH, n_phi = 2 * kMapW;
  std::vector<cl_float4> bounds() const {
    std::vector<cl_float4> v;
    for (int i = 0; i < n_theta; ++i)
      for (int j = 0; j < n_phi; ++j)
        v.push_back({{float(std::cos(kPi * (i + 1) / n_theta)), float(std::cos(kPi * i / n_theta)),
                      float(2.0 * kPi * j / n_phi), float(2.0 * kPi * (j + 1) / n_phi)}});
    return v;
  }
  int bin(const glm::dvec3& d) const {
    int i = std::clamp(int(std::acos(std::clamp(d.y, -1.0, 1.0)) / kPi * n_theta), 0, n_theta - 1);
    int j = std::clamp(int(phi_of(d) / (2.0 * kPi) * n_phi), 0, n_phi - 1);
    return i * n_phi + j;
  }
};

ChiSquare histogram_test(const std::vector<cl_float4>& s, const Cells& cells, std::vector<double> prob) {
  std::vector<double> observed(prob.size(), 0.0);
  size_t n = s.size() / 2;
  double total = 0.0;
  for (double p : prob) total += p;
  for (size_t i = 0; i < n; ++i) {
    const cl_float4& a = s[2 * i];
    observed[size_t(cells.bin({a.s[0], a.s[1], a.s[2]}))] += 1.0;
  }
  for (double& p : prob) p *= double(n) / total;
  return chi_square_test(observed, prob);
}

}  // namespace

// Sampled directions follow environment_pdf (at rotation 0 and at 45 degrees, four texels),
// which integrates to 1; a pdf without the Jacobian's 1 / sin(theta) is rejected
TEST_P(EnvironmentKernels, SampledDirectionsMatchPdf) {
  cl_uint seed = 3;
  for (float rotation : {0.0f, 45.0f}) {
    SCOPED_TRACE(rotation);
    use(env_of(sky_and_sun(kMapW, kMapH), 1.0f, rotation));
    std::vector<cl_float4> s = sample(seed++);
    Cells cells;
    std::vector<double> prob = cell_probabilities(cells.bounds(), 0);
    double total = 0.0;
    for (double p : prob) total += p;
    EXPECT_NEAR(total, 1.0, 1e-4) << "environment_pdf integrates to 1 over the sphere";
    ChiSquare r = histogram_test(s, cells, prob);
    RecordProperty("chi2_rotation_" + std::to_string(int(rotation)),
                   std::to_string(r.statistic) + " dof " + std::to_string(r.dof) + " p " + std::to_string(r.p_value) +
                       " integral " + std::to_string(total));
    EXPECT_GT(r.p_value, kAlpha) << "chi2 " << r.statistic << " dof " << r.dof;
    EXPECT_GT(r.dof, 1000);
    ChiSquare wrong = histogram_test(s, cells, cell_probabilities(cells.bounds(), 1));
    EXPECT_LT(wrong.p_value, 1e-6) << "the wrong pdf passes: chi2 " << wrong.statistic << " dof " << wrong.dof;
  }
}

// Each sample's pdf equals environment_pdf at its direction and the host's pdf of the
// documented mapping and CDFs; its radiance is strength x the texel the mapping names
TEST_P(EnvironmentKernels, SamplePdfAndRadianceMatchHostReference) {
  const float strength = 1.7f, rotation = 30.0f;
  TextureDesc map = sky_and_sun(kMapW, kMapH);
  use(env_of(map, strength, rotation));
  const std::vector<float>& cdf = compiled_.buffers.env_distribution;
  const size_t guides_at = size_t(kMapH + 1) + size_t(kMapH) * (kMapW + 1);
  ASSERT_EQ(cdf.size(), guides_at + size_t(dev::environment_guide_cells(kMapH)) +
                            size_t(kMapH) * size_t(dev::environment_guide_cells(kMapW)));
  // Row 3's guide: cell k starts at the largest column whose CDF value is <= k / cells of the total
  const float* row3 = cdf.data() + (kMapH + 1) + 3 * (kMapW + 1);
  const float* guide3 =
      cdf.data() + guides_at + dev::environment_guide_cells(kMapH) + 3 * dev::environment_guide_cells(kMapW);
  for (int k = 0; k < dev::environment_guide_cells(kMapW); ++k) {
    int i = int(guide3[k]);
    float t = float(double(k) / dev::environment_guide_cells(kMapW) * row3[kMapW]);
    ASSERT_LE(row3[i], t) << "cell " << k;
    if (i + 1 < kMapW) {
      ASSERT_GT(row3[i + 1], t) << "cell " << k;
    }
  }
  std::vector<cl_float4> s = sample(5, 1 << 16);
  size_t compared = 0, mismatched = 0;
  for (size_t i = 0; i < s.size() / 2; ++i) {
    const cl_float4 &a = s[2 * i], &b = s[2 * i + 1];
    glm::dvec3 d(a.s[0], a.s[1], a.s[2]);
    ASSERT_NEAR(glm::length(d), 1.0, 1e-5);
    ASSERT_GT(a.s[3], 0.0f) << "sample " << i;
    ASSERT_EQ(a.s[3], b.s[0]) << "sample " << i << ": sampled pdf differs from environment_pdf";
    double edge;
    glm::ivec2 t = host_texel(d, kMapW, kMapH, rotation, &edge);
    if (edge < 1e-3) continue;  // float rounding may pick the neighbour
    ++compared;
    const float* rows = cdf.data();
    const float* cols = rows + (kMapH + 1) + t.y * (kMapW + 1);
    double p_uv = double(rows[t.y + 1] - rows[t.y]) / rows[kMapH] * kMapH * double(cols[t.x + 1] - cols[t.x]) /
                  cols[kMapW] * kMapW;
    double pdf = p_uv / (2.0 * kPi * kPi * std::sqrt(d.x * d.x + d.z * d.z));
    size_t texel = size_t(t.y) * kMapW + size_t(t.x);
    bool ok = std::fabs(a.s[3] - pdf) <= 1e-4 * pdf;
    for (int c = 0; c < 3; ++c)
      ok = ok && std::fabs(b.s[1 + c] - strength * map.rgbaf[4 * texel + size_t(c)]) <= 1e-5 * b.s[1 + c];
    if (!ok && mismatched++ < 5)
      ADD_FAILURE() << "sample " << i << " texel " << t.x << "," << t.y << ": pdf " << a.s[3] << " host " << pdf
                    << ", radiance " << b.s[1] << " host " << strength * map.rgbaf[4 * texel];
  }
  EXPECT_EQ(mismatched, 0u);
  EXPECT_GT(compared, s.size() / 2 * 99 / 100);
}

// The documented orientation: the top row is +Y, the image centre is seen along -Z with
// u growing toward +X, and a rotation of 90 degrees moves what -Z saw to -X
TEST_P(EnvironmentKernels, MappingAndRotation) {
  // Texel (x, y) holds (x, y, 1): its value names it
  TextureDesc map = make_map(16, 8, [](int x, int y) { return glm::vec3(float(x), float(y), 1.0f); });
  const double a = 5.0 * kPi / 180.0;
  struct Case {
    float rotation;
    glm::dvec3 dir;
    int x, y;
  } cases[] = {
      {0.0f, {std::sin(a), std::sin(a), -1.0}, 8, 3},    // just right of -Z, just above the horizon
      {0.0f, {-std::sin(a), -std::sin(a), -1.0}, 7, 4},  // just left of -Z, just below
      {0.0f, {1.0, 0.3, std::sin(a)}, 12, 3},            // +X (u = 3/4), a little toward +Z (u = 1)
      {0.0f, {-1.0, 0.3, std::sin(a)}, 3, 3},            // -X (u = 1/4), a little toward +Z (u = 0)
      {0.0f, {0.0, 1.0, 0.1}, 0, 0},                     // near the zenith: the top row
      {0.0f, {0.0, -1.0, 0.1}, 0, 7},                    // near the nadir: the bottom row (phi = 0 at +Z)
      {90.0f, {-1.0, std::sin(a), -std::sin(a)}, 8, 3},  // rotated: -Z's view is now at -X
      {90.0f, {std::sin(a), std::sin(a), -1.0}, 12, 3},  // and +X's at -Z
      {-90.0f, {1.0, std::sin(a), std::sin(a)}, 8, 3},   // the other way round: at +X
  };
  for (float rotation : {0.0f, 90.0f, -90.0f}) {
    use(env_of(map, 2.0f, rotation));
    std::vector<glm::dvec3> dirs;
    for (const Case& c : cases)
      if (c.rotation == rotation) dirs.push_back(glm::normalize(c.dir));
    std::vector<glm::vec3> l = radiance(dirs);
    size_t k = 0;
    for (const Case& c : cases) {
      if (c.rotation != rotation) continue;
      EXPECT_EQ(l[k], glm::vec3(2.0f * c.x, 2.0f * c.y, 2.0f))
          << "rotation " << rotation << " dir " << c.dir.x << "," << c.dir.y << "," << c.dir.z;
      glm::ivec2 t = host_texel(dirs[k], 16, 8, rotation);
      EXPECT_EQ(t, glm::ivec2(c.x, c.y)) << "the test's host mapping";
      ++k;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Devices, EnvironmentKernels, kernel_devices(), DeviceParamName());

// A closed white Lambertian sphere under a map of constant value 0.6 x strength 1.5 is
// invisible: every pixel is 0.9, under both strategies (a map, not the constant path)
TEST(EnvironmentRender, WhiteSphereUnderConstantMapIsInvisible) {
  Scene scene = load_scene(sphere_in_view(lambert_material(1.0f)), "env-furnace.gltf");
  scene.environment = env_of(make_map(16, 8, [](int, int) { return glm::vec3(0.6f); }), 1.5f, 20.0f);
  for (Strategy s : {Strategy::Nee, Strategy::Bsdf}) {
    Film f = render_film(scene, s, 16, 16, 256, 1000, 7);
    Estimate e = image_mean(f);
    EXPECT_LT(e.standard_error, 0.01);
    EXPECT_NEAR(e.mean, 0.9, 4.0 * e.standard_error + 1e-5) << (s == Strategy::Nee ? "nee" : "bsdf");
    EXPECT_EQ(f.dropped_samples(), 0u);
  }
}

// A diffuse sphere on a floor under tiny-sun.hdr (dim 0.02 and a sun of 2 x 2 texels at
// 1000): nee and bsdf agree on the image mean, and nee's standard error per sample is
// far lower (BSDF sampling finds the sun on about 1 bounce in 600)
TEST(EnvironmentRender, TinySunNeeAgreesWithBsdfAndHasLowerVariance) {
  GltfBuilder g;
  int white = g.add("materials", lambert_material(0.8f)), grey = g.add("materials", lambert_material(0.5f));
  g.add_node({{"mesh", g.add_mesh({sphere_primitive(glm::vec3(0.0f, 0.5f, 0.0f), 0.5f, 3, white),
                                   quad_facing_up(3.0f, 0.0f, grey)})}});
  g.add_camera(glm::vec3(0.0f, 1.2f, 2.5f), glm::vec3(0.0f, 0.4f, 0.0f), 0.8f);
  Scene scene = load_scene(g, "env-tiny-sun.gltf");
  scene.environment = load_environment(scene_path("lights/tiny-sun.hdr"), 1.0f, 0.0f);
  const int size = 16;
  const uint32_t nee_spp = 64, bsdf_spp = 4096;
  Film nee = render_film(scene, Strategy::Nee, size, size, nee_spp, 3, 1);
  Film bsdf = render_film(scene, Strategy::Bsdf, size, size, bsdf_spp, 3, 2);
  Estimate a = image_mean(nee), b = image_mean(bsdf);
  double se = std::sqrt(a.standard_error * a.standard_error + b.standard_error * b.standard_error);
  EXPECT_GT(a.mean, 0.1) << "the sun lights the scene";
  EXPECT_NEAR(a.mean, b.mean, 4.0 * se) << "nee " << a.mean << " +- " << a.standard_error << ", bsdf " << b.mean
                                        << " +- " << b.standard_error;
  // Standard error of one sample per pixel: se x sqrt(spp)
  double per_sample_nee = a.standard_error * std::sqrt(double(nee_spp));
  double per_sample_bsdf = b.standard_error * std::sqrt(double(bsdf_spp));
  RecordProperty("means", "nee " + std::to_string(a.mean) + " +- " + std::to_string(a.standard_error) + ", bsdf " +
                              std::to_string(b.mean) + " +- " + std::to_string(b.standard_error));
  RecordProperty("se_ratio", std::to_string(per_sample_bsdf / per_sample_nee));
  EXPECT_GT(per_sample_bsdf, 5.0 * per_sample_nee) << "nee " << per_sample_nee << " bsdf " << per_sample_bsdf;
  EXPECT_EQ(nee.dropped_samples(), 0u);
  EXPECT_EQ(bsdf.dropped_samples(), 0u);
}

// Rotating the map by 90 degrees moves the sun: a camera ray that sees the sun's texel
// directly at rotation 0 sees the dim sky at 90 degrees, and the one turned by 90 degrees
// about +Y (counter-clockwise from above) sees the sun, each exactly the texel's value
TEST(EnvironmentRender, RotationMovesTheSun) {
  EnvironmentDesc env = load_environment(scene_path("lights/tiny-sun.hdr"), 1.0f, 0.0f);
  int w = env.image.width, h = env.image.height;
  size_t sun = size_t(std::max_element(env.image.rgbaf.begin(), env.image.rgbaf.end()) - env.image.rgbaf.begin()) / 4;
  int sx = int(sun % size_t(w)), sy = int(sun / size_t(w));
  float sun_value = env.image.rgbaf[4 * sun];
  ASSERT_GT(sun_value, 500.0f);
  // The centre of the sun texel at rotation 0, and that direction turned by +90 degrees
  glm::dvec3 d0 = direction(kPi * (sy + 0.5) / h, 2.0 * kPi * (sx + 0.5) / w);
  glm::dvec3 d90(d0.z, d0.y, -d0.x);  // right-handed rotation about +Y by 90 degrees
  for (float rotation : {0.0f, 90.0f}) {
    env.rotation = rotation;
    Scene scene = environment_only(env);
    for (const glm::dvec3& d : {d0, d90}) {
      CameraDesc cam;
      cam.position = glm::vec3(0.0f);
      cam.forward = glm::vec3(d);
      cam.yfov = 0.2f * float(kPi) / 180.0f;  // a pixel far inside one texel
      scene.camera = cam;
      Film f = render_film(scene, Strategy::Nee, 1, 1, 4, 0, 0);
      bool want_sun = rotation == 0.0f ? d == d0 : d == d90;
      glm::ivec2 t = host_texel(d, w, h, rotation);
      float texel = env.image.rgbaf[4 * (size_t(t.y) * w + t.x)];
      EXPECT_EQ(f.pixel(0).x, texel) << "rotation " << rotation;
      if (want_sun)
        EXPECT_EQ(f.pixel(0).x, sun_value) << "rotation " << rotation << ": the sun is not where it should be";
      else
        EXPECT_LT(f.pixel(0).x, 1.0f) << "rotation " << rotation << ": the sun is still here";
    }
  }
}

// scenes[i].extras.candela.environment: the file relative to the glTF file, strength
// and rotation; a missing file is an error; without a folder the map is not read
TEST(EnvironmentLoader, SceneExtras) {
  GltfBuilder g;
  int m = g.add("materials", lambert_material(0.5f));
  g.add_node({{"mesh", g.add_mesh({sphere_primitive(glm::vec3(0.0f), 0.5f, 1, m)})}});
  g.doc["scenes"][0]["extras"] = {
      {"candela", {{"environment", {{"file", "tiny-sun.hdr"}, {"strength", 2.5}, {"rotation", 30}}}}}};
  std::string text = g.document().dump();
  Scene s = load_gltf_from_memory(text, scene_path("lights"));  // as if beside tiny-sun.hdr
  ASSERT_TRUE(s.environment);
  EXPECT_EQ(s.environment->image.width, 128);
  EXPECT_EQ(s.environment->image.height, 64);
  EXPECT_FLOAT_EQ(s.environment->strength, 2.5f);
  EXPECT_FLOAT_EQ(s.environment->rotation, 30.0f);
  EXPECT_TRUE(s.has_light());
  float peak = *std::max_element(s.environment->image.rgbaf.begin(), s.environment->image.rgbaf.end());
  EXPECT_NEAR(peak, 1000.0f, 1000.0f / 128.0f) << "RGBE keeps 8 bits of mantissa";
  // Compiled: a LIGHT_ENVIRONMENT with the map's texture, strength and rotation
  CompiledScene c = compile_scene(s);
  ASSERT_NE(c.environment_light, NO_LIGHT);
  const dev::Light& l = c.buffers.lights[size_t(c.environment_light)];
  EXPECT_EQ(l.type, LIGHT_ENVIRONMENT);
  EXPECT_EQ(int(l.params.environment.map), int(c.buffers.textures.size()) - 1);
  EXPECT_FLOAT_EQ(l.params.environment.strength, 2.5f);
  EXPECT_NEAR(l.params.environment.rotation, 30.0 * kPi / 180.0, 1e-6);

  g.doc["scenes"][0]["extras"]["candela"]["environment"]["file"] = "no-such-map.hdr";
  EXPECT_THROW(load_gltf_from_memory(g.document().dump(), scene_path("lights")), Error);
  Scene no_folder = load_gltf_from_memory(text, "");
  EXPECT_FALSE(no_folder.environment);
  EXPECT_FALSE(no_folder.warnings.empty());
}

// The built-in studio: neutral grey, smooth (bilinear, fine enough that neighbouring texels
// differ by little away from the soft lights), brighter overhead than at the horizon and
// than the floor, with its key light in front to the left and above
TEST(EnvironmentLoader, BuiltinStudio) {
  EnvironmentDesc studio = builtin_environment();
  const TextureDesc& t = studio.image;
  EXPECT_FALSE(t.nearest);
  EXPECT_GE(t.width, 512);
  auto texel = [&](int x, int y) {
    const float* p = &t.rgbaf[4 * (size_t(y) * t.width + x)];
    return glm::vec3(p[0], p[1], p[2]);
  };
  // Column w / 4 looks along -X, away from the soft lights; row `y` at height cos(pi (y + 1/2) / h)
  // 15 degrees above the horizon: row h (90 - 15) / 180; the ceiling there is 0.55 + 0.3 sin 15
  glm::vec3 zenith = texel(t.width / 4, 0), horizon = texel(t.width / 4, t.height * 75 / 180),
            nadir = texel(t.width / 4, t.height - 1);
  EXPECT_EQ(zenith.x, zenith.y);
  EXPECT_EQ(zenith.y, zenith.z);
  EXPECT_GT(zenith.x, horizon.x);
  EXPECT_GT(horizon.x, nadir.x);
  EXPECT_NEAR(horizon.x, 0.55f + 0.3f * std::sin(15.0f * 3.14159265f / 180.0f), 0.01f);
  EXPECT_NEAR(nadir.x, 0.18f, 0.01f);
  // The background (column w / 4 looks along -X, away from the soft lights) has no hard
  // band: neighbouring rows differ by under 15 % (the former 64 x 32 sky stepped by 25 % at
  // once), and the horizon blends over at least 10 rows between floor and ceiling
  int blend_rows = 0;
  for (int y = 1; y < t.height; ++y) {
    float a = texel(t.width / 4, y - 1).x, b = texel(t.width / 4, y).x;
    EXPECT_LT(std::fabs(a - b), 0.15f * std::max(a, b)) << "rows " << y - 1 << " and " << y;
    blend_rows += b > 0.2f && b < 0.5f;
  }
  EXPECT_GE(blend_rows, 10);
  // The key light: brightest toward (-0.45, 0.75, 0.5)
  float best = 0.0f;
  glm::vec3 best_dir(0.0f);
  for (int y = 0; y < t.height; ++y)
    for (int x = 0; x < t.width; ++x)
      if (texel(x, y).x > best) {
        best = texel(x, y).x;
        double theta = kPi * (y + 0.5) / t.height, phi = 2.0 * kPi * (x + 0.5) / t.width;
        best_dir = glm::vec3(-std::sin(theta) * std::sin(phi), std::cos(theta), std::sin(theta) * std::cos(phi));
      }
  EXPECT_GT(glm::dot(best_dir, glm::normalize(glm::vec3(-0.45f, 0.75f, 0.5f))), 0.99f);
  double mean = environment_mean_luminance(t);
  EXPECT_GT(mean, 0.35);
  EXPECT_LT(mean, 0.7);
}

}  // namespace candela::test
