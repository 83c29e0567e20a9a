// Every light type of CD_LIGHTS (cl/shared/device_types.h) has what the list promises, so that
// a new type is exactly its places (docs/extending.md): its parameters (the member of
// LightParams named as its entry: static_asserts in host/base/device_types.hpp), the five
// kernel functions lights_NAME_* in a program file of cl/lights/, its power and its bounds
// in the light tree (light_power_NAME, light_bounds_NAME in host/compile/light_types.cpp,
// which the generated dispatch calls) and its name. Also the spot profile that host and
// kernel share (cl/shared/light_profiles.h).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "base/device_types.hpp"
#include "base/error.hpp"
#include "compile/scene_compiler.hpp"

namespace candela::test {
namespace {

namespace fs = std::filesystem;

struct LightEntry {
  unsigned id;
  std::string name;
};
#define CD_LIGHT_ENTRY(id, name, feature) {id, #name},
const std::vector<LightEntry> kLights = {CD_LIGHTS(CD_LIGHT_ENTRY)};
#undef CD_LIGHT_ENTRY

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The text without // and /* */ comments
std::string strip_comments(const std::string& text) {
  return std::regex_replace(std::regex_replace(text, std::regex(R"(//[^\n]*)"), ""), std::regex(R"(/\*[\s\S]*?\*/)"),
                            "");
}

// A scene of one emissive triangle, compiled: buffers light_power and light_bounds can read
CompiledScene emissive_triangle() {
  Scene s;
  MaterialDesc m;
  m.emission = glm::vec3(1.0f);
  s.materials.push_back(m);
  MeshDesc mesh;
  mesh.positions = {glm::vec3(0.0f), glm::vec3(1.0f, 0.0f, 0.0f), glm::vec3(0.0f, 1.0f, 0.0f)};
  mesh.indices = {0, 1, 2};
  s.meshes.push_back(mesh);
  return compile_scene(s);
}

}  // namespace

// Each type's kernel functions are defined, each once, in the program's files of cl/lights/
TEST(LightTypes, EveryTypeHasItsKernelFunctions) {
  const fs::path root(CANDELA_SOURCE_DIR);
  std::string program = read_text(root / "cl" / "program.cmake");
  std::string code;
  size_t files = 0;
  for (const auto& f : fs::directory_iterator(root / "cl" / "lights")) {
    if (f.path().extension() != ".cl") continue;
    std::string rel = "cl/lights/" + f.path().filename().string();
    EXPECT_NE(program.find("  " + rel + "\n"), std::string::npos) << rel << " is not in cl/program.cmake";
    code += strip_comments(read_text(f.path())) + "\n";
    ++files;
  }
  ASSERT_GE(files, 5u) << "cl/lights/ holds the dispatch, the tree and a file per family of types";
  for (const LightEntry& e : kLights) {
    SCOPED_TRACE(e.name);
    for (const char* suffix : {"sample", "pdf", "extent", "omega_bound", "prim"}) {
      std::string fn = "lights_" + e.name + "_" + suffix;
      std::regex definition(R"((^|\n)\w[\w \t\*]*\b)" + fn + R"(\s*\([^;{}]*\)\s*\{)");
      auto begin = std::sregex_iterator(code.begin(), code.end(), definition);
      EXPECT_EQ(std::distance(begin, std::sregex_iterator()), 1) << fn << "() defined once in cl/lights/";
    }
  }
}

// light_power and light_bounds dispatch to every listed type and to no other
TEST(LightTypes, PowerAndTreeBoundsCoverEveryType) {
  CompiledScene c = emissive_triangle();
  ASSERT_EQ(c.buffers.lights.size(), 1u);
  ASSERT_EQ(kLights.size(), dev::kLightTypeCount);
  std::set<std::string> members;
  for (const LightEntry& e : kLights) {
    SCOPED_TRACE(e.name);
    EXPECT_STREQ(dev::light_type_name(e.id), e.name.c_str());
    dev::Light l = c.buffers.lights[0];
    l.type = e.id;
    for (float& r : l.radiance) r = 1.0f;
    if (e.id == LIGHT_SPOT) l.params.spot = {{0, 0, 0}, {0, 0, -1}, 2.0f, -1.0f};
    EXPECT_GT(light_power(l, c.buffers, 1.0, 1.0), 0.0);
    LightBounds b;
    if (light_bounds(l, c.buffers, 1.0, &b)) {
      members.insert(e.name);
      EXPECT_GT(b.intensity, 0.0);
      EXPECT_LE(b.lo.x, b.hi.x);
      EXPECT_GE(b.theta_e, 0.0);
    }
  }
  // The finite lights make the tree; lights at infinity stay with the alias table
  EXPECT_EQ(members, (std::set<std::string>{"triangle", "point", "spot"}));
  dev::Light unknown = c.buffers.lights[0];
  unknown.type = dev::kLightTypeCount;
  LightBounds b;
  EXPECT_THROW(light_bounds(unknown, c.buffers, 1.0, &b), Error);
  EXPECT_THROW(light_power(unknown, c.buffers, 1.0, 1.0), Error);
}

// The spot profile both sides use: 0 outside the outer cone, 1 inside the inner one, and
// t^2 between, t linear in the cosine; the cone parameters of the extension's reference form
TEST(LightTypes, SpotProfile) {
  const double inner = 0.3, outer = 0.5;
  dev::SpotCone cone = dev::spot_cone(inner, outer);
  double ci = std::cos(inner), co = std::cos(outer);
  EXPECT_FLOAT_EQ(cone.scale, float(1.0 / (ci - co)));
  EXPECT_FLOAT_EQ(cone.offset, float(-co / (ci - co)));
  EXPECT_EQ(dev::spot_profile(float(std::cos(0.6)), cone.scale, cone.offset), 0.0f);
  EXPECT_EQ(dev::spot_profile(float(std::cos(0.2)), cone.scale, cone.offset), 1.0f);
  EXPECT_EQ(dev::spot_profile(-1.0f, cone.scale, cone.offset), 0.0f);
  for (double a : {0.32, 0.4, 0.48}) {
    double t = (std::cos(a) - co) / (ci - co);
    EXPECT_NEAR(dev::spot_profile(float(std::cos(a)), cone.scale, cone.offset), t * t, 1e-4) << a;
  }
  // A cone of inner = outer: the extension's 0.001 floor on the cosines' difference
  dev::SpotCone sharp = dev::spot_cone(outer, outer);
  EXPECT_FLOAT_EQ(sharp.scale, 1000.0f);
}

}  // namespace candela::test
