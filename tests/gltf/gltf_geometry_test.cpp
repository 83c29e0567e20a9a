// glTF geometry: deep node trees, morph targets, skins, EXT_mesh_gpu_instancing, compressed
// geometry (Draco, meshopt), EXT_texture_webp, spec-gloss materials and material variants.
#include <gtest/gtest.h>
#include <meshoptimizer.h>
#include <unistd.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "base/error.hpp"
#include "gltf/gltf_loader.hpp"
#include "support/test_support.hpp"

namespace fs = std::filesystem;
using nlohmann::json;

namespace candela::test {
namespace {

// A quad in z = 0 (x, y in [-1, 1]) with normals +z, as mesh 0 of a builder without nodes
GltfBuilder quad_mesh() {
  GltfBuilder g;
  GltfBuilder::Primitive q = quad_primitive({{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, -1);
  q.normals.assign(4, glm::vec3(0, 0, 1));
  g.add_mesh({q});
  return g;
}

class TempDir {
 public:
  TempDir() {
    path = fs::temp_directory_path() /
           ("candela-geometry-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter_++));
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  std::string write(const std::string& name, const std::string& bytes) const {
    std::string p = (path / name).string();
    std::ofstream(p, std::ios::binary) << bytes;
    return p;
  }
  fs::path path;

 private:
  static inline int counter_ = 0;
};

Scene load_json(const json& j, const LoadOptions& options = {}) { return load_gltf_from_memory(j.dump(), "", options); }

Bounds bounds_of(const MeshDesc& m) {
  Bounds b;
  for (const glm::vec3& p : m.positions) b.grow(p);
  return b;
}

void expect_near(const glm::vec3& a, const glm::vec3& b, float tol = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

// ../shared/gltf-samples beside the checkout (beside the main checkout from a git worktree),
// or "" when absent
std::string samples_dir() {
  if (const char* env = std::getenv("CANDELA_SAMPLES")) return env;
  fs::path root(CANDELA_SOURCE_DIR);
  fs::path dir = root.parent_path() / "shared" / "gltf-samples";
  if (fs::is_directory(dir)) return dir.string();
  std::ifstream git(root / ".git");  // a worktree: "gitdir: MAIN/.git/worktrees/NAME"
  std::string line;
  if (std::getline(git, line) && line.rfind("gitdir: ", 0) == 0) {
    std::string gitdir = line.substr(8);
    size_t at = gitdir.find("/.git/");
    if (at != std::string::npos) {
      dir = fs::path(gitdir.substr(0, at)).parent_path() / "shared" / "gltf-samples";
      if (fs::is_directory(dir)) return dir.string();
    }
  }
  return "";
}

}  // namespace

// A chain of a million nodes, the quad at its end: loaded without recursion
TEST(GltfGeometry, MillionNodeChainLoads) {
  constexpr int kDepth = 1000000;
  json j = quad_mesh().document();
  std::string nodes;
  nodes.reserve(size_t(kDepth) * 24);
  for (int i = 0; i + 1 < kDepth; ++i)
    nodes += "{\"children\":[" + std::to_string(i + 1) + (i % 1000 == 0 ? "],\"translation\":[0,0,1]}," : "]},");
  nodes += "{\"mesh\":0}";
  j["scenes"][0]["nodes"] = {0};
  j.erase("nodes");
  std::string text = j.dump();
  text.insert(text.size() - 1, ",\"nodes\":[" + nodes + "]");
  Scene s = load_gltf_from_memory(text, "");
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(bounds_of(s.meshes[0]).lo.z, kDepth / 1000);
}

TEST(GltfGeometry, NodeCyclesAreOneClearError) {
  json j = quad_mesh().document();
  j["nodes"] = {{{"children", {1}}}, {{"children", {2}}}, {{"mesh", 0}, {"children", {1}}}};
  j["scenes"][0]["nodes"] = {0};
  std::string what = error_of([&] { load_json(j); });
  EXPECT_NE(what.find("glTF node 1 has two parents or is part of a cycle"), std::string::npos) << what;
}

// glTF 3.7.2.2: POSITION, NORMAL and TANGENT displacements times the weights; the node's
// weights replace the mesh's
TEST(GltfGeometry, MorphTargetsTakeTheDefaultWeights) {
  GltfBuilder g = quad_mesh();
  int dz = g.add_floats({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3");
  int dx = g.add_floats({2, 0, 0, 2, 0, 0, 2, 0, 0, 2, 0, 0}, "VEC3");
  int dn = g.add_floats({1, 0, -1, 1, 0, -1, 1, 0, -1, 1, 0, -1}, "VEC3");
  g.doc["meshes"][0]["primitives"][0]["targets"] = {{{"POSITION", dz}, {"NORMAL", dn}}, {{"POSITION", dx}}};
  g.doc["meshes"][0]["weights"] = {0.5, 0.25};
  g.add_node({{"mesh", 0}});
  Scene mesh_weights = load_json(g.document());
  ASSERT_EQ(mesh_weights.meshes.size(), 1u);
  Bounds b = bounds_of(mesh_weights.meshes[0]);
  expect_near(b.lo, {-0.5f, -1.0f, 0.5f});
  expect_near(b.hi, {1.5f, 1.0f, 0.5f});
  expect_near(mesh_weights.meshes[0].normals[0], glm::normalize(glm::vec3(0.5f, 0.0f, 0.5f)));

  g.doc["nodes"][0]["weights"] = {1.0, 0.0};
  Scene node_weights = load_json(g.document());
  b = bounds_of(node_weights.meshes[0]);
  expect_near(b.lo, {-1.0f, -1.0f, 1.0f});
  expect_near(b.hi, {1.0f, 1.0f, 1.0f});
  expect_near(node_weights.meshes[0].normals[0], {1.0f, 0.0f, 0.0f});
}

// glTF 3.7.3: each vertex by the weighted joint matrices (joint world x inverse bind); the
// skinned node's own transform does not apply
TEST(GltfGeometry, SkinsPoseVerticesByTheirJoints) {
  GltfBuilder g = quad_mesh();
  // Vertices 0, 1 on joint 0; 2 half joint 0, half joint 1; 3 a quarter on joint 1 in
  // JOINTS_0 and a quarter on joint 0 in JOINTS_1 (weights normalized)
  int joints = g.add_ushorts({0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0}, "VEC4");
  int weights = g.add_floats({1, 0, 0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0, 0.25f, 0, 0, 0}, "VEC4");
  int joints1 = g.add_ushorts({0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}, "VEC4");
  int weights1 = g.add_floats({0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0.25f}, "VEC4");
  auto& attributes = g.doc["meshes"][0]["primitives"][0]["attributes"];
  attributes["JOINTS_0"] = joints;
  attributes["WEIGHTS_0"] = weights;
  attributes["JOINTS_1"] = joints1;
  attributes["WEIGHTS_1"] = weights1;
  // Inverse bind matrices: identity, and a translation by (-2, 0, 0) (column-major)
  std::vector<float> ibm = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0,  0, 0, 1,
                            1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -2, 0, 0, 1};
  int ibm_accessor = g.add_floats(ibm, "MAT4");
  int j0 = g.add_node({{"translation", {1, 0, 0}}, {"children", {2}}});
  g.add_node({{"mesh", 0}, {"skin", 0}, {"translation", {100, 0, 0}}});
  g.add("nodes", {{"translation", {2, 0, 3}}});  // joint 1, child of joint 0: world (3, 0, 3)
  g.add("skins", {{"joints", {j0, 2}}, {"inverseBindMatrices", ibm_accessor}});
  Scene s = load_json(g.document());
  ASSERT_EQ(s.meshes.size(), 1u);
  const MeshDesc& m = s.meshes[0];
  // Joint matrices: T(1, 0, 0) and T(3, 0, 3) T(-2, 0, 0) = T(1, 0, 3)
  expect_near(m.positions[0], {0.0f, -1.0f, 0.0f});
  expect_near(m.positions[1], {2.0f, -1.0f, 0.0f});
  expect_near(m.positions[2], {2.0f, 1.0f, 1.5f});
  expect_near(m.positions[3], {0.0f, 1.0f, 1.5f});
  bool skins_warned = false;
  for (const auto& w : s.warnings) skins_warned |= w.find("skin") != std::string::npos;
  EXPECT_FALSE(skins_warned);

  g.doc["skins"][0]["joints"] = {j0};  // joint 1 no longer exists
  std::string what = error_of([&] { load_json(g.document()); });
  EXPECT_NE(what.find("JOINTS refers to joint 1 of a skin of 1"), std::string::npos) << what;
}

// EXT_mesh_gpu_instancing: each instance's TRS, then the node's transform
TEST(GltfGeometry, GpuInstancesAreEachRendered) {
  GltfBuilder g = quad_mesh();
  int t = g.add_floats({0, 0, 0, 10, 0, 0, 0, 10, 0}, "VEC3");
  float h = std::sqrt(0.5f);
  int r = g.add_floats({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, h, h}, "VEC4");  // the third: 90 deg about z
  int sc = g.add_floats({1, 1, 1, 2, 2, 2, 1, 3, 1}, "VEC3");
  g.add_node({{"mesh", 0},
              {"translation", {0, 0, 5}},
              {"extensions",
               {{"EXT_mesh_gpu_instancing", {{"attributes", {{"TRANSLATION", t}, {"ROTATION", r}, {"SCALE", sc}}}}}}}});
  g.doc["extensionsUsed"] = {"EXT_mesh_gpu_instancing"};
  Scene s = load_json(g.document());
  ASSERT_EQ(s.meshes.size(), 3u);
  EXPECT_EQ(s.triangles(), 6u);
  Bounds b0 = bounds_of(s.meshes[0]), b1 = bounds_of(s.meshes[1]), b2 = bounds_of(s.meshes[2]);
  expect_near(b0.lo, {-1, -1, 5});
  expect_near(b0.hi, {1, 1, 5});
  expect_near(b1.lo, {8, -2, 5});
  expect_near(b1.hi, {12, 2, 5});
  expect_near(b2.lo, {-3, 9, 5});  // scaled 3 in y, then turned: 3 wide in x
  expect_near(b2.hi, {3, 11, 5});
  for (const auto& w : s.warnings) EXPECT_EQ(w.find("EXT_mesh_gpu_instancing"), std::string::npos) << w;

  g.doc["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["SCALE"] = g.add_floats({1, 1, 1}, "VEC3");
  std::string what = error_of([&] { load_json(g.document()); });
  EXPECT_NE(what.find("different counts"), std::string::npos) << what;
}

// KHR_materials_variants: the default mapping, a named variant, and an unknown name
TEST(GltfGeometry, MaterialVariantsChooseThePrimitivesMaterial) {
  GltfBuilder g = quad_mesh();
  for (float c : {0.5f, 0.8f, 0.2f})
    g.add("materials", {{"pbrMetallicRoughness", {{"baseColorFactor", {c, c, c, 1}}}}});
  g.doc["meshes"][0]["primitives"][0]["material"] = 0;
  g.doc["meshes"][0]["primitives"][0]["extensions"]["KHR_materials_variants"]["mappings"] = {
      {{"material", 1}, {"variants", {0}}}, {{"material", 2}, {"variants", {1, 2}}}};
  g.doc["extensions"]["KHR_materials_variants"]["variants"] = {
      {{"name", "light"}}, {{"name", "dark"}}, {{"name", "also dark"}}};
  g.doc["extensionsUsed"] = {"KHR_materials_variants"};
  g.add_node({{"mesh", 0}});
  Scene plain = load_json(g.document());
  EXPECT_EQ(plain.meshes.at(0).material, 0u);
  EXPECT_EQ(plain.variants, (std::vector<std::string>{"light", "dark", "also dark"}));
  LoadOptions options;
  options.variant = "dark";
  EXPECT_EQ(load_json(g.document(), options).meshes.at(0).material, 2u);
  options.variant = "light";
  EXPECT_EQ(load_json(g.document(), options).meshes.at(0).material, 1u);
  options.variant = "bright";
  std::string what = error_of([&] { load_json(g.document(), options); });
  EXPECT_NE(what.find("'bright'"), std::string::npos) << what;
  EXPECT_NE(what.find("'light', 'dark', 'also dark'"), std::string::npos) << what;
}

// KHR_materials_pbrSpecularGlossiness read through Khronos' conversion to metallic-roughness
TEST(GltfGeometry, SpecularGlossinessConvertsToMetallicRoughness) {
  GltfBuilder g = quad_mesh();
  g.add("materials",
        {{"extensions",
          {{"KHR_materials_pbrSpecularGlossiness",
            {{"diffuseFactor", {0, 0, 0, 1}}, {"specularFactor", {1.0, 0.766, 0.336}}, {"glossinessFactor", 0.9}}}}}});
  g.add("materials", {{"pbrMetallicRoughness", {{"baseColorFactor", {0.1, 0.1, 0.1, 1}}}},
                      {"extensions",
                       {{"KHR_materials_pbrSpecularGlossiness",
                         {{"diffuseFactor", {0.5, 0.25, 0.5, 0.75}},
                          {"specularFactor", {0.04, 0.04, 0.04}},
                          {"glossinessFactor", 0.3}}}}}});
  g.doc["meshes"][0]["primitives"][0]["material"] = 0;
  g.add_node({{"mesh", 0}});
  g.doc["extensionsUsed"] = {"KHR_materials_pbrSpecularGlossiness"};
  Scene s = load_json(g.document());
  const MaterialDesc& gold = s.materials.at(0);
  EXPECT_NEAR(gold.metallic, 1.0f, 1e-4f);
  EXPECT_NEAR(gold.roughness, 0.1f, 1e-5f);
  expect_near(glm::vec3(gold.base_color), {1.0f, 0.766f, 0.336f}, 1e-3f);
  const MaterialDesc& plastic = s.materials.at(1);  // the extension wins over pbrMetallicRoughness
  EXPECT_NEAR(plastic.metallic, 0.0f, 1e-5f);
  EXPECT_NEAR(plastic.roughness, 0.7f, 1e-5f);
  expect_near(glm::vec3(plastic.base_color), {0.5f, 0.25f, 0.5f}, 1e-4f);
  EXPECT_NEAR(plastic.base_color.w, 0.75f, 1e-6f);
  for (const auto& w : s.warnings) EXPECT_EQ(w.find("SpecularGlossiness"), std::string::npos) << w;
}

// EXT_texture_webp: the WebP image first, the core source when it does not decode
TEST(GltfGeometry, WebpTexturesDecodeWithTheCoreSourceAsFallback) {
  if (!OIIO::ImageOutput::create("webp")) GTEST_SKIP() << "OpenImageIO has no WebP writer";
  TempDir dir;
  std::string webp = (dir.path / "red.webp").string();
  {
    auto out = OIIO::ImageOutput::create(webp);
    OIIO::ImageSpec spec(2, 2, 3, OIIO::TypeDesc::UINT8);
    spec.attribute("compression", "lossless");
    ASSERT_TRUE(out->open(webp, spec));
    std::vector<unsigned char> red = {255, 0, 0, 255, 0, 0, 255, 0, 0, 255, 0, 0};
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, red.data()));
    out->close();
  }
  std::string png = (dir.path / "grey.png").string();
  {
    auto out = OIIO::ImageOutput::create(png);
    OIIO::ImageSpec spec(1, 1, 3, OIIO::TypeDesc::UINT8);
    ASSERT_TRUE(out->open(png, spec));
    std::vector<unsigned char> grey = {128, 128, 128};
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, grey.data()));
    out->close();
  }
  GltfBuilder g = quad_mesh();
  g.add("materials", {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
  g.doc["meshes"][0]["primitives"][0]["material"] = 0;
  g.add("images", {{"uri", "grey.png"}});
  g.add("images", {{"uri", "red.webp"}});
  g.add("textures", {{"source", 0}, {"extensions", {{"EXT_texture_webp", {{"source", 1}}}}}});
  g.doc["extensionsUsed"] = {"EXT_texture_webp"};
  g.add_node({{"mesh", 0}});
  Scene s = load_gltf(dir.write("webp.gltf", g.document().dump()));
  int tex = s.materials.at(0).texture(TEX_BASE_COLOR).index;
  ASSERT_GE(tex, 0);
  ASSERT_EQ(s.textures.at(size_t(tex)).width, 2);
  EXPECT_GE(s.textures[size_t(tex)].rgba8[0], 250);  // red, within WebP's lossy coding
  EXPECT_LE(s.textures[size_t(tex)].rgba8[1], 5);

  dir.write("red.webp", "not a WebP any more");  // the core source's PNG then
  Scene fallback = load_gltf((dir.path / "webp.gltf").string());
  tex = fallback.materials.at(0).texture(TEX_BASE_COLOR).index;
  ASSERT_GE(tex, 0);
  EXPECT_EQ(fallback.textures.at(size_t(tex)).width, 1);
  EXPECT_EQ(fallback.textures[size_t(tex)].rgba8[0], 128);
}

// EXT_meshopt_compression: attribute and triangle codecs, the uncompressed buffer a
// placeholder without data
TEST(GltfGeometry, MeshoptCompressedViewsDecode) {
  std::vector<float> positions = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  std::vector<uint16_t> indices = {0, 1, 2, 0, 2, 3};
  std::vector<unsigned char> vb(meshopt_encodeVertexBufferBound(4, 12));
  vb.resize(meshopt_encodeVertexBuffer(vb.data(), vb.size(), positions.data(), 4, 12));
  std::vector<unsigned char> ib(meshopt_encodeIndexBufferBound(6, 4));
  ib.resize(meshopt_encodeIndexBuffer(ib.data(), ib.size(), indices.data(), 6));
  ASSERT_FALSE(vb.empty());
  ASSERT_FALSE(ib.empty());
  std::string bin(vb.begin(), vb.end());
  bin.resize((bin.size() + 3) & ~size_t(3), '\0');
  size_t ib_offset = bin.size();
  bin.append(ib.begin(), ib.end());
  TempDir dir;
  dir.write("c.bin", bin);
  json j = {
      {"asset", {{"version", "2.0"}}},
      {"extensionsUsed", {"EXT_meshopt_compression"}},
      {"extensionsRequired", {"EXT_meshopt_compression"}},
      {"buffers",
       {{{"uri", "c.bin"}, {"byteLength", bin.size()}},
        {{"byteLength", 60}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}}}},
      {"bufferViews",
       {{{"buffer", 1},
         {"byteLength", 48},
         {"byteStride", 12},
         {"extensions",
          {{"EXT_meshopt_compression",
            {{"buffer", 0}, {"byteLength", vb.size()}, {"byteStride", 12}, {"count", 4}, {"mode", "ATTRIBUTES"}}}}}},
        {{"buffer", 1},
         {"byteOffset", 48},
         {"byteLength", 12},
         {"extensions",
          {{"EXT_meshopt_compression",
            {{"buffer", 0},
             {"byteOffset", ib_offset},
             {"byteLength", ib.size()},
             {"byteStride", 2},
             {"count", 6},
             {"mode", "TRIANGLES"}}}}}}}},
      {"accessors",
       {{{"bufferView", 0},
         {"componentType", 5126},
         {"count", 4},
         {"type", "VEC3"},
         {"min", {-1, -1, 0}},
         {"max", {1, 1, 0}}},
        {{"bufferView", 1}, {"componentType", 5123}, {"count", 6}, {"type", "SCALAR"}}}},
      {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}}},
      {"nodes", {{{"mesh", 0}}}},
      {"scenes", {{{"nodes", {0}}}}},
      {"scene", 0}};
  Scene s = load_gltf(dir.write("meshopt.gltf", j.dump()));
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
  expect_near(s.meshes[0].positions[2], {1, 1, 0});
  for (const auto& w : s.warnings) EXPECT_EQ(w.find("meshopt"), std::string::npos) << w;
}

// KHR_draco_mesh_compression: a primitive that does not decode is skipped with a warning
TEST(GltfGeometry, UndecodableDracoPrimitivesAreSkippedWithAWarning) {
  GltfBuilder g = quad_mesh();
  int garbage = g.add_floats({1, 2, 3, 4, 5, 6}, "SCALAR");
  int view = g.doc["accessors"][size_t(garbage)]["bufferView"];
  int points = g.add("accessors", {{"componentType", 5126}, {"count", 3}, {"type", "VEC3"}});
  g.doc["meshes"][0]["primitives"].push_back(
      {{"attributes", {{"POSITION", points}}},
       {"extensions", {{"KHR_draco_mesh_compression", {{"bufferView", view}, {"attributes", {{"POSITION", 0}}}}}}}});
  g.doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
  g.add_node({{"mesh", 0}});
  Scene s = load_json(g.document());
  EXPECT_EQ(s.triangles(), 2u);
  int warned = 0;
  for (const auto& w : s.warnings) warned += w.find("1 Draco-compressed primitive") != std::string::npos;
  EXPECT_EQ(warned, 1);
}

// The Khronos 2CylinderEngine, Draco-compressed (skipped without ../shared/gltf-samples)
TEST(GltfGeometry, DracoSampleAssetDecodes) {
  std::string dir = samples_dir();
  fs::path file = fs::path(dir) / "2CylinderEngine_draco" / "2CylinderEngine.gltf";
  if (dir.empty() || !fs::exists(file)) GTEST_SKIP() << "no ../shared/gltf-samples/2CylinderEngine_draco";
  Scene s = load_gltf(file.string());
  EXPECT_GT(s.triangles(), 100000u);
  for (const auto& w : s.warnings) EXPECT_EQ(w.find("Draco"), std::string::npos) << w;
  Bounds b = s.bounds();
  EXPECT_GT(b.hi.x - b.lo.x, 100.0f);  // millimetres: the engine is about half a metre long
}

}  // namespace candela::test
