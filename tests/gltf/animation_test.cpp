// glTF animations: the sampler's interpolation modes against values computed by hand, and
// documents posed at a time (node transforms, morph weights, cameras, lights,
// KHR_animation_pointer) as the loader reads them.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "base/error.hpp"
#include "gltf/animation.hpp"
#include "gltf/gltf_loader.hpp"
#include "support/test_support.hpp"

using nlohmann::json;

namespace candela::test {
namespace {

using gltf::AnimationCurve;
using gltf::Interpolation;
using gltf::sample_curve;

AnimationCurve curve(Interpolation mode, std::vector<float> times, std::vector<float> values, size_t width) {
  AnimationCurve c;
  c.interpolation = mode;
  c.times = std::move(times);
  c.values = std::move(values);
  c.width = width;
  return c;
}

float at(const AnimationCurve& c, double t) { return sample_curve(c, t, false)[0]; }

TEST(AnimationSampler, StepHoldsEachKeyUntilTheNext) {
  AnimationCurve c = curve(Interpolation::Step, {0, 1, 2}, {0, 10, 20}, 1);
  EXPECT_EQ(at(c, 0.0), 0.0f);
  EXPECT_EQ(at(c, 0.999), 0.0f);
  EXPECT_EQ(at(c, 1.0), 10.0f);  // exactly at a key: that key's value
  EXPECT_EQ(at(c, 1.5), 10.0f);
  EXPECT_EQ(at(c, 2.0), 20.0f);
}

TEST(AnimationSampler, OutsideTheKeysTheEndValues) {
  for (Interpolation mode : {Interpolation::Step, Interpolation::Linear}) {
    AnimationCurve c = curve(mode, {1, 3}, {5, 7}, 1);
    EXPECT_EQ(at(c, 0.0), 5.0f);
    EXPECT_EQ(at(c, 1.0), 5.0f);
    EXPECT_EQ(at(c, 3.0), 7.0f);
    EXPECT_EQ(at(c, 100.0), 7.0f);
  }
  // A cubic spline's end values are its keys' values, not their tangents
  AnimationCurve c = curve(Interpolation::CubicSpline, {1, 3}, {9, 5, 9, 9, 7, 9}, 1);
  EXPECT_EQ(at(c, 0.5), 5.0f);
  EXPECT_EQ(at(c, 4.0), 7.0f);
  // One key: its value at every time
  AnimationCurve one = curve(Interpolation::Linear, {2}, {4, 5, 6}, 3);
  EXPECT_EQ(sample_curve(one, 0.0, false), (std::vector<float>{4, 5, 6}));
  EXPECT_EQ(sample_curve(one, 9.0, false), (std::vector<float>{4, 5, 6}));
}

TEST(AnimationSampler, LinearInterpolatesEachComponent) {
  AnimationCurve c = curve(Interpolation::Linear, {0, 2, 3}, {0, 0, 0, 2, 4, -6, 3, 4, -6}, 3);
  std::vector<float> v = sample_curve(c, 0.5, false);  // a quarter of the way from key 0 to key 1
  EXPECT_FLOAT_EQ(v[0], 0.5f);
  EXPECT_FLOAT_EQ(v[1], 1.0f);
  EXPECT_FLOAT_EQ(v[2], -1.5f);
  v = sample_curve(c, 2.75, false);
  EXPECT_FLOAT_EQ(v[0], 2.75f);
  EXPECT_FLOAT_EQ(v[2], -6.0f);
}

// p(s) = (2s³ − 3s² + 1) v0 + (s³ − 2s² + s) td b0 + (−2s³ + 3s²) v1 + (s³ − s²) td a1
TEST(AnimationSampler, CubicSplineScalesTheTangentsByTheKeyInterval) {
  // Keys (in-tangent, value, out-tangent) at uneven times 0, 2, 5
  AnimationCurve c = curve(Interpolation::CubicSpline, {0, 2, 5}, {0, 1, 3, /**/ -1, 4, 1, /**/ 2, 5, 0}, 1);
  // t = 0.5: td = 2, s = 1/4: 0.84375·1 + 0.140625·2·3 + 0.15625·4 − 0.046875·2·(−1)
  EXPECT_NEAR(at(c, 0.5), 2.40625, 1e-6);
  // t = 3.5: td = 3, s = 1/2: 0.5·4 + 0.125·3·1 + 0.5·5 − 0.125·3·2
  EXPECT_NEAR(at(c, 3.5), 4.125, 1e-6);
  EXPECT_NEAR(at(c, 2.0), 4.0, 1e-6);  // at a key: its value
}

// Rotations: (x, y, z, w)
std::vector<float> rotation(const AnimationCurve& c, double t) { return sample_curve(c, t, true); }

// q and −q are one rotation: compares up to sign
void expect_same_rotation(const std::vector<float>& q, const std::vector<float>& want) {
  double dot = 0.0;
  for (int i = 0; i < 4; ++i) dot += double(q[i]) * want[i];
  EXPECT_NEAR(std::fabs(dot), 1.0, 1e-6) << q[0] << " " << q[1] << " " << q[2] << " " << q[3];
}

TEST(AnimationSampler, SlerpFollowsTheArc) {
  // 0 to 90 degrees about y; a third of the way: 30 degrees
  const double h = std::sqrt(0.5), k = std::cos(M_PI / 12), sk = std::sin(M_PI / 12);
  AnimationCurve c = curve(Interpolation::Linear, {0, 3}, {0, 0, 0, 1, 0, float(h), 0, float(h)}, 4);
  expect_same_rotation(rotation(c, 1.0), {0, float(sk), 0, float(k)});
}

TEST(AnimationSampler, SlerpTakesTheShorterArc) {
  // Identity to −(90 degrees about z), the same rotation as +90: halfway is +45 degrees, not
  // the long way round (−135)
  const float h = float(std::sqrt(0.5));
  AnimationCurve c = curve(Interpolation::Linear, {0, 1}, {0, 0, 0, 1, 0, 0, -h, -h}, 4);
  std::vector<float> q = rotation(c, 0.5);
  expect_same_rotation(q, {0, 0, float(std::sin(M_PI / 8)), float(std::cos(M_PI / 8))});
  // Antipodal keys (q and −q) are one rotation: it holds all the way
  AnimationCurve antipodal = curve(Interpolation::Linear, {0, 1}, {0, 0.6f, 0, 0.8f, 0, -0.6f, 0, -0.8f}, 4);
  for (double t : {0.25, 0.5, 0.75}) expect_same_rotation(rotation(antipodal, t), {0, 0.6f, 0, 0.8f});
}

TEST(AnimationSampler, CubicSplineRotationsAreNormalized) {
  // Zero tangents, identity to 90 degrees about x: halfway the Hermite blend is (h/2, 0, 0, (1 + h)/2)
  const float h = float(std::sqrt(0.5));
  AnimationCurve c = curve(Interpolation::CubicSpline, {0, 1},
                           {0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, /**/ 0, 0, 0, 0, h, 0, 0, h, 0, 0, 0, 0}, 4);
  std::vector<float> q = rotation(c, 0.5);
  double n = std::sqrt(double(q[0]) * q[0] + q[3] * q[3]);
  EXPECT_NEAR(n, 1.0, 1e-6);
  EXPECT_NEAR(q[0] / q[3], h / (1 + h), 1e-6);
}

// ---- documents posed at a time ----

Scene load(const json& j, std::optional<double> t, const std::string& animation = "") {
  LoadOptions o;
  o.anim_time = t;
  o.animation = animation;
  return load_gltf_from_memory(j.dump(), "", o);
}

glm::vec3 centre(const Scene& s) { return s.bounds().center(); }

bool has_warning(const Scene& s, const std::string& part) {
  for (const std::string& w : s.warnings)
    if (w.find(part) != std::string::npos) return true;
  return false;
}

// A quad about the origin in node 0, with an animation `name` of one channel
GltfBuilder quad_scene() {
  GltfBuilder g;
  g.add_mesh({quad_primitive({{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, -1)});
  g.add_node({{"mesh", 0}});
  return g;
}

void add_animation(GltfBuilder& g, const std::string& name, json target, const std::vector<float>& times,
                   const std::vector<float>& values, const char* type, const char* mode = "LINEAR") {
  int in = g.add_floats(times, "SCALAR"), out = g.add_floats(values, type);
  g.add("animations", {{"name", name},
                       {"samplers", {{{"input", in}, {"output", out}, {"interpolation", mode}}}},
                       {"channels", {{{"sampler", 0}, {"target", target}}}}});
}

TEST(AnimationPose, TranslationMovesTheNodeAndRestPoseIgnoresIt) {
  GltfBuilder g = quad_scene();
  add_animation(g, "slide", {{"node", 0}, {"path", "translation"}}, {1, 3}, {0, 0, 0, 2, 0, 0}, "VEC3");
  json j = g.document();
  Scene rest = load(j, std::nullopt);
  EXPECT_NEAR(centre(rest).x, 0.0f, 1e-6);
  EXPECT_TRUE(has_warning(rest, "animations are ignored"));
  ASSERT_EQ(rest.animations.size(), 1u);
  EXPECT_EQ(rest.animations[0].name, "slide");
  EXPECT_EQ(rest.animations[0].channels, 1u);
  EXPECT_EQ(rest.animations[0].start, 1.0);
  EXPECT_EQ(rest.animations[0].end, 3.0);
  EXPECT_EQ(rest.animations[0].targets, "translation of 1 node");
  EXPECT_NEAR(centre(load(j, 0.0)).x, 0.0f, 1e-6);  // before the first key
  EXPECT_NEAR(centre(load(j, 2.0)).x, 1.0f, 1e-6);
  EXPECT_NEAR(centre(load(j, 2.5, "slide")).x, 1.5f, 1e-6);
  EXPECT_NEAR(centre(load(j, 2.5, "0")).x, 1.5f, 1e-6);
  EXPECT_NEAR(centre(load(j, 7.0)).x, 2.0f, 1e-6);  // after the last
  EXPECT_FALSE(has_warning(load(j, 2.0), "animations are ignored"));
}

TEST(AnimationPose, UnknownAnimationsAreOneErrorNamingThem) {
  GltfBuilder g = quad_scene();
  add_animation(g, "slide", {{"node", 0}, {"path", "translation"}}, {0, 1}, {0, 0, 0, 1, 0, 0}, "VEC3");
  json j = g.document();
  std::string what = error_of([&] { load(j, 1.0, "walk"); });
  EXPECT_NE(what.find("no animation 'walk' (its animations: 0 'slide')"), std::string::npos) << what;
  EXPECT_NE(error_of([&] { load(j, 1.0, "1"); }), "");
  EXPECT_NE(error_of([&] { load(j, -1.0); }), "");
  EXPECT_NE(error_of([&] { load(j, std::nan("")); }), "");
  EXPECT_NE(error_of([&] { load(j, std::nullopt, "slide"); }), "");
}

TEST(AnimationPose, RotationAndScaleComposeAsTRS) {
  GltfBuilder g;
  // A quad from x = 1 to 3 so that rotation and scale move its centre
  g.add_mesh({quad_primitive({{1, -1, 0}, {3, -1, 0}, {3, 1, 0}, {1, 1, 0}}, -1)});
  g.add_node({{"mesh", 0}, {"translation", {0, 5, 0}}});
  const float h = float(std::sqrt(0.5));
  int in = g.add_floats({0, 1}, "SCALAR");
  int rot = g.add_floats({0, 0, 0, 1, 0, 0, h, h}, "VEC4");  // to 90 degrees about z
  int scale = g.add_floats({1, 1, 1, 3, 3, 3}, "VEC3");
  g.add(
      "animations",
      {{"samplers", {{{"input", in}, {"output", rot}, {"interpolation", "STEP"}}, {{"input", in}, {"output", scale}}}},
       {"channels",
        {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "rotation"}}}},
         {{"sampler", 1}, {"target", {{"node", 0}, {"path", "scale"}}}}}}});
  // t = 1: scale 3, then 90 degrees about z, then the node's own translation (0, 5, 0) kept:
  // the centre (2, 0, 0) goes to (0, 6, 0) + (0, 5, 0)
  glm::vec3 c = centre(load(g.document(), 1.0));
  EXPECT_NEAR(c.x, 0.0f, 1e-5);
  EXPECT_NEAR(c.y, 11.0f, 1e-5);
  // t = 0.5: STEP keeps the identity rotation, the scale is 2: (4, 5, 0)
  c = centre(load(g.document(), 0.5));
  EXPECT_NEAR(c.x, 4.0f, 1e-5);
  EXPECT_NEAR(c.y, 5.0f, 1e-5);
}

// Morph weights: the node's mesh's targets, weighted by the sampled weights (one output per
// target a key)
TEST(AnimationPose, WeightsMorphTheMesh) {
  GltfBuilder g;
  g.add_mesh({quad_primitive({{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, -1)});
  int dz = g.add_floats({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3");
  int dx = g.add_floats({2, 0, 0, 2, 0, 0, 2, 0, 0, 2, 0, 0}, "VEC3");
  g.doc["meshes"][0]["primitives"][0]["targets"] = {{{"POSITION", dz}}, {{"POSITION", dx}}};
  g.doc["meshes"][0]["weights"] = {0.5, 0.5};
  g.add_node({{"mesh", 0}});
  add_animation(g, "morph", {{"node", 0}, {"path", "weights"}}, {0, 2}, {0, 1, 1, 0}, "SCALAR");
  json j = g.document();
  glm::vec3 rest = centre(load(j, std::nullopt)), quarter = centre(load(j, 0.5)), end = centre(load(j, 9.0));
  EXPECT_NEAR(rest.x, 1.0f, 1e-6);  // the mesh's default weights
  EXPECT_NEAR(rest.z, 0.5f, 1e-6);
  EXPECT_NEAR(quarter.z, 0.25f, 1e-6);  // weights (0.25, 0.75)
  EXPECT_NEAR(quarter.x, 1.5f, 1e-6);
  EXPECT_NEAR(end.z, 1.0f, 1e-6);
  EXPECT_NEAR(end.x, 0.0f, 1e-6);
  // An output that does not hold one value per target is an error
  add_animation(g, "bad", {{"node", 0}, {"path", "weights"}}, {0, 2}, {0, 1, 1}, "SCALAR");
  EXPECT_NE(error_of([&] { load(g.document(), 1.0, "bad"); }), "");
}

TEST(AnimationPose, CamerasAndLightsMoveWithTheirNodes) {
  GltfBuilder g = quad_scene();
  int cam = g.add_camera({0, 0, 5}, {0, 0, 0}, 0.8f);
  g.doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}, {"intensity", 1.0}}};
  g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  int light = g.add_node({{"translation", {0, 3, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  int in = g.add_floats({0, 1}, "SCALAR");
  int cam_path = g.add_floats({0, 0, 5, 4, 0, 5}, "VEC3"), light_path = g.add_floats({0, 3, 0, 0, 7, 0}, "VEC3");
  g.add("animations", {{"samplers", {{{"input", in}, {"output", cam_path}}, {{"input", in}, {"output", light_path}}}},
                       {"channels",
                        {{{"sampler", 0}, {"target", {{"node", cam}, {"path", "translation"}}}},
                         {{"sampler", 1}, {"target", {{"node", light}, {"path", "translation"}}}}}}});
  Scene s = load(g.document(), 0.25);
  ASSERT_TRUE(s.camera);
  EXPECT_NEAR(s.camera->position.x, 1.0f, 1e-6);
  EXPECT_NEAR(s.camera->position.z, 5.0f, 1e-6);
  ASSERT_EQ(s.punctual_lights.size(), 1u);
  EXPECT_NEAR(s.punctual_lights[0].position.y, 4.0f, 1e-6);
}

// All animations play together by default, in order (a later channel on the same property wins)
TEST(AnimationPose, AllAnimationsTogetherByDefault) {
  GltfBuilder g = quad_scene();
  g.add_node({{"mesh", 0}, {"translation", {0, 10, 0}}});
  add_animation(g, "a", {{"node", 0}, {"path", "translation"}}, {0, 1}, {0, 0, 0, 0, 0, 4}, "VEC3");
  add_animation(g, "b", {{"node", 1}, {"path", "translation"}}, {0, 1}, {0, 10, 0, 0, 10, 4}, "VEC3");
  json j = g.document();
  EXPECT_NEAR(centre(load(j, 0.5)).z, 2.0f, 1e-6);
  EXPECT_NEAR(centre(load(j, 0.5, "a")).z, 1.0f, 1e-6);  // node 1 at rest
}

TEST(AnimationPose, AnimationPointerTargetsNodesAndMaterials) {
  GltfBuilder g;
  g.add("materials", {{"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 1}}}}});
  g.add_mesh({quad_primitive({{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, 0)});
  g.add_node({{"mesh", 0}});
  g.doc["extensionsUsed"] = {"KHR_animation_pointer"};
  int in = g.add_floats({0, 1}, "SCALAR");
  int move = g.add_floats({0, 0, 0, 0, 2, 0}, "VEC3"), colour = g.add_floats({1, 1, 1, 1, 1, 0.5f, 1, 1}, "VEC4");
  int other = g.add_floats({0, 1}, "SCALAR");
  auto pointer = [](const std::string& p) {
    return json{{"path", "pointer"}, {"extensions", {{"KHR_animation_pointer", {{"pointer", p}}}}}};
  };
  g.add("animations",
        {{"samplers",
          {{{"input", in}, {"output", move}}, {{"input", in}, {"output", colour}}, {{"input", in}, {"output", other}}}},
         {"channels",
          {{{"sampler", 0}, {"target", pointer("/nodes/0/translation")}},
           {{"sampler", 1},
            {"target", pointer("/materials/0/pbrMetallicRoughness/"
                               "baseColorFactor")}},
           {{"sampler", 2},
            {"target", pointer("/materials/0/extensions/"
                               "KHR_materials_ior/ior")}}}}});
  Scene rest = load(g.document(), std::nullopt);
  ASSERT_EQ(rest.animations.size(), 1u);
  EXPECT_EQ(rest.animations[0].targets, "3 KHR_animation_pointer properties");
  Scene s = load(g.document(), 0.5);
  EXPECT_NEAR(centre(s).y, 1.0f, 1e-6);
  EXPECT_NEAR(s.materials[0].base_color.y, 0.75f, 1e-6);
  EXPECT_NEAR(s.materials[0].base_color.x, 1.0f, 1e-6);
  size_t left_out = 0;
  for (const std::string& w : s.warnings)
    left_out += w.find("/materials/0/extensions/KHR_materials_ior/ior is not supported") != std::string::npos;
  EXPECT_EQ(left_out, 1u);
}

// Pointers into a material's extensions and its textures' KHR_texture_transform
TEST(AnimationPose, AnimationPointerTargetsExtensionNumbers) {
  GltfBuilder g;
  g.add("images", {{"uri",
                    "data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAIAAACQd1PeAAAACW9GRnMAAAAAAAAAAADa"
                    "KrbOAAAADElEQVQImWP4//8/AAX+Av5Y8msOAAAAAElFTkSuQmCC"}});
  g.add("textures", {{"source", 0}});
  json material = {{"emissiveFactor", {1, 1, 1}}};
  material["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] = 2.0;
  json& base = material["pbrMetallicRoughness"]["baseColorTexture"];
  base["index"] = 0;
  base["extensions"]["KHR_texture_transform"]["offset"] = {0, 0};
  g.add("materials", material);
  g.add_mesh({quad_primitive({{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, 0)});
  g.add_node({{"mesh", 0}});
  g.doc["extensionsUsed"] = {"KHR_animation_pointer", "KHR_materials_emissive_strength", "KHR_texture_transform"};
  int in = g.add_floats({0, 1}, "SCALAR");
  int strength = g.add_floats({2, 6}, "SCALAR"), offset = g.add_floats({0, 0, 1, -2}, "VEC2");
  int index = g.add_floats({0, 1}, "SCALAR");
  auto pointer = [](const std::string& p) {
    return json{{"path", "pointer"}, {"extensions", {{"KHR_animation_pointer", {{"pointer", p}}}}}};
  };
  const std::string tex = "/materials/0/pbrMetallicRoughness/baseColorTexture";
  g.add("animations",
        {{"samplers",
          {{{"input", in}, {"output", strength}},
           {{"input", in}, {"output", offset}},
           {{"input", in}, {"output", index}}}},
         {"channels",
          {{{"sampler", 0},
            {"target", pointer("/materials/0/extensions/KHR_materials_emissive_strength/emissiveStrength")}},
           {{"sampler", 1}, {"target", pointer(tex + "/extensions/KHR_texture_transform/offset")}},
           {{"sampler", 2}, {"target", pointer(tex + "/index")}}}}});
  Scene s = load(g.document(), 0.25);
  EXPECT_NEAR(s.materials[0].emission.x, 3.0f, 1e-5);  // strength 2 -> 6, a quarter of the way
  const TextureSlot& slot = s.materials[0].texture(TEX_BASE_COLOR);
  ASSERT_NE(slot.index, NO_TEXTURE);
  glm::vec2 uv = glm::vec2(slot.transform * glm::vec3(0.0f, 0.0f, 1.0f));
  EXPECT_NEAR(uv.x, 0.25f, 1e-6);
  EXPECT_NEAR(uv.y, -0.5f, 1e-6);
  EXPECT_TRUE(has_warning(s, tex + "/index is not supported"));  // an index is no animatable number
}

// The glTF validator's files with animations (malformed ones among them), posed: each loads
// or is rejected with a message, nothing else
TEST(AnimationPose, ValidatorCorpusPosesOrFailsWithError) {
  namespace fs = std::filesystem;
  size_t animated = 0;
  for (const auto& entry : fs::recursive_directory_iterator(fs::path(CANDELA_SOURCE_DIR) / "tests/fuzz/validator")) {
    if (!entry.is_regular_file() || entry.path().extension() != ".gltf") continue;
    std::stringstream text;
    text << std::ifstream(entry.path()).rdbuf();
    if (text.str().find("\"animations\"") == std::string::npos) continue;
    ++animated;
    SCOPED_TRACE(entry.path().string());
    LoadOptions o;
    for (double t : {0.0, 0.5, 100.0}) {
      o.anim_time = t;
      try {
        load_gltf(entry.path().string(), o);
      } catch (const Error& e) {
        EXPECT_STRNE(e.what(), "");
      } catch (...) {
        ADD_FAILURE() << "threw something other than candela::Error";
      }
    }
  }
  EXPECT_GE(animated, 20u);
}

}  // namespace
}  // namespace candela::test
