// glTF loading: transforms, winding, materials, textures, cameras, errors and warnings.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "base/error.hpp"
#include "gltf/gltf_loader.hpp"
#include "render/renderer.hpp"
#include "support/test_support.hpp"

namespace fs = std::filesystem;
using nlohmann::json;

namespace candela::test {
namespace {

// A quad (two triangles, z = 0, facing +z, UVs with v down) with material 0
GltfBuilder::Primitive quad() { return quad_primitive({{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, 0); }

// A glTF with the primitive (accessors: 0 POSITION, 1 TEXCOORD_0, 2 indices) as mesh 0 in
// node 0, and a grey Lambertian material 0 (no specular layer)
GltfBuilder quad_gltf(const GltfBuilder::Primitive& prim = quad()) {
  GltfBuilder g;
  g.add("materials", {{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.5, 0.5, 1}}, {"metallicFactor", 0}}},
                      {"extensions", {{"KHR_materials_specular", {{"specularFactor", 0}}}}}});
  g.add_node({{"mesh", g.add_mesh({prim})}});
  return g;
}

class TempDir {
 public:
  TempDir() {
    path = fs::temp_directory_path() /
           ("candela-gltf-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter_++));
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  std::string write(const std::string& name, const std::string& text) const {
    std::string p = (path / name).string();
    std::ofstream(p) << text;
    return p;
  }
  fs::path path;

 private:
  static inline int counter_ = 0;
};

// One triangle of a loaded scene, its vertex attributes gathered from its mesh
struct Tri {
  glm::vec3 p[3];
  glm::vec3 color[3];
};

std::vector<Tri> triangles_of(const Scene& s) {
  std::vector<Tri> out;
  for (const MeshDesc& m : s.meshes)
    for (size_t t = 0; t < m.triangles(); ++t) {
      Tri tri;
      for (int k = 0; k < 3; ++k) {
        uint32_t v = m.indices[3 * t + k];
        tri.p[k] = m.positions[v];
        tri.color[k] = m.colors.empty() ? glm::vec3(1.0f) : m.colors[v];
      }
      out.push_back(tri);
    }
  return out;
}

glm::vec3 winding_normal(const Tri& t) { return glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]); }

std::string join(const std::vector<std::string>& lines) {
  std::string all;
  for (const auto& l : lines) all += l + "\n";
  return all;
}

}  // namespace

TEST(GltfLoader, CornellBoxHasPublishedLightCameraAndSize) {
  Scene s = load_gltf(scene_path("cornell-box/cornell-box.gltf"));
  EXPECT_EQ(s.triangles(), 32u);
  ASSERT_TRUE(s.camera.has_value());
  EXPECT_NEAR(s.camera->position.z, -0.8f, 1e-6f);
  EXPECT_NEAR(s.camera->forward.z, 1.0f, 1e-6f);
  EXPECT_NEAR(s.camera->yfov, 2.0 * std::atan(12.5 / 35.0), 1e-6);
  bool found_light = false;
  for (const auto& m : s.materials)
    if (m.emission[0] > 0) {
      found_light = true;
      EXPECT_FLOAT_EQ(m.emission[0], 17.0f);
      EXPECT_NEAR(m.emission[1], 12.0f, 1e-5f);
      EXPECT_NEAR(m.emission[2], 4.0f, 1e-5f);
      EXPECT_FALSE(m.double_sided);
    }
  EXPECT_TRUE(found_light);
  Bounds b = s.bounds();
  EXPECT_NEAR(b.hi.x, 0.556f, 1e-5f);
  EXPECT_NEAR(b.hi.y, 0.5488f, 1e-5f);
  EXPECT_NEAR(b.hi.z, 0.5592f, 1e-5f);
}

TEST(GltfLoader, NodeHierarchyTransformsApply) {
  Scene s = load_gltf(scene_path("furnace/white-objects.gltf"));
  // The sphere: parent translation (-0.35,0,0), child scale 0.5 of a unit sphere
  Bounds sphere;
  for (const auto& t : triangles_of(s))
    if (t.p[0].x < -0.2f && t.p[1].x < -0.2f && t.p[2].x < -0.2f)
      for (const auto& p : t.p) sphere.grow(p);
  EXPECT_NEAR(sphere.lo.x, -0.85f, 1e-3f);
  EXPECT_NEAR(sphere.hi.y, 0.5f, 1e-3f);
  EXPECT_NEAR(s.background.x, 1.0f, 0.0f);
}

// scenes[i].extras.candela.strategy sets the default strategy; anything else is an error
TEST(GltfLoader, SceneExtrasChooseTheStrategy) {
  TempDir dir;
  json j = quad_gltf().document();
  EXPECT_EQ(load_gltf(dir.write("none.gltf", j.dump())).strategy, "");
  j["scenes"][0]["extras"]["candela"]["strategy"] = "auto";
  EXPECT_EQ(load_gltf(dir.write("auto.gltf", j.dump())).strategy, "auto");
  j["scenes"][0]["extras"]["candela"]["strategy"] = "mis";
  EXPECT_THROW(load_gltf(dir.write("bad.gltf", j.dump())), Error);
  j["scenes"][0]["extras"]["candela"]["strategy"] = 1;
  EXPECT_THROW(load_gltf(dir.write("bad2.gltf", j.dump())), Error);
}

// A normal-mapped mesh without TANGENT gets per-vertex tangents along dp/du of the normal
// texture's coordinates, with w = -1 where the UVs are mirrored (glTF: bitangent =
// cross(normal, tangent) w points toward decreasing v)
TEST(GltfLoader, GeneratesTangentsForNormalMapsWithoutTangent) {
  TempDir dir;
  for (bool mirrored : {false, true}) {
    GltfBuilder::Primitive p = quad();
    p.normals.assign(4, glm::vec3(0, 0, 1));
    if (mirrored) p.uvs = {{1, 1}, {0, 1}, {0, 0}, {1, 0}};
    json j = quad_gltf(p).document();
    j["images"] = {
        {{"uri",
          "data:image/"
          "png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8BQDwAEhQGAhKmMIQAAAABJRU5ErkJggg="
          "="}}};
    j["textures"] = {{{"source", 0}}};
    j["materials"][0]["normalTexture"] = {{"index", 0}};
    Scene s = load_gltf(dir.write(mirrored ? "m.gltf" : "n.gltf", j.dump()));
    ASSERT_EQ(s.meshes.size(), 1u);
    ASSERT_EQ(s.meshes[0].tangents.size(), 4u);
    for (const glm::vec4& t : s.meshes[0].tangents) {
      EXPECT_NEAR(t.x, mirrored ? -1.0f : 1.0f, 1e-6f);
      EXPECT_NEAR(t.y, 0.0f, 1e-6f);
      EXPECT_NEAR(t.z, 0.0f, 1e-6f);
      EXPECT_EQ(t.w, mirrored ? -1.0f : 1.0f);
    }
    EXPECT_TRUE(s.features().tangents);
  }
  // Without a normal texture nothing is generated
  GltfBuilder::Primitive p = quad();
  EXPECT_TRUE(load_gltf(dir.write("plain.gltf", quad_gltf(p).document().dump())).meshes[0].tangents.empty());
}

TEST(GltfLoader, MirroringTransformKeepsFrontFacesFront) {
  TempDir dir;
  json j = quad_gltf().document();
  j["nodes"][0]["scale"] = {-1, 1, 1};
  Scene s = load_gltf(dir.write("mirror.gltf", j.dump()));
  ASSERT_EQ(s.triangles(), 2u);
  // Unmirrored the quad faces +z; mirroring in x must not turn it around
  for (const auto& t : triangles_of(s)) EXPECT_GT(winding_normal(t).z, 0.0f);
}

TEST(GltfLoader, MatrixTransformAndTriangleStrip) {
  TempDir dir;
  GltfBuilder::Primitive strip = quad();
  strip.indices = {0, 1, 3, 2};
  strip.mode = 5;
  json j = quad_gltf(strip).document();
  j["nodes"][0]["matrix"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 5, 6, 7, 1};  // translate (5,6,7)
  Scene s = load_gltf(dir.write("strip.gltf", j.dump()));
  ASSERT_EQ(s.triangles(), 2u);
  for (const auto& t : triangles_of(s)) {
    EXPECT_GT(winding_normal(t).z, 0.0f) << "strip winding alternates";
    for (const auto& p : t.p) EXPECT_FLOAT_EQ(p.z, 7.0f);
  }
  EXPECT_FLOAT_EQ(s.bounds().lo.x, 4.0f);
}

TEST(GltfLoader, TextureTransformAppliesToUvs) {
  TempDir dir;
  GltfBuilder g = quad_gltf();
  g.add("images", {{"uri", "missing-is-not-read.png"}});
  g.add("textures", {{"source", 0}});
  json j = g.document();
  j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {
      {"index", 0},
      {"extensions",
       {{"KHR_texture_transform", {{"offset", {0.5, 0}}, {"scale", {2, 2}}, {"rotation", 1.5707963267948966}}}}}};
  // The image cannot be read: the loader says so and drops the texture, not the scene
  Scene missing = load_gltf(dir.write("tt.gltf", j.dump()));
  EXPECT_EQ(missing.materials[0].texture(TEX_BASE_COLOR).index, NO_TEXTURE);
  EXPECT_NE(join(missing.warnings).find("missing-is-not-read.png"), std::string::npos) << join(missing.warnings);

  unsigned char px[3] = {255, 255, 255};
  std::string png = (dir.path / "white.png").string();
  auto out = OIIO::ImageOutput::create(png);
  ASSERT_TRUE(out && out->open(png, OIIO::ImageSpec(1, 1, 3, OIIO::TypeDesc::UINT8)));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, px));
  out->close();
  j["images"][0]["uri"] = "white.png";
  Scene s = load_gltf(dir.write("tt.gltf", j.dump()));
  // Raw UVs reach the device; the slot's transform maps uv (1, 1): scaled (2, 2), rotated
  // by pi/2 (u' = u cos + v sin, v' = -u sin + v cos) to (2, -2), offset to (2.5, -2)
  const TextureSlot& ref = s.materials[0].texture(TEX_BASE_COLOR);
  EXPECT_EQ(ref.texcoord, 0);
  glm::vec2 uv = glm::vec2(ref.transform * glm::vec3(1.0f, 1.0f, 1.0f));
  EXPECT_NEAR(uv.x, 2.5f, 1e-5f);
  EXPECT_NEAR(uv.y, -2.0f, 1e-5f);
}

// COLOR_0 (normalized unsigned bytes, RGBA) multiplies the base color: a white-lit quad
// with red corners on the left and blue on the right shows those colours, blended across
TEST(GltfLoader, VertexColorsMultiplyTheBaseColor) {
  TempDir dir;
  GltfBuilder::Primitive colored = quad();
  // vertices: 0 (-1,-1) 1 (1,-1) 2 (1,1) 3 (-1,1)
  colored.colors = {{255, 0, 0, 255}, {0, 0, 255, 255}, {0, 0, 255, 255}, {255, 0, 0, 255}};
  GltfBuilder g = quad_gltf(colored);
  g.add_camera({0, 0, 3}, {0, 0, 0}, 0.5f);
  g.set_background({1, 1, 1});
  json j = g.document();
  j["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {1, 1, 1, 1};
  Scene s = load_gltf(dir.write("colors.gltf", j.dump()));
  EXPECT_TRUE(s.features().vertex_colors);
  EXPECT_FLOAT_EQ(triangles_of(s)[0].color[0].x, 1.0f);
  EXPECT_FLOAT_EQ(triangles_of(s)[0].color[1].z, 1.0f);

  RenderSettings settings;
  settings.width = settings.height = 16;
  settings.max_depth = 2;
  Film f = scene_renderer(pocl_device(), s, settings).render(0, 16).film;
  // Radiance equals the albedo (white background of 1, nothing else to see): the
  // colour at screen x is the linear blend of red (x = -1) and blue (x = +1)
  double half_width = 3.0 * std::tan(0.25);
  for (int x : {1, 8, 14}) {
    glm::vec3 c = f.pixel(size_t(8) * 16 + x);
    double world_x = ((x + 0.5) / 16.0 * 2.0 - 1.0) * half_width;
    double t = 0.5 * (world_x + 1.0);
    EXPECT_NEAR(c.x, 1.0 - t, 0.05) << "pixel " << x;
    EXPECT_NEAR(c.z, t, 0.05) << "pixel " << x;
    EXPECT_NEAR(c.y, 0.0, 1e-6);
  }
}

TEST(GltfLoader, UnsupportedFeaturesAreNamedOnceEach) {
  TempDir dir;
  json j = quad_gltf().document();
  j["extensionsUsed"] = {"ADOBE_materials_thin_transparency"};
  j["materials"][0]["extensions"] = {{"ADOBE_materials_thin_transparency", {{"transmissionFactor", 1}}}};
  j["materials"].push_back(j["materials"][0]);
  j["materials"][0]["occlusionTexture"] = {{"index", 0}};
  j["materials"][1]["occlusionTexture"] = {{"index", 0}};
  j["textures"] = {{{"source", 0}}};
  j["images"] = {
      {{"uri",
        "data:image/"
        "png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8BQDwAEhQGAhKmMIQAAAABJRU5ErkJggg="
        "="}}};
  Scene s = load_gltf(dir.write("unsupported.gltf", j.dump()));
  int unsupported = 0, occlusion = 0;
  for (const auto& w : s.warnings) {
    unsupported += w.find("ADOBE_materials_thin_transparency") != std::string::npos;
    occlusion += w.find("occlusionTexture") != std::string::npos;
  }
  EXPECT_EQ(unsupported, 1);
  EXPECT_EQ(occlusion, 1);
}

TEST(GltfLoader, MissingAndMalformedFilesFailClearly) {
  TempDir dir;
  EXPECT_THROW(load_gltf((dir.path / "nope.gltf").string()), Error);
  EXPECT_THROW(load_gltf(dir.write("bad.gltf", "{ this is not json")), Error);
  json j = quad_gltf().document();
  j["accessors"][0]["count"] = 400;  // reads past the buffer
  EXPECT_THROW(load_gltf(dir.write("short.gltf", j.dump())), Error);
  json cyclic = quad_gltf().document();
  cyclic["nodes"] = {{{"mesh", 0}, {"children", {1, 1}}}, {{"children", {0}}}};
  EXPECT_THROW(load_gltf(dir.write("cyclic.gltf", cyclic.dump())), Error);
  json negative = quad_gltf().document();
  negative["materials"][0]["emissiveFactor"] = {1, 1, 1};
  negative["materials"][0]["extensions"] = {{"KHR_materials_emissive_strength", {{"emissiveStrength", -2}}}};
  EXPECT_THROW(load_gltf(dir.write("negative.gltf", negative.dump())), Error);
  json bad_scene = quad_gltf().document();
  bad_scene["scene"] = 3;
  EXPECT_THROW(load_gltf(dir.write("bad-scene.gltf", bad_scene.dump())), Error);
  json huge = quad_gltf().document();
  huge["accessors"][1]["count"] = 4611686018427387905ull;  // 2^62 + 1: wraps naive bounds checks
  EXPECT_THROW(load_gltf(dir.write("huge.gltf", huge.dump())), Error);
  try {
    load_gltf(dir.write("empty.gltf", GltfBuilder().document().dump()));
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no triangles"), std::string::npos);
  }
}

// A textured diffuse quad facing a camera under a white background of radiance 1 reflects
// exactly its albedo: the sRGB-decoded texel colour times baseColorFactor.
TEST(GltfLoader, BaseColorTextureIsSrgbDecodedAndRendered) {
  TempDir dir;
  // 2x1 PNG: left texel sRGB 188 red-ish, right sRGB 100 blue-ish
  unsigned char px[6] = {188, 60, 20, 20, 60, 100};
  std::string png = (dir.path / "tex.png").string();
  auto out = OIIO::ImageOutput::create(png);
  ASSERT_TRUE(out && out->open(png, OIIO::ImageSpec(2, 1, 3, OIIO::TypeDesc::UINT8)));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, px));
  out->close();
  GltfBuilder g = quad_gltf();
  g.add("images", {{"uri", "tex.png"}});
  g.add("samplers", {{"wrapS", 33071}, {"wrapT", 33071}});  // clamp to edge
  g.add("textures", {{"source", 0}, {"sampler", 0}});
  g.add_camera({0, 0, 3}, {0, 0, 0}, 0.5f);
  g.set_background({1, 1, 1});
  json j = g.document();
  j["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {1, 1, 1, 1};
  j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
  j["materials"][0]["doubleSided"] = true;
  Scene s = load_gltf(dir.write("textured.gltf", j.dump()));
  ASSERT_EQ(s.textures.size(), 1u);
  auto srgb = [](double c) {
    c /= 255.0;
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
  };
  const TextureDesc& tex = s.textures[0];
  ASSERT_EQ(tex.rgba8.size(), 8u);  // RGBA8, decoded from sRGB in the kernel
  EXPECT_TRUE(tex.srgb);
  EXPECT_EQ(tex.rgba8[0], 188);
  EXPECT_EQ(tex.rgba8[6], 100);
  EXPECT_EQ(tex.rgba8[3], 255);
  EXPECT_TRUE(s.features().textures);

  RenderSettings settings;
  settings.width = settings.height = 16;
  settings.max_depth = 4;
  Renderer r = scene_renderer(pocl_device(), s, settings);
  Film f = r.render(0, 64).film;
  // Quad spans the whole view; the left and right quarters see only their texel (clamped).
  // Background sampling has variance: compare within 4 measured standard errors
  for (int y = 4; y < 12; ++y) {
    size_t l = size_t(y) * 16 + 1, rt = size_t(y) * 16 + 14;
    auto se = [&](size_t i, int c) { return 4.0 * std::sqrt(f.variance_of_mean(i)[c]) + 1e-4; };
    EXPECT_NEAR(f.pixel(l).x, srgb(188), se(l, 0));
    EXPECT_NEAR(f.pixel(l).z, srgb(20), se(l, 2));
    EXPECT_NEAR(f.pixel(rt).x, srgb(20), se(rt, 0));
    EXPECT_NEAR(f.pixel(rt).z, srgb(100), se(rt, 2));
  }
}

}  // namespace candela::test

namespace candela::test {
namespace {

std::string write_png(const TempDir& dir, const std::string& name, int w, int h, int channels,
                      const unsigned char* px) {
  std::string path = (dir.path / name).string();
  auto out = OIIO::ImageOutput::create(path);
  if (!out || !out->open(path, OIIO::ImageSpec(w, h, channels, OIIO::TypeDesc::UINT8))) return "";
  out->write_image(OIIO::TypeDesc::UINT8, px);
  out->close();
  return path;
}

int count_containing(const std::vector<std::string>& lines, const std::string& part) {
  int n = 0;
  for (const auto& l : lines) n += l.find(part) != std::string::npos;
  return n;
}

}  // namespace

// glTF 3.6.2: an accessor without a bufferView reads as zeros, and sparse values replace
// some of them. TEXCOORD_0 loses its bufferView; POSITION is zeros but for vertices 0-2,
// substituted by sparse indices (the index buffer's first three entries: 0 1 2) and values
// (the original positions): vertex 3 falls to the origin and triangle (0, 2, 3) degenerates
TEST(GltfLoader, AccessorWithoutBufferViewReadsAsZeros) {
  TempDir dir;
  json j = quad_gltf().document();
  j["accessors"][1].erase("bufferView");
  json& pos = j["accessors"][0];
  pos.erase("bufferView");
  pos["sparse"] = {
      {"count", 3}, {"indices", {{"bufferView", 2}, {"componentType", 5123}}}, {"values", {{"bufferView", 0}}}};
  Scene s = load_gltf(dir.write("zeros.gltf", j.dump()));
  ASSERT_EQ(s.meshes.size(), 1u);
  const MeshDesc& m = s.meshes[0];
  ASSERT_EQ(m.uv0.size(), 4u);
  for (const auto& uv : m.uv0) EXPECT_EQ(uv, glm::vec2(0.0f));
  EXPECT_EQ(m.positions[1], glm::vec3(1, -1, 0));
  EXPECT_EQ(m.positions[2], glm::vec3(1, 1, 0));
  EXPECT_EQ(m.positions[3], glm::vec3(0.0f));
  EXPECT_EQ(s.triangles(), 1u);
}

// An image candela cannot decode never fails the scene: a texture uses its core source
// when an extension's image (EXT_texture_webp) cannot be decoded; a texture without any
// decodable image (only WebP, a corrupt PNG, a PNG header claiming 40000^2 texels) is
// dropped with one warning however many slots use it, and those slots are untextured
TEST(GltfLoader, UndecodableImagesFallBackToTheCoreSourceOrAreDropped) {
  TempDir dir;
  const unsigned char white[3] = {255, 255, 255};
  ASSERT_FALSE(write_png(dir, "white.png", 1, 1, 3, white).empty());
  dir.write("fake.webp", std::string("RIFF\x24\0\0\0WEBPVP8 \x18\0\0\0", 20) + std::string(24, '\0'));
  const unsigned char png_header[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R'};
  std::string ihdr_small = std::string("\0\0\0\4\0\0\0\4\x08\x06\0\0\0", 13);         // 4 x 4, RGBA8
  std::string ihdr_huge = std::string("\0\0\x9c\x40\0\0\x9c\x40\x08\x06\0\0\0", 13);  // 40000 x 40000
  std::string header(reinterpret_cast<const char*>(png_header), sizeof png_header);
  dir.write("corrupt.png", header + ihdr_small + "not a zlib stream at all");
  dir.write("huge.png", header + ihdr_huge + std::string(16, '\0'));
  GltfBuilder g = quad_gltf();
  g.add("images", {{"uri", "white.png"}});
  g.add("images", {{"uri", "fake.webp"}, {"mimeType", "image/webp"}});
  g.add("images", {{"uri", "corrupt.png"}});
  g.add("images", {{"uri", "huge.png"}});
  g.add("textures", {{"source", 0}, {"extensions", {{"EXT_texture_webp", {{"source", 1}}}}}});
  g.add("textures", {{"extensions", {{"EXT_texture_webp", {{"source", 1}}}}}});
  g.add("textures", {{"source", 2}});
  g.add("textures", {{"source", 3}});
  json j = g.document();
  j["extensionsUsed"] = {"EXT_texture_webp"};
  json& m0 = j["materials"][0];
  m0["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
  m0["emissiveFactor"] = {1, 1, 1};
  m0["emissiveTexture"] = {{"index", 1}};
  m0["pbrMetallicRoughness"]["metallicRoughnessTexture"] = {{"index", 2}};
  j["materials"].push_back(j["materials"][0]);
  j["materials"][1]["normalTexture"] = {{"index", 2}};
  j["materials"][1]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 3}};
  Scene s = load_gltf(dir.write("fallback.gltf", j.dump()));
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].width, 1);
  EXPECT_EQ(s.materials[0].texture(TEX_BASE_COLOR).index, 0);
  EXPECT_EQ(s.materials[0].texture(TEX_EMISSION).index, NO_TEXTURE);
  EXPECT_EQ(s.materials[0].texture(TEX_METALLIC_ROUGHNESS).index, NO_TEXTURE);
  EXPECT_EQ(s.materials[1].texture(TEX_NORMAL).index, NO_TEXTURE);
  EXPECT_EQ(s.materials[1].texture(TEX_BASE_COLOR).index, NO_TEXTURE);
  EXPECT_EQ(count_containing(s.warnings, "glTF texture 0 "), 0);
  EXPECT_EQ(count_containing(s.warnings, "glTF texture 1 "), 1);
  EXPECT_EQ(count_containing(s.warnings, "glTF texture 2 "), 1);
  EXPECT_EQ(count_containing(s.warnings, "glTF texture 3 "), 1);
  EXPECT_EQ(count_containing(s.warnings, "neither PNG nor JPEG"), 1);
  EXPECT_EQ(count_containing(s.warnings, "too large"), 1);
  EXPECT_GT(compile_scene(s).triangles, 0u);
}

// Sampler magFilter NEAREST (9728) selects nearest-texel lookups; LINEAR (9729) and no
// sampler stay bilinear; neither warns
TEST(GltfLoader, SamplerMagFilterNearestSelectsNearestLookups) {
  TempDir dir;
  const unsigned char white[3] = {255, 255, 255};
  ASSERT_FALSE(write_png(dir, "white.png", 1, 1, 3, white).empty());
  GltfBuilder g = quad_gltf();
  g.add("images", {{"uri", "white.png"}});
  g.add("samplers", {{"magFilter", 9728}});
  g.add("samplers", {{"magFilter", 9729}, {"minFilter", 9728}});
  g.add("textures", {{"source", 0}, {"sampler", 0}});
  g.add("textures", {{"source", 0}, {"sampler", 1}});
  json j = g.document();
  j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
  j["materials"][0]["emissiveFactor"] = {1, 1, 1};
  j["materials"][0]["emissiveTexture"] = {{"index", 1}};
  Scene s = load_gltf(dir.write("nearest.gltf", j.dump()));
  ASSERT_EQ(s.textures.size(), 2u);
  EXPECT_TRUE(s.textures[size_t(s.materials[0].texture(TEX_BASE_COLOR).index)].nearest);
  EXPECT_FALSE(s.textures[size_t(s.materials[0].texture(TEX_EMISSION).index)].nearest);
  EXPECT_EQ(count_containing(s.warnings, "NEAREST"), 0);
  CompiledScene c = compile_scene(s);
  EXPECT_EQ(c.buffers.textures[size_t(s.materials[0].texture(TEX_BASE_COLOR).index)].flags & TEXTURE_NEAREST,
            TEXTURE_NEAREST);
  EXPECT_EQ(c.buffers.textures[size_t(s.materials[0].texture(TEX_EMISSION).index)].flags & TEXTURE_NEAREST, 0u);
}

// A 1x1 PNG as a data URI
const char* const kPixelPng =
    "data:image/png;base64,"
    "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8BQDwAEhQGAhKmMIQAAAABJRU5ErkJggg==";

// KHR_materials_clearcoat's clearcoatNormalTexture reaches its slot with its texCoord, scale
// and KHR_texture_transform, as linear data, with no warning; the compiled material carries it
TEST(GltfLoader, ClearcoatNormalTextureIsRead) {
  TempDir dir;
  json j = quad_gltf().document();
  j["extensionsUsed"] = {"KHR_materials_clearcoat", "KHR_texture_transform"};
  j["textures"] = {{{"source", 0}}};
  j["images"] = {{{"uri", kPixelPng}}};
  j["materials"][0]["extensions"]["KHR_materials_clearcoat"] = {
      {"clearcoatFactor", 1},
      {"clearcoatNormalTexture",
       {{"index", 0},
        {"texCoord", 1},
        {"scale", 0.5},
        {"extensions", {{"KHR_texture_transform", {{"offset", {0.25, 0}}}}}}}}};
  Scene s = load_gltf(dir.write("coat.gltf", j.dump()));
  const MaterialDesc& m = s.materials[0];
  const TextureSlot& slot = m.texture(TEX_CLEARCOAT_NORMAL);
  ASSERT_NE(slot.index, NO_TEXTURE);
  EXPECT_EQ(slot.texcoord, 1);
  EXPECT_FALSE(s.textures.at(size_t(slot.index)).srgb);
  EXPECT_NEAR(glm::vec2(slot.transform * glm::vec3(0.0f, 0.0f, 1.0f)).x, 0.25f, 1e-6f);
  EXPECT_FLOAT_EQ(m.clearcoat_normal_scale, 0.5f);
  EXPECT_EQ(m.texture(TEX_NORMAL).index, NO_TEXTURE);  // the base keeps its own (none)
  EXPECT_EQ(join(s.warnings).find("clearcoatNormalTexture"), std::string::npos) << join(s.warnings);
  CompiledScene c = compile_scene(s);
  EXPECT_FLOAT_EQ(c.buffers.materials[0].params.gltf.clearcoat_normal_scale, 0.5f);
  EXPECT_EQ(c.buffers.materials[0].textures[TEX_CLEARCOAT_NORMAL].index, slot.index);
  EXPECT_EQ(c.buffers.materials[0].textures[TEX_CLEARCOAT_NORMAL].texcoord, 1u);
}

// KHR_materials_diffuse_transmission: factor (texture A, linear), colour (texture RGB, sRGB),
// the defaults of the extension, its range checks, and the kernel feature it turns on
TEST(GltfLoader, DiffuseTransmissionIsRead) {
  TempDir dir;
  json j = quad_gltf().document();
  j["extensionsUsed"] = {"KHR_materials_diffuse_transmission"};
  j["textures"] = {{{"source", 0}}, {{"source", 1}}};
  j["images"] = {{{"uri", kPixelPng}}, {{"uri", kPixelPng}}};
  j["materials"][0]["extensions"]["KHR_materials_diffuse_transmission"] = {
      {"diffuseTransmissionFactor", 0.4},
      {"diffuseTransmissionColorFactor", {0.9, 0.5, 0.2}},
      {"diffuseTransmissionTexture", {{"index", 0}}},
      {"diffuseTransmissionColorTexture", {{"index", 1}}}};
  j["materials"].push_back(j["materials"][0]);
  j["materials"][1]["extensions"]["KHR_materials_diffuse_transmission"] = json::object();
  Scene s = load_gltf(dir.write("dt.gltf", j.dump()));
  const MaterialDesc& m = s.materials[0];
  EXPECT_FLOAT_EQ(m.diffuse_transmission, 0.4f);
  EXPECT_EQ(m.diffuse_transmission_color, glm::vec3(0.9f, 0.5f, 0.2f));
  const TextureSlot &factor = m.texture(TEX_DIFFUSE_TRANSMISSION), &color = m.texture(TEX_DIFFUSE_TRANSMISSION_COLOR);
  ASSERT_NE(factor.index, NO_TEXTURE);
  ASSERT_NE(color.index, NO_TEXTURE);
  EXPECT_FALSE(s.textures.at(size_t(factor.index)).srgb);
  EXPECT_TRUE(s.textures.at(size_t(color.index)).srgb);
  EXPECT_EQ(m.kernel_type(), MATERIAL_GLTF);  // not the Lambertian short cut, though specular is 0
  EXPECT_TRUE(s.features().diffuse_transmission);
  EXPECT_EQ(join(s.warnings).find("KHR_materials_diffuse_transmission"), std::string::npos) << join(s.warnings);
  // Defaults: factor 0, colour white; that material is Lambertian
  EXPECT_FLOAT_EQ(s.materials[1].diffuse_transmission, 0.0f);
  EXPECT_EQ(s.materials[1].diffuse_transmission_color, glm::vec3(1.0f));
  EXPECT_EQ(s.materials[1].kernel_type(), MATERIAL_DIFFUSE);
  CompiledScene c = compile_scene(s);
  const dev::GltfMaterial& g = c.buffers.materials[0].params.gltf;
  EXPECT_FLOAT_EQ(g.diffuse_transmission, 0.4f);
  EXPECT_FLOAT_EQ(g.diffuse_transmission_color[1], 0.5f);
  for (double bad : {-0.1, 1.5}) {
    j["materials"][0]["extensions"]["KHR_materials_diffuse_transmission"]["diffuseTransmissionFactor"] = bad;
    EXPECT_THROW(load_gltf(dir.write("bad.gltf", j.dump())), Error);
  }
}

// KHR_materials_iridescence: factor (texture R), film ior, thickness range (texture G), both
// textures linear, the extension's defaults, its range checks, and the kernel feature it turns on
TEST(GltfLoader, IridescenceIsRead) {
  TempDir dir;
  json j = quad_gltf().document();
  j["extensionsUsed"] = {"KHR_materials_iridescence"};
  j["textures"] = {{{"source", 0}}, {{"source", 1}}};
  j["images"] = {{{"uri", kPixelPng}}, {{"uri", kPixelPng}}};
  j["materials"][0]["extensions"]["KHR_materials_iridescence"] = {{"iridescenceFactor", 0.7},
                                                                  {"iridescenceIor", 1.8},
                                                                  {"iridescenceThicknessMinimum", 200.0},
                                                                  {"iridescenceThicknessMaximum", 650.0},
                                                                  {"iridescenceTexture", {{"index", 0}}},
                                                                  {"iridescenceThicknessTexture", {{"index", 1}}}};
  j["materials"][0]["pbrMetallicRoughness"]["metallicFactor"] = 1.0;  // not the Lambertian short cut
  j["materials"].push_back(j["materials"][0]);
  j["materials"][1]["extensions"]["KHR_materials_iridescence"] = json::object();
  Scene s = load_gltf(dir.write("ir.gltf", j.dump()));
  const MaterialDesc& m = s.materials[0];
  EXPECT_FLOAT_EQ(m.iridescence, 0.7f);
  EXPECT_FLOAT_EQ(m.iridescence_ior, 1.8f);
  EXPECT_FLOAT_EQ(m.iridescence_thickness_min, 200.0f);
  EXPECT_FLOAT_EQ(m.iridescence_thickness_max, 650.0f);
  const TextureSlot &factor = m.texture(TEX_IRIDESCENCE), &thickness = m.texture(TEX_IRIDESCENCE_THICKNESS);
  ASSERT_NE(factor.index, NO_TEXTURE);
  ASSERT_NE(thickness.index, NO_TEXTURE);
  EXPECT_FALSE(s.textures.at(size_t(factor.index)).srgb);
  EXPECT_FALSE(s.textures.at(size_t(thickness.index)).srgb);
  EXPECT_TRUE(m.needs("CD_FEATURE_IRIDESCENCE"));
  EXPECT_TRUE(s.features().iridescence);
  EXPECT_EQ(join(s.warnings).find("KHR_materials_iridescence"), std::string::npos) << join(s.warnings);
  // Defaults: factor 0 (no film), ior 1.3, 100 to 400 nm
  EXPECT_FLOAT_EQ(s.materials[1].iridescence, 0.0f);
  EXPECT_FLOAT_EQ(s.materials[1].iridescence_ior, 1.3f);
  EXPECT_FLOAT_EQ(s.materials[1].iridescence_thickness_min, 100.0f);
  EXPECT_FLOAT_EQ(s.materials[1].iridescence_thickness_max, 400.0f);
  EXPECT_FALSE(s.materials[1].needs("CD_FEATURE_IRIDESCENCE"));
  CompiledScene c = compile_scene(s);
  const dev::GltfMaterial& g = c.buffers.materials[0].params.gltf;
  EXPECT_FLOAT_EQ(g.iridescence, 0.7f);
  EXPECT_FLOAT_EQ(g.iridescence_ior, 1.8f);
  EXPECT_FLOAT_EQ(g.iridescence_thickness_min, 200.0f);
  EXPECT_FLOAT_EQ(g.iridescence_thickness_max, 650.0f);
  // Without a film the scene's kernel compiles none of it
  j["materials"][0]["extensions"]["KHR_materials_iridescence"]["iridescenceFactor"] = 0.0;
  EXPECT_FALSE(load_gltf(dir.write("none.gltf", j.dump())).features().iridescence);
  j["materials"][0]["extensions"]["KHR_materials_iridescence"]["iridescenceFactor"] = 1.5;
  EXPECT_THROW(load_gltf(dir.write("bad.gltf", j.dump())), Error);
  j["materials"][0]["extensions"]["KHR_materials_iridescence"]["iridescenceFactor"] = 1.0;
  j["materials"][0]["extensions"]["KHR_materials_iridescence"]["iridescenceIor"] = 0.5;
  EXPECT_THROW(load_gltf(dir.write("bad.gltf", j.dump())), Error);
}

// KHR_materials_diffuse_roughness: factor (texture R, linear), default 0, range check; a
// material that is otherwise Lambertian is shaded by the glTF BSDF (EON), and the kernel
// feature is on only where the roughness is above 0
TEST(GltfLoader, DiffuseRoughnessIsRead) {
  TempDir dir;
  json j = quad_gltf().document();
  j["extensionsUsed"] = {"KHR_materials_diffuse_roughness"};
  j["textures"] = {{{"source", 0}}};
  j["images"] = {{{"uri", kPixelPng}}};
  j["materials"][0]["extensions"]["KHR_materials_diffuse_roughness"] = {{"diffuseRoughnessFactor", 0.6},
                                                                        {"diffuseRoughnessTexture", {{"index", 0}}}};
  j["materials"].push_back(j["materials"][0]);
  j["materials"][1]["extensions"]["KHR_materials_diffuse_roughness"] = json::object();
  Scene s = load_gltf(dir.write("dr.gltf", j.dump()));
  const MaterialDesc& m = s.materials[0];
  EXPECT_FLOAT_EQ(m.diffuse_roughness, 0.6f);
  const TextureSlot& tex = m.texture(TEX_DIFFUSE_ROUGHNESS);
  ASSERT_NE(tex.index, NO_TEXTURE);
  EXPECT_FALSE(s.textures.at(size_t(tex.index)).srgb);
  EXPECT_EQ(m.kernel_type(), MATERIAL_GLTF);
  EXPECT_TRUE(m.needs("CD_FEATURE_DIFFUSE_ROUGHNESS"));
  EXPECT_TRUE(s.features().diffuse_roughness);
  EXPECT_EQ(join(s.warnings).find("KHR_materials_diffuse_roughness"), std::string::npos) << join(s.warnings);
  EXPECT_FLOAT_EQ(s.materials[1].diffuse_roughness, 0.0f);
  EXPECT_EQ(s.materials[1].kernel_type(), MATERIAL_DIFFUSE);
  EXPECT_FALSE(s.materials[1].needs("CD_FEATURE_DIFFUSE_ROUGHNESS"));
  CompiledScene c = compile_scene(s);
  EXPECT_FLOAT_EQ(c.buffers.materials[0].params.gltf.diffuse_roughness, 0.6f);
  j["materials"][0]["extensions"]["KHR_materials_diffuse_roughness"]["diffuseRoughnessFactor"] = 0.0;
  EXPECT_FALSE(load_gltf(dir.write("none.gltf", j.dump())).features().diffuse_roughness);
  j["materials"][0]["extensions"]["KHR_materials_diffuse_roughness"]["diffuseRoughnessFactor"] = 1.5;
  EXPECT_THROW(load_gltf(dir.write("bad.gltf", j.dump())), Error);
}

}  // namespace candela::test
