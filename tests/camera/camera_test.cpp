// Cameras and pixel filters:
//  - the filters' sampled offsets and the concentric disk follow their densities (chi-square);
//  - renders of a sharp emissive edge through the real kernels (PoCL, and rusticl when
//    installed): a thin lens keeps the focus plane as sharp as a pinhole and blurs a plane
//    behind it by the circle of confusion of the thin-lens formula; tent and Gaussian
//    filters blur the edge by their CDFs; an orthographic camera covers exactly the pixel
//    rectangle of a square at any distance;
//  - a zero aperture renders the pinhole image bit for bit;
//  - the glTF loader reads orthographic cameras and the thin-lens extras.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "base/error.hpp"
#include "compile/camera.hpp"
#include "gltf/gltf_loader.hpp"
#include "render/renderer.hpp"
#include "support/reference.hpp"
#include "support/scenes.hpp"
#include "support/stats.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

// ---- Sampled offsets -------------------------------------------------------------------

// n offsets (one per work-item) of test kernel `name`, its arguments `args` and then the output
template <typename... Args>
std::vector<cl_float2> run_offsets_kernel(const char* name, size_t n, const Args&... args) {
  const KernelRig& rig = kernel_rig("pocl");
  auto out = rig.output<cl_float2>(n);
  rig.run(name, n, args..., out);
  return out.read();
}

// CDFs of one coordinate of each filter's offset, in pixels
double box_cdf(double x) { return std::clamp(x + 0.5, 0.0, 1.0); }
double tent_cdf(double x) {
  if (x <= -1.0) return 0.0;
  if (x <= 0.0) return 0.5 * (x + 1.0) * (x + 1.0);
  if (x <= 1.0) return 1.0 - 0.5 * (1.0 - x) * (1.0 - x);
  return 1.0;
}
double gaussian_cdf(double x) { return 0.5 * std::erfc(-x / (0.5 * std::sqrt(2.0))); }

// Pearson's test of 2D offsets on a grid of `bins` x `bins` cells over [-extent, extent]^2
// plus open cells beyond it, against the product of the marginal CDFs (a separable density)
ChiSquare offsets_chi_square(const std::vector<cl_float2>& xy, const std::function<double(double)>& cdf, double extent,
                             int bins) {
  std::vector<double> edges = {-INFINITY};
  for (int i = 0; i <= bins; ++i) edges.push_back(-extent + 2.0 * extent * i / bins);
  edges.push_back(INFINITY);
  const int cells = int(edges.size()) - 1;
  auto cell = [&](double v) { return int(std::upper_bound(edges.begin(), edges.end(), v) - edges.begin()) - 1; };
  std::vector<double> observed(size_t(cells * cells), 0.0), expected(observed.size());
  for (const cl_float2& p : xy) observed[size_t(cell(p.s[1]) * cells + cell(p.s[0]))] += 1.0;
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i)
      expected[size_t(j * cells + i)] =
          double(xy.size()) * (cdf(edges[i + 1]) - cdf(edges[i])) * (cdf(edges[j + 1]) - cdf(edges[j]));
  return chi_square_test(observed, expected);
}

const size_t kOffsets = size_t(1) << 20;
const double kAlpha = sidak_alpha(0.01, 4);  // three filters and the disk

TEST(PixelFilter, SampledOffsetsFollowTheFilterDensity) {
  struct Case {
    PixelFilter filter;
    const char* name;
    std::function<double(double)> cdf;
    double extent, max_offset;
  };
  std::vector<Case> cases = {{PixelFilter::Box, "box", box_cdf, 0.5, 0.5},
                             {PixelFilter::Tent, "tent", tent_cdf, 1.0, 1.0},
                             {PixelFilter::Gaussian, "gaussian", gaussian_cdf, 1.5, 3.0}};
  for (const Case& c : cases) {
    auto xy = run_offsets_kernel("test_filter_offsets", kOffsets, cl_uint(c.filter), 7u);
    double max_abs = 0.0;
    for (const auto& p : xy) max_abs = std::max({max_abs, std::fabs(double(p.s[0])), std::fabs(double(p.s[1]))});
    EXPECT_LE(max_abs, c.max_offset) << c.name;
    ChiSquare chi = offsets_chi_square(xy, c.cdf, c.extent, 20);
    EXPECT_GT(chi.p_value, kAlpha) << c.name << ": chi2 " << chi.statistic << " dof " << chi.dof;
    if (c.filter == PixelFilter::Tent) {
      // The test has power: tent offsets are not Gaussian (sigma 0.41 vs 0.5)
      ChiSquare wrong = offsets_chi_square(xy, gaussian_cdf, 1.5, 20);
      EXPECT_LT(wrong.p_value, 1e-6) << "chi2 " << wrong.statistic << " dof " << wrong.dof;
    }
  }
}

TEST(PixelFilter, BoxIsTheDefault) { EXPECT_EQ(RenderSettings().filter, PixelFilter::Box); }

// Uniform on the unit disk: r^2 and the angle are independent and uniform
TEST(ThinLens, ConcentricDiskIsUniform) {
  auto xy = run_offsets_kernel("test_concentric_disk", kOffsets, 11u);
  const int nr = 16, nphi = 32;
  std::vector<double> observed(nr * nphi, 0.0), expected(nr * nphi, double(kOffsets) / (nr * nphi));
  for (const auto& p : xy) {
    double r2 = double(p.s[0]) * p.s[0] + double(p.s[1]) * p.s[1];
    ASSERT_LE(r2, 1.0 + 1e-6);
    double phi = std::atan2(double(p.s[1]), double(p.s[0])) + kPi;
    int i = std::min(nr - 1, int(r2 * nr)), j = std::min(nphi - 1, int(phi / (2.0 * kPi) * nphi));
    observed[size_t(j * nr + i)] += 1.0;
  }
  ChiSquare chi = chi_square_test(observed, expected);
  EXPECT_GT(chi.p_value, kAlpha) << "chi2 " << chi.statistic << " dof " << chi.dof;
}

// ---- Renders of a sharp edge -----------------------------------------------------------

MaterialDesc emitter(float radiance) {
  MaterialDesc m;
  m.type = MATERIAL_DIFFUSE;
  m.base_color = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  m.emission = glm::vec3(radiance);
  return m;
}

// Quad (x0, y0) - (x1, y1) at z = z, facing +z
void add_rect(Scene* s, float x0, float y0, float x1, float y1, float z, uint32_t material) {
  add_polygon(s, {{x0, y0, z}, {x1, y0, z}, {x1, y1, z}, {x0, y1, z}}, material);
}

// Emission seen directly (max depth 0) under a black background: every sample is 0 or 1
Film render(const DeviceEntry& device, const Scene& scene, int w, int h, uint32_t spp,
            PixelFilter filter = PixelFilter::Box, uint32_t seed = 1) {
  RenderSettings settings;
  settings.width = w;
  settings.height = h;
  settings.max_depth = 0;
  settings.filter = filter;
  settings.seed = seed;
  return scene_renderer(device, scene, settings).render(0, spp).film;
}

// The edge scene: a camera at the origin looking down -z with tan(yfov/2) = 1/8 on a
// 32 x 8 image, so a pixel spans depth/32 at any depth. A plane at `depth` emits 1 left
// of x = depth/64 and nothing right of it: the edge runs down the middle of column 16.
const int kEdgeW = 32, kEdgeH = 8;
const double kEdgeColumn = 16.5;  // the edge in continuous pixel coordinates
const double kTanY = 0.125;

Scene edge_scene(float depth) {
  Scene s;
  s.materials = {emitter(1.0f), emitter(0.0f)};
  float e = depth / 64.0f, big = 2.0f * depth;
  add_rect(&s, -big, -big, e, big, -depth, 0);
  add_rect(&s, e, -big, big, big, -depth, 1);
  CameraDesc cam;
  cam.yfov = float(2.0 * std::atan(kTanY));
  s.camera = cam;
  return s;
}

double pixel_size_at(double depth) { return 2.0 * kTanY * depth / kEdgeH; }

// Column means (all rows) with their standard errors
std::vector<Estimate> column_profile(const Film& f) {
  std::vector<Estimate> p;
  for (int x = 0; x < f.width; ++x) p.push_back(region_mean(f, 0, x, x + 1, 0, f.height));
  return p;
}

// Expected column values for samples spread uniformly over the pixel (the box filter)
// and then displaced horizontally by a random amount with CDF `disp_cdf` (in pixels):
// the column's mean of P(x + displacement < edge), x uniform over the column
std::vector<double> predicted_profile(const std::function<double(double)>& disp_cdf) {
  std::vector<double> p;
  const int steps = 4000;
  for (int c = 0; c < kEdgeW; ++c) {
    double sum = 0.0;
    for (int k = 0; k < steps; ++k) sum += disp_cdf(kEdgeColumn - (c + (k + 0.5) / steps));
    p.push_back(sum / steps);
  }
  return p;
}

// CDF of the x coordinate of a uniform point of a disk of radius rho (rho = 0: a step)
std::function<double(double)> disk_x_cdf(double rho) {
  return [rho](double x) {
    if (rho <= 0.0) return x > 0.0 ? 1.0 : 0.0;
    double s = std::clamp(x / rho, -1.0, 1.0);
    return 0.5 + (s * std::sqrt(1.0 - s * s) + std::asin(s)) / kPi;
  };
}

// Every column within 4 standard errors (plus the quadrature's 1e-4) of the prediction.
// Samples are 0 or 1, so a column of n samples with expected value p has the binomial
// standard error sqrt(p (1 - p) / n): that one, where the measured one is smaller, lets a
// column expecting a fraction of a sample hold none.
void expect_profile(const std::vector<Estimate>& got, const std::vector<double>& want, double samples,
                    const std::string& what) {
  for (int c = 0; c < kEdgeW; ++c) {
    double se = std::max(got[c].standard_error, std::sqrt(want[c] * (1.0 - want[c]) / samples));
    EXPECT_NEAR(got[c].mean, want[c], 4.0 * se + 1e-4) << what << ", column " << c << " (se " << se << ")";
  }
}

class CameraRenderTest : public ::testing::TestWithParam<std::string> {};

// A plane at the focus distance: the lens image equals the pinhole image (the edge stays
// within its one mixed column); a plane twice as far is blurred by the circle of
// confusion: lens radius A, focus D, depth z give a disk of radius A |1 - z/D| on the plane
TEST_P(CameraRenderTest, ThinLensKeepsTheFocusPlaneSharpAndBlursByTheCircleOfConfusion) {
  DeviceEntry device;
  CANDELA_DEVICE_OR_SKIP(GetParam(), device);
  const float depth = 4.0f, aperture = 0.5f;
  Scene scene = edge_scene(depth);
  auto pinhole = column_profile(render(device, scene, kEdgeW, kEdgeH, 64));
  expect_profile(pinhole, predicted_profile(disk_x_cdf(0.0)), kEdgeH * 64, "pinhole");

  scene.camera->aperture_radius = aperture;
  scene.camera->focus_distance = depth;
  auto focused = column_profile(render(device, scene, kEdgeW, kEdgeH, 256));
  expect_profile(focused, predicted_profile(disk_x_cdf(0.0)), kEdgeH * 256, "plane in focus");
  for (int c = 0; c < kEdgeW; ++c) {
    double se = std::hypot(pinhole[c].standard_error, focused[c].standard_error);
    EXPECT_NEAR(focused[c].mean, pinhole[c].mean, 4.0 * se + 1e-6) << "column " << c;
  }

  scene.camera->focus_distance = depth / 2.0f;
  double rho = aperture * std::fabs(1.0 - depth / (depth / 2.0)) / pixel_size_at(depth);  // 4 pixels
  auto blurred = column_profile(render(device, scene, kEdgeW, kEdgeH, 256));
  expect_profile(blurred, predicted_profile(disk_x_cdf(rho)), kEdgeH * 256, "plane behind the focus plane");
  // Two pixels left of the edge is a mix now, where the pinhole sees only the emitter
  EXPECT_EQ(pinhole[14].mean, 1.0);
  EXPECT_GT(blurred[14].mean, 0.6);
  EXPECT_LT(blurred[14].mean, 0.9);
  // and the blur ends where the circle of confusion does
  EXPECT_EQ(blurred[10].mean, 1.0);
  EXPECT_EQ(blurred[22].mean, 0.0);
}

// The rendered edge is the edge convolved with the filter: column c holds
// F(edge - (c + 1/2)), F the CDF of one coordinate of the filter's offset
TEST_P(CameraRenderTest, FilteredEdgeProfileIsTheFilterCdf) {
  DeviceEntry device;
  CANDELA_DEVICE_OR_SKIP(GetParam(), device);
  Scene scene = edge_scene(1.0f);
  for (auto [filter, cdf] : {std::pair<PixelFilter, double (*)(double)>{PixelFilter::Tent, tent_cdf},
                             {PixelFilter::Gaussian, gaussian_cdf}}) {
    auto got = column_profile(render(device, scene, kEdgeW, kEdgeH, 256, filter));
    std::vector<double> want;
    for (int c = 0; c < kEdgeW; ++c) want.push_back(cdf(kEdgeColumn - (c + 0.5)));
    expect_profile(got, want, kEdgeH * 256, filter == PixelFilter::Tent ? "tent" : "gaussian");
    // The tent reaches one pixel, so only the edge's column is mixed (the centres of its
    // neighbours lie one pixel from the edge); the Gaussian reaches the neighbours
    if (filter == PixelFilter::Tent) {
      EXPECT_EQ(got[15].mean, 1.0);
      EXPECT_EQ(got[17].mean, 0.0);
    } else {
      EXPECT_LT(got[15].mean, 1.0);
      EXPECT_GT(got[17].mean, 0.0);
    }
  }
}

// An emissive rectangle seen by an orthographic camera (ymag 1, 48 x 32 pixels: xmag 1.5,
// pixels 1/16 wide) covers its pixel rectangle: each pixel holds its covered fraction,
// whatever the distance
TEST_P(CameraRenderTest, OrthographicCameraCoversTheExpectedPixelsAtAnyDistance) {
  DeviceEntry device;
  CANDELA_DEVICE_OR_SKIP(GetParam(), device);
  const int w = 48, h = 32;
  const double x0 = -0.53, x1 = 0.71, y0 = -0.29, y1 = 0.6, pixel = 1.0 / 16.0;
  auto overlap = [](double a0, double a1, double b0, double b1) {
    return std::max(0.0, std::min(a1, b1) - std::max(a0, b0));
  };
  for (float distance : {0.5f, 40.0f}) {
    Scene s;
    s.materials = {emitter(1.0f)};
    add_rect(&s, float(x0), float(y0), float(x1), float(y1), -distance, 0);
    CameraDesc cam;
    cam.projection = Projection::Orthographic;
    cam.ymag = 1.0f;
    s.camera = cam;
    Film f = render(device, s, w, h, 64);
    double covered = 0.0, var = 0.0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        double px0 = -1.5 + x * pixel, py1 = 1.0 - y * pixel;
        double want = overlap(px0, px0 + pixel, x0, x1) * overlap(py1 - pixel, py1, y0, y1) / (pixel * pixel);
        size_t i = size_t(y) * w + x;
        double se = std::sqrt(f.variance_of_mean(i).x);
        EXPECT_NEAR(f.pixel(i).x, want, 4.5 * se + 1e-6) << "distance " << distance << ", pixel " << x << "," << y;
        covered += f.pixel(i).x * pixel * pixel;
        var += f.variance_of_mean(i).x * pixel * pixel * pixel * pixel;
      }
    EXPECT_NEAR(covered, (x1 - x0) * (y1 - y0), 4.0 * std::sqrt(var) + 1e-9) << "distance " << distance;
  }
}

INSTANTIATE_TEST_SUITE_P(Devices, CameraRenderTest, kernel_devices(), DeviceParamName());

// The CPU packets' eight pinhole rays at once (camera_rays8) are camera_ray's, lane for
// lane and bit for bit: random film positions (some past the image's edges, where the tent
// and Gaussian filters reach) of a tilted camera, square and wide images
class CameraRays8Test : public DeviceTest {};

TEST_P(CameraRays8Test, EightLaneRaysAreTheScalarRays) {
  CameraDesc cam;
  cam.position = glm::vec3(0.3f, -1.2f, 4.5f);
  cam.forward = glm::vec3(-0.2f, 0.35f, -1.0f);
  cam.up = glm::vec3(0.1f, 1.0f, 0.0f);
  cam.yfov = 0.9f;
  uint64_t state = 12345;
  auto uniform = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return float(state >> 40) * 0x1.0p-24f;
  };
  for (auto [w, h] : {std::pair{37, 23}, std::pair{512, 512}, std::pair{1920, 817}}) {
    dev::RenderParams params{};
    params.camera = make_device_camera(cam, w, h);
    params.width = cl_uint(w);
    params.height = cl_uint(h);
    const size_t groups = 4096;
    std::vector<cl_float2> film(8 * groups);
    for (cl_float2& f : film) f = {{(uniform() * 1.1f - 0.05f) * float(w), (uniform() * 1.1f - 0.05f) * float(h)}};
    auto out = rig().output<cl_uint>(groups);
    rig().run("test_camera_rays8", groups, rig().input(std::vector<dev::RenderParams>{params}), rig().input(film), out);
    std::vector<cl_uint> same = out.read();
    EXPECT_EQ(std::count(same.begin(), same.end(), 1u), long(groups)) << w << "x" << h;
  }
}

INSTANTIATE_TEST_SUITE_P(Devices, CameraRays8Test, kernel_devices(), DeviceParamName());

// A thin lens of radius 0 is the pinhole camera, bit for bit; any aperture changes the image
TEST(ThinLens, ZeroApertureIsThePinholeImage) {
  Scene scene = load_gltf(scene_path("cornell-box/cornell-box.gltf"));
  Film pinhole = render(pocl_device(), scene, 16, 16, 8);
  scene.camera->aperture_radius = 0.0f;
  scene.camera->focus_distance = 0.37f;
  Film lens0 = render(pocl_device(), scene, 16, 16, 8);
  EXPECT_EQ(pinhole.mean, lens0.mean);
  EXPECT_EQ(pinhole.m2, lens0.m2);
  scene.camera->aperture_radius = 0.01f;
  Film lens = render(pocl_device(), scene, 16, 16, 8);
  EXPECT_NE(pinhole.mean, lens.mean);
}

TEST(ThinLens, DefaultFocusIsTheBoundsCentreAlongTheViewAxis) {
  Scene scene = edge_scene(4.0f);
  scene.camera->aperture_radius = 0.1f;
  CameraDesc cam = resolve_camera(scene);
  ASSERT_TRUE(cam.focus_distance.has_value());
  EXPECT_NEAR(*cam.focus_distance, 4.0f, 1e-6f);
  scene.camera->projection = Projection::Orthographic;
  EXPECT_THROW(resolve_camera(scene), Error) << "an orthographic camera has no lens";
  scene.camera->projection = Projection::Perspective;
  scene.camera->aperture_radius = -0.1f;
  EXPECT_THROW(resolve_camera(scene), Error);
}

// ---- glTF ------------------------------------------------------------------------------

std::string write_camera_scene(const std::string& name, const nlohmann::json& camera) {
  GltfBuilder g;
  g.add_node({{"mesh", g.add_mesh({quad_primitive({{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, -1)})}});
  int c = g.add("cameras", camera);
  g.add_node({{"camera", c}, {"translation", {0.0, 0.0, 3.0}}});
  std::string path = ::testing::TempDir() + name;
  g.write(path);
  return path;
}

TEST(GltfCamera, OrthographicCameraIsRead) {
  Scene s = load_gltf(write_camera_scene(
      "ortho.gltf",
      {{"type", "orthographic"}, {"orthographic", {{"xmag", 3.0}, {"ymag", 1.5}, {"znear", 0.1}, {"zfar", 10.0}}}}));
  ASSERT_TRUE(s.camera.has_value());
  EXPECT_EQ(s.camera->projection, Projection::Orthographic);
  EXPECT_FLOAT_EQ(s.camera->ymag, 1.5f);
  EXPECT_FLOAT_EQ(s.camera->aspect, 2.0f) << "the image aspect comes from xmag / ymag";
  EXPECT_NEAR(s.camera->position.z, 3.0f, 1e-6f);
  for (const auto& w : s.warnings) EXPECT_EQ(w.find("camera"), std::string::npos) << w;
  // The device camera spans ymag vertically and ymag * width / height horizontally
  dev::Camera d = make_device_camera(*s.camera, 40, 20);
  EXPECT_EQ(d.type, CAMERA_ORTHOGRAPHIC);
  EXPECT_NEAR(d.up[1], 1.5f, 1e-6f);
  EXPECT_NEAR(d.right[0], 3.0f, 1e-6f);
  EXPECT_EQ(d.lens_radius, 0.0f);
}

TEST(GltfCamera, ThinLensExtrasAreRead) {
  nlohmann::json cam = {{"type", "perspective"},
                        {"perspective", {{"yfov", 0.5}, {"znear", 0.01}}},
                        {"extras", {{"candela", {{"aperture_radius", 0.05}, {"focus_distance", 2.5}}}}}};
  Scene s = load_gltf(write_camera_scene("lens.gltf", cam));
  ASSERT_TRUE(s.camera.has_value());
  EXPECT_FLOAT_EQ(s.camera->aperture_radius, 0.05f);
  ASSERT_TRUE(s.camera->focus_distance.has_value());
  EXPECT_FLOAT_EQ(*s.camera->focus_distance, 2.5f);
  dev::Camera d = make_device_camera(resolve_camera(s), 8, 8);
  EXPECT_EQ(d.type, CAMERA_PERSPECTIVE);
  EXPECT_FLOAT_EQ(d.lens_radius, 0.05f);
  EXPECT_FLOAT_EQ(d.focus_distance, 2.5f);

  auto bad = [&](const char* name, nlohmann::json c) {
    EXPECT_THROW(load_gltf(write_camera_scene(name, c)), Error) << name;
  };
  nlohmann::json negative = cam;
  negative["extras"]["candela"]["aperture_radius"] = -0.1;
  bad("negative-aperture.gltf", negative);
  nlohmann::json zero_focus = cam;
  zero_focus["extras"]["candela"]["focus_distance"] = 0.0;
  bad("zero-focus.gltf", zero_focus);
  nlohmann::json text = cam;
  text["extras"]["candela"]["focus_distance"] = "far";
  bad("text-focus.gltf", text);
  bad("ortho-lens.gltf", {{"type", "orthographic"},
                          {"orthographic", {{"xmag", 1.0}, {"ymag", 1.0}, {"znear", 0.1}, {"zfar", 10.0}}},
                          {"extras", {{"candela", {{"aperture_radius", 0.05}}}}}});
}

}  // namespace
}  // namespace candela::test
