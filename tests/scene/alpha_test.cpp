// glTF alphaMode and texture filtering on the real kernel code:
//  - ray queries against a card with a checker alpha texture (MASK cuts out exactly where
//    alpha < alphaCutoff, OPAQUE ignores alpha, BLEND stops a ray with probability alpha)
//    and closest hits agreeing with shadow rays, ray by ray;
//  - renders: camera rays see through holes, BLEND at alpha 0.5 shows half the background,
//    a masked card casts half an opaque card's shadow (mirror symmetry), NEE and BSDF
//    sampling agree on a scene with a masked light and a masked occluder;
//  - NEAREST lookups return texel values exactly where bilinear ones blend.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <random>

#include "render/renderer.hpp"
#include "support/scenes.hpp"
#include "support/stats.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

// Quad p0 p1 p2 p3 (counter-clockwise seen from its front), TEXCOORD_0 (0,1) (1,1) (1,0)
// (0,0) at its corners as in quad_primitive: u runs from p0 to p1, v from p3 to p0
void add_quad(Scene* s, glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3 p3, uint32_t material) {
  MeshDesc m;
  m.positions = {p0, p1, p2, p3};
  m.uv0 = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  m.indices = {0, 1, 2, 0, 2, 3};
  m.material = material;
  s->meshes.push_back(m);
}

MaterialDesc diffuse(float albedo) {
  MaterialDesc m;
  m.type = MATERIAL_DIFFUSE;
  m.base_color = glm::vec4(albedo, albedo, albedo, 1.0f);
  return m;
}

// 2x2 RGBA8 checker: white, alpha 255 at texels (0,0) and (1,1), 0 at the other two (or
// the reverse); linear, nearest lookups, clamped
TextureDesc checker(bool inverted = false) {
  TextureDesc t;
  t.width = t.height = 2;
  t.wrap_s = t.wrap_t = WRAP_CLAMP;
  t.nearest = true;
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 2; ++x) {
      bool opaque = ((x + y) % 2 == 0) != inverted;
      t.rgba8.insert(t.rgba8.end(), {255, 255, 255, uint8_t(opaque ? 255 : 0)});
    }
  return t;
}

// A material of `mode` whose alpha is `alpha` times the checker texture's (texture 0) or,
// untextured, `alpha` alone
MaterialDesc card(AlphaMode mode, float alpha, bool textured, float albedo = 0.0f) {
  MaterialDesc m = diffuse(albedo);
  m.alpha_mode = mode;
  m.base_color.a = alpha;
  if (textured) m.textures[TEX_BASE_COLOR].index = 0;
  return m;
}

// ---------------------------------------------------------------------------------------
// Ray queries: a card z = 0, |x|, |y| <= 1 (prims 0 and 1) in front of a wall z = -1
// (prims 2 and 3); rays from z = 1 straight down -z

Scene card_scene(const MaterialDesc& card_material) {
  Scene s;
  s.materials = {card_material, diffuse(0.5f)};
  s.textures = {checker()};
  add_quad(&s, {-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, 0);
  add_quad(&s, {-2, -2, -1}, {2, -2, -1}, {2, 2, -1}, {-2, 2, -1}, 1);
  return s;
}

// The checker at card point (x, y): u = (x + 1) / 2, v = (1 - y) / 2 pick the texel
bool checker_opaque(double x, double y) {
  int col = x >= 0.0 ? 1 : 0, row = y <= 0.0 ? 1 : 0;
  return (col + row) % 2 == 0;
}

struct Traced {
  std::vector<cl_float4> hits;  // (t, b1, b2, prim)
  std::vector<cl_int> occluded;
  bool on_card(size_t i) const { return hits[i].s[3] >= 0.0f && hits[i].s[3] < 2.0f; }
  bool on_wall(size_t i) const { return hits[i].s[3] >= 2.0f; }
};

// Rays from (x, y, 1) along -z with tmax, through test_alpha_trace
Traced trace(const KernelRig& rig, const Scene& scene, const std::vector<glm::vec2>& points, float tmax) {
  CompiledScene compiled = compile_scene(scene);
  SceneOnDevice on_device(rig, compiled);
  std::vector<cl_float4> rays;
  for (const glm::vec2& p : points) {
    rays.push_back({{p.x, p.y, 1.0f, tmax}});
    rays.push_back({{0.0f, 0.0f, -1.0f, 0.0f}});
  }
  size_t n = points.size();
  auto hits = rig.output<cl_float4>(n);
  auto occluded = rig.output<cl_int>(n);
  rig.run("test_alpha_trace", n, on_device, rig.input(rays), hits, occluded);
  return {hits.read(), occluded.read()};
}

// Random points of the card away from the checker's cell borders and the card's edges
std::vector<glm::vec2> card_points(size_t n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.98f, 0.98f);
  std::vector<glm::vec2> p;
  while (p.size() < n) {
    glm::vec2 q(u(rng), u(rng));
    if (std::fabs(q.x) > 0.02f && std::fabs(q.y) > 0.02f) p.push_back(q);
  }
  return p;
}

class AlphaTraceTest : public DeviceTest {
 protected:
  // Closest hits over the whole ray, and shadow rays that end between card and wall
  // agreeing with closest hits over the same span, ray by ray
  Traced trace_checked(const Scene& s, const std::vector<glm::vec2>& points) {
    Traced full = trace(rig(), s, points, 10.0f);
    Traced half = trace(rig(), s, points, 1.5f);
    for (size_t i = 0; i < points.size(); ++i) {
      EXPECT_TRUE(full.on_card(i) || full.on_wall(i)) << "ray " << i;
      EXPECT_EQ(full.occluded[i], 1);
      EXPECT_EQ(half.on_card(i), full.on_card(i)) << "ray " << i;
      EXPECT_EQ(half.occluded[i] != 0, half.on_card(i)) << "shadow ray and closest hit disagree, ray " << i;
      EXPECT_NEAR(full.hits[i].s[0], full.on_card(i) ? 1.0f : 2.0f, 1e-5f);
    }
    return full;
  }
};

TEST_P(AlphaTraceTest, MaskCutsOutExactlyWhereAlphaIsBelowTheCutoff) {
  std::vector<glm::vec2> points = card_points(2048);
  Traced t = trace_checked(card_scene(card(AlphaMode::Mask, 1.0f, true)), points);
  for (size_t i = 0; i < points.size(); ++i)
    EXPECT_EQ(t.on_card(i), checker_opaque(points[i].x, points[i].y)) << points[i].x << ", " << points[i].y;
  // Factor alpha 0.4 below the cutoff 0.5 cuts the whole card; cutoff 0.3 keeps the opaque cells
  Traced none = trace_checked(card_scene(card(AlphaMode::Mask, 0.4f, true)), points);
  MaterialDesc low_cutoff = card(AlphaMode::Mask, 0.4f, true);
  low_cutoff.alpha_cutoff = 0.3f;
  Traced kept = trace_checked(card_scene(low_cutoff), points);
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_TRUE(none.on_wall(i));
    EXPECT_EQ(kept.on_card(i), checker_opaque(points[i].x, points[i].y));
  }
}

TEST_P(AlphaTraceTest, OpaqueIgnoresAlpha) {
  std::vector<glm::vec2> points = card_points(512);
  Traced t = trace_checked(card_scene(card(AlphaMode::Opaque, 0.0f, true)), points);
  for (size_t i = 0; i < points.size(); ++i) EXPECT_TRUE(t.on_card(i));
}

// Each ray stops at a BLEND card of alpha 0.5 with probability 0.5, whatever the ray
// (binomial, within 4 standard deviations), the same way on every query; alpha 0 and 1
// texels of a textured BLEND card always pass and always stop
TEST_P(AlphaTraceTest, BlendStopsARayWithProbabilityAlpha) {
  std::vector<glm::vec2> points = card_points(8192);
  Traced t = trace_checked(card_scene(card(AlphaMode::Blend, 0.5f, false)), points);
  size_t stopped = 0;
  for (size_t i = 0; i < points.size(); ++i) stopped += t.on_card(i);
  double n = double(points.size());
  EXPECT_NEAR(stopped / n, 0.5, 4.0 * std::sqrt(0.25 / n));
  Traced again = trace(rig(), card_scene(card(AlphaMode::Blend, 0.5f, false)), points, 10.0f);
  for (size_t i = 0; i < points.size(); ++i) ASSERT_EQ(again.on_card(i), t.on_card(i)) << "ray " << i;

  Traced textured = trace_checked(card_scene(card(AlphaMode::Blend, 1.0f, true)), points);
  for (size_t i = 0; i < points.size(); ++i) EXPECT_EQ(textured.on_card(i), checker_opaque(points[i].x, points[i].y));
}

// The stochastic test's random numbers over rays differing only in the last bits of
// their directions are uniform: chi-square over 64 cells
TEST_P(AlphaTraceTest, StochasticOpacityNumbersAreUniform) {
  const size_t n = 1 << 16;
  std::vector<cl_float4> dirs(n);
  for (size_t i = 0; i < n; ++i) {
    float dx = 1e-6f * float(i % 256), dy = 1e-6f * float(i / 256);
    dirs[i] = {{dx, dy, -1.0f, 0.0f}};
  }
  auto out = rig().output<float>(n);
  rig().run("test_alpha_random", n, cl_uint(3), f4({0.25, 0.5, 1.0}), rig().input(dirs), out);
  std::vector<float> u = out.read();
  const int cells = 64;
  std::vector<double> observed(cells, 0.0), expected(cells, double(n) / cells);
  for (float x : u) {
    ASSERT_TRUE(x >= 0.0f && x < 1.0f);
    observed[std::min(int(x * cells), cells - 1)] += 1.0;
  }
  EXPECT_GT(chi_square_test(observed, expected).p_value, 0.001);
}

INSTANTIATE_TEST_SUITE_P(Devices, AlphaTraceTest, kernel_devices(), DeviceParamName());

// ---------------------------------------------------------------------------------------
// Renders on PoCL

// Green channel over pixels [x0,x1) x [y0,y1), and over the image, with its standard error
Estimate green_mean(const Film& f, int x0, int x1, int y0, int y1) { return region_mean(f, 1, x0, x1, y0, y1); }
Estimate green_mean(const Film& f) { return region_mean(f, 1, 0, f.width, 0, f.height); }

double z_score(const Estimate& a, const Estimate& b) {
  return (a.mean - b.mean) / std::sqrt(a.standard_error * a.standard_error + b.standard_error * b.standard_error);
}

// A black card z = 0, |x|, |y| <= 1, filling the view of a camera at z = 2, before a
// background of radiance 1: every sample is 1 (through the card) or 0 (on it)
Scene window_scene(const MaterialDesc& card_material) {
  Scene s;
  s.materials = {card_material};
  s.textures = {checker()};
  s.background = glm::vec3(1.0f);
  add_quad(&s, {-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, 0);
  CameraDesc cam;
  cam.position = {0, 0, 2};
  cam.forward = {0, 0, -1};
  cam.yfov = 0.5f;
  s.camera = cam;
  return s;
}

// Screen right is +x and up +y: the top-left and bottom-right quadrants see opaque cells.
// Pixels wholly inside a quadrant are exact; by the checker's mirror symmetry half the
// view is hole, so the image mean is 1/2 within its standard error.
TEST(AlphaRender, CameraRaysSeeThroughMaskHoles) {
  Film f = render_film(window_scene(card(AlphaMode::Mask, 1.0f, true)), Strategy::Nee, 16, 16, 32, 4, 1);
  for (int y : {1, 3, 6})
    for (int x : {1, 3, 6}) {
      EXPECT_EQ(f.pixel(size_t(y) * 16 + x).y, 0.0f) << "top-left " << x << "," << y;
      EXPECT_EQ(f.pixel(size_t(y) * 16 + 15 - x).y, 1.0f) << "top-right " << x << "," << y;
      EXPECT_EQ(f.pixel(size_t(15 - y) * 16 + x).y, 1.0f) << "bottom-left " << x << "," << y;
      EXPECT_EQ(f.pixel(size_t(15 - y) * 16 + 15 - x).y, 0.0f) << "bottom-right " << x << "," << y;
    }
  Estimate e = green_mean(f);
  EXPECT_NEAR(e.mean, 0.5, 4.0 * e.standard_error + 1e-6);
  // OPAQUE ignores alpha: the same card, factor alpha 0 and the checker, hides everything
  Film opaque = render_film(window_scene(card(AlphaMode::Opaque, 0.0f, true)), Strategy::Nee, 16, 16, 8, 4, 1);
  for (size_t i = 0; i < opaque.pixels(); ++i) ASSERT_EQ(opaque.pixel(i).y, 0.0f) << "pixel " << i;
}

// BLEND at alpha 0.5: every pixel shows half the background, within its standard error
TEST(AlphaRender, BlendAtHalfAlphaTransmitsHalfTheBackground) {
  Film f = render_film(window_scene(card(AlphaMode::Blend, 0.5f, false)), Strategy::Nee, 16, 16, 64, 4, 3);
  Estimate e = green_mean(f);
  EXPECT_NEAR(e.mean, 0.5, 4.0 * e.standard_error);
  EXPECT_LT(e.standard_error, 0.01);
  for (int by = 0; by < 16; by += 4)
    for (int bx = 0; bx < 16; bx += 4) {
      Estimate b = green_mean(f, bx, bx + 4, by, by + 4);
      EXPECT_NEAR(b.mean, 0.5, 4.5 * b.standard_error) << "block " << bx << "," << by;
    }
}

// A floor lit by a square light above it, a black card halfway between, and a camera
// under the card looking down; the whole set-up is symmetric under x -> -x
enum class Card { None, Opaque, Mask, MaskInverted, Blend };

Scene shadow_scene(Card kind) {
  Scene s;
  MaterialDesc light = diffuse(0.0f);
  light.emission = glm::vec3(5.0f);
  s.materials = {diffuse(0.8f), light};
  s.textures = {checker(kind == Card::MaskInverted)};
  add_quad(&s, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}, 0);  // floor, facing +y
  const float l = 0.3f, c = 0.4f;
  add_quad(&s, {-l, 1, -l}, {l, 1, -l}, {l, 1, l}, {-l, 1, l}, 1);  // light, facing -y
  switch (kind) {
    case Card::None:
      break;
    case Card::Opaque:  // alpha 0 and a checker, ignored
      s.materials.push_back(card(AlphaMode::Opaque, 0.0f, true));
      break;
    case Card::Mask:
    case Card::MaskInverted:
      s.materials.push_back(card(AlphaMode::Mask, 1.0f, true));
      break;
    case Card::Blend:
      s.materials.push_back(card(AlphaMode::Blend, 0.5f, false));
      break;
  }
  if (kind != Card::None) add_quad(&s, {-c, 0.5f, -c}, {c, 0.5f, -c}, {c, 0.5f, c}, {-c, 0.5f, c}, 2);
  CameraDesc cam;
  cam.position = {0, 0.3f, 0};
  cam.forward = {0, -1, 0};
  cam.up = {0, 0, 1};
  cam.yfov = 2.0f;
  s.camera = cam;
  return s;
}

// Direct light only (max depth 1) is linear in each shadow ray's visibility. The checker
// and its inverse partition the card, so their shadows sum to no card plus the opaque
// card; the mirror swaps them, so each is the mean of the two. BLEND at 0.5 lets half
// the shadow rays through: the same mean.
TEST(AlphaRender, MaskedAndBlendedCardsCastHalfTheShadow) {
  const int size = 24;
  const uint32_t spp = 64;
  Estimate none = green_mean(render_film(shadow_scene(Card::None), Strategy::Nee, size, size, spp, 1, 1));
  Estimate full = green_mean(render_film(shadow_scene(Card::Opaque), Strategy::Nee, size, size, spp, 1, 2));
  Estimate mask = green_mean(render_film(shadow_scene(Card::Mask), Strategy::Nee, size, size, spp, 1, 3));
  Estimate inverted = green_mean(render_film(shadow_scene(Card::MaskInverted), Strategy::Nee, size, size, spp, 1, 4));
  Estimate blend = green_mean(render_film(shadow_scene(Card::Blend), Strategy::Nee, size, size, spp, 1, 5));
  EXPECT_LT(full.mean, 0.7 * none.mean) << "the card must cast a clear shadow";
  Estimate half{0.5 * (none.mean + full.mean),
                0.5 * std::sqrt(none.standard_error * none.standard_error + full.standard_error * full.standard_error)};
  EXPECT_LT(std::fabs(z_score(mask, half)), 4.0) << "mask " << mask.mean << " expected " << half.mean;
  EXPECT_LT(std::fabs(z_score(inverted, half)), 4.0) << "inverted " << inverted.mean << " expected " << half.mean;
  EXPECT_LT(std::fabs(z_score(blend, half)), 4.0) << "blend " << blend.mean << " expected " << half.mean;
  EXPECT_LT(half.standard_error, 0.02 * half.mean);
}

// A masked light (emissive, checker alpha) above a floor, a masked occluder between, through
// the glTF loader (alphaMode MASK, sampler NEAREST): light sampling must find the light's
// holes dark as BSDF-sampled rays do (they pass through them), block by block
TEST(AlphaRender, StrategiesAgreeOnAMaskedScene) {
  std::string dir = ::testing::TempDir();
  unsigned char px[16] = {255, 255, 255, 255, 255, 255, 255, 0, 255, 255, 255, 0, 255, 255, 255, 255};
  auto out = OIIO::ImageOutput::create(dir + "alpha-checker.png");
  ASSERT_TRUE(out && out->open(dir + "alpha-checker.png", OIIO::ImageSpec(2, 2, 4, OIIO::TypeDesc::UINT8)));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, px));
  out->close();
  // The light (material 1) masked by the checker, and an occluder of material 2
  GltfBuilder g = floor_under_square_light(1.0f, 0.3f, 6, {quad_facing_up(0.3f, 0.5f, 2)});
  g.doc["materials"][1]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
  g.doc["materials"][1]["alphaMode"] = "MASK";
  g.add("materials", nlohmann::json::parse(R"(
    {"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0,
                              "baseColorTexture": {"index": 0}},
     "alphaMode": "MASK", "alphaCutoff": 0.25, "doubleSided": true})"));
  g.add("images", {{"uri", "alpha-checker.png"}});
  g.add("samplers", {{"magFilter", 9728}, {"wrapS", 33071}, {"wrapT", 33071}});
  g.add("textures", {{"source", 0}, {"sampler", 0}});
  g.add_camera({0.0f, 0.35f, 0.01f}, {0, 0, 0}, 1.8f);
  Scene scene = load_scene(g, "alpha-masked.gltf");
  ASSERT_EQ(scene.materials[1].alpha_mode, AlphaMode::Mask);
  ASSERT_TRUE(scene.textures.at(0).nearest);
  ASSERT_TRUE(scene.features().alpha);
  const int size = 16;
  Film nee = render_film(scene, Strategy::Nee, size, size, 256, 3, 1);
  Film bsdf = render_film(scene, Strategy::Bsdf, size, size, 2048, 3, 2);
  double chi2 = 0.0;
  int blocks = 0;
  for (int by = 0; by < size; by += 4)
    for (int bx = 0; bx < size; bx += 4) {
      double z = z_score(green_mean(nee, bx, bx + 4, by, by + 4), green_mean(bsdf, bx, bx + 4, by, by + 4));
      EXPECT_LT(std::fabs(z), 4.5) << "block " << bx << "," << by;
      chi2 += z * z;
      ++blocks;
    }
  EXPECT_LT(chi2, blocks + 5.0 * std::sqrt(2.0 * blocks));
  Estimate e = green_mean(nee);
  EXPECT_GT(e.mean, 0.05);
  EXPECT_LT(green_mean(bsdf).standard_error, 0.05 * e.mean);
}

// ---------------------------------------------------------------------------------------
// Texture filtering

// 2x1 texture, texels (0.2, 0.4, 0.6, 1) and (1, 0.8, 0, 0.5), linear RGBA8, repeating
TEST(Textures, NearestLookupReturnsExactTexelsWhereBilinearBlends) {
  const KernelRig& rig = kernel_rig("pocl");
  Scene s;
  TextureDesc t;
  t.width = 2;
  t.height = 1;
  t.rgba8 = {51, 102, 153, 255, 255, 204, 0, 128};
  s.textures = {t, t};
  s.textures[1].nearest = true;
  s.materials = {diffuse(1.0f), diffuse(1.0f)};
  s.materials[0].textures[TEX_BASE_COLOR].index = 0;
  s.materials[1].textures[TEX_BASE_COLOR].index = 1;
  add_quad(&s, {-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, 0);
  CompiledScene compiled = compile_scene(s);
  ASSERT_EQ(compiled.buffers.textures[1].flags & TEXTURE_NEAREST, TEXTURE_NEAREST);
  SceneOnDevice on_device(rig, compiled);
  // Texel centres, points between them, and points beyond [0, 1) that repeat
  std::vector<cl_float2> uvs = {{{0.25f, 0.5f}}, {{0.75f, 0.5f}}, {{0.4f, 0.3f}},  {{0.6f, 0.9f}},
                                {{0.05f, 0.1f}}, {{0.95f, 0.5f}}, {{1.3f, -0.2f}}, {{-0.3f, 2.7f}}};
  auto lookup = [&](uint32_t material) {
    auto out = rig.output<cl_float4>(uvs.size());
    rig.run("test_alpha_texture_lookup", uvs.size(), on_device, cl_uint(material), rig.input(uvs), out);
    return out.read();
  };
  std::vector<cl_float4> bilinear = lookup(0), nearest = lookup(1);
  const float texel[2][4] = {{0.2f, 0.4f, 0.6f, 1.0f}, {1.0f, 0.8f, 0.0f, 128 / 255.0f}};
  for (size_t i = 0; i < uvs.size(); ++i) {
    float u = uvs[i].s[0] - std::floor(uvs[i].s[0]);
    int x = u < 0.5f ? 0 : 1;
    for (int c = 0; c < 4; ++c) {
      EXPECT_FLOAT_EQ(nearest[i].s[c], texel[x][c]) << "uv " << i << " channel " << c;
      // Bilinear: weight of texel 1 is the distance from the left texel centre, repeating
      float w = u - 0.25f;
      if (w < 0.0f) w += 1.0f;
      float a = w <= 0.5f ? w / 0.5f : (1.0f - w) / 0.5f;
      float expect = (1.0f - a) * texel[0][c] + a * texel[1][c];
      EXPECT_NEAR(bilinear[i].s[c], expect, 1e-5f) << "uv " << i << " channel " << c;
    }
  }
  // Between the centres bilinear blends where nearest does not
  EXPECT_GT(std::fabs(bilinear[2].s[0] - nearest[2].s[0]), 0.1f);
}

}  // namespace
}  // namespace candela::test
