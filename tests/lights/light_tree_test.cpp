// The light tree (host/compile/light_tree.cpp, cl/lights/light_tree.cl) on the real kernel code:
//  - its structure: every tree light's trail leads to its leaf, every slot of a node bounds
//    its child's positions and emission cones;
//  - lights_select_pmf sums to 1 over the lights at random shading points (inside the
//    lights' bounds too, and in a medium, n = 0), and is > 0 for every light that can
//    light the point, also along trails deeper than 16 levels (a tree built to be deep);
//  - the frequencies of lights_select match lights_select_pmf (chi-square, alpha 0.01 with
//    the Sidak correction over this file's chi-square tests), and the pmf it reports is
//    the one lights_select_pmf computes;
//  - renders with the tree and with selection by power alone agree within standard errors,
//    and nee and auto still agree with the tree.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <glm/glm.hpp>
#include <limits>
#include <memory>
#include <random>

#include "compile/camera.hpp"
#include "compile/light_tree.hpp"
#include "compile/scene_compiler.hpp"
#include "gltf/gltf_loader.hpp"
#include "render/renderer.hpp"
#include "support/stats.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

constexpr int kChiSquareTests = 3 * 3;  // per device: 3 contexts on 3 scenes
const double kAlpha = sidak_alpha(0.01, kChiSquareTests);

CompiledScene compiled(const std::string& file) { return compile_scene(load_gltf(scene_path(file))); }

// What a node's slot bounds: its child's sphere (and the box around that sphere), emission
// cone and intensity
struct Slot {
  glm::dvec3 centre, axis;
  double radius, cos_o, sin_o, cos_e, intensity;
  glm::dvec3 lo() const { return centre - radius; }
  glm::dvec3 hi() const { return centre + radius; }
};

Slot slot_of(const dev::LightTreeNode& n, uint32_t k) {
  return {{n.centre[0][k], n.centre[1][k], n.centre[2][k]},
          {n.axis[0][k], n.axis[1][k], n.axis[2][k]},
          n.radius[k],
          n.cos_o[k],
          n.sin_o[k],
          n.cos_e[k],
          n.intensity[k]};
}

// The points a light's bounds must hold: a triangle's corners, a point or spot's position
std::vector<glm::dvec3> light_points(const CompiledScene& c, const dev::Light& light) {
  std::vector<glm::dvec3> points;
  if (light.type == LIGHT_TRIANGLE) {
    const dev::Prim& p = c.buffers.prims[light.index];
    for (int k = 0; k < 3; ++k) {
      size_t v = 3 * size_t(p.v[k]);
      points.emplace_back(c.buffers.positions[v], c.buffers.positions[v + 1], c.buffers.positions[v + 2]);
    }
  } else {
    const float* pos = light.type == LIGHT_SPOT ? light.params.spot.position : light.params.point.position;
    points.emplace_back(pos[0], pos[1], pos[2]);
  }
  return points;
}

// Whether cone (axis a, cos_o a) holds cone b: the angle between the axes plus b's theta_o
// within a's theta_o (1e-5 rad of rounding)
bool cone_holds(const Slot& a, const Slot& b) {
  double theta_a = std::acos(std::clamp(a.cos_o, -1.0, 1.0));
  double theta_b = std::acos(std::clamp(b.cos_o, -1.0, 1.0));
  double d = std::acos(std::clamp(glm::dot(a.axis, b.axis), -1.0, 1.0));
  return theta_a >= 3.14159 || d + theta_b <= theta_a + 1e-5;
}

// Checks the tree's structure and counts its cluster nodes
void check_tree(const CompiledScene& c, size_t* clusters) {
  const auto& nodes = c.buffers.light_tree;
  const auto& trails = c.buffers.light_trails;
  ASSERT_FALSE(nodes.empty());
  ASSERT_EQ(trails.size(), c.buffers.lights.size());
  size_t in_tree = 0;
  double share = 0.0;
  // Per slot (node x width + slot): the farthest point of a light below it from its centre
  std::vector<double> farthest(nodes.size() * LIGHT_TREE_WIDTH, 0.0);
  for (size_t l = 0; l < trails.size(); ++l) {
    const dev::Light& light = c.buffers.lights[l];
    bool finite = light.type == LIGHT_TRIANGLE || light.type == LIGHT_POINT || light.type == LIGHT_SPOT;
    if (!finite) {
      EXPECT_EQ(trails[l].depth, LIGHT_TREE_NONE);
      continue;
    }
    ++in_tree;
    share += light.pmf;
    ASSERT_GT(trails[l].depth, 0u);
    uint32_t node = 0;
    for (uint32_t k = 0; k < trails[l].depth; ++k) {
      ASSERT_LT(node, nodes.size());
      uint32_t slot = (trails[l].bits[k >> 4] >> (2 * (k & 15))) & 3u;
      ASSERT_GT(nodes[node].intensity[slot], 0.0f) << "light " << l << "'s trail enters an empty slot";
      bool last = k + 1 == trails[l].depth;
      ASSERT_EQ(nodes[node].leaf[slot], last ? LIGHT_TREE_LEAF : LIGHT_TREE_INTERIOR) << "light " << l;
      // Every slot on the trail holds the light in its sphere, and stores its cone's sine
      Slot s = slot_of(nodes[node], slot);
      for (const glm::dvec3& q : light_points(c, light)) {
        EXPECT_LE(glm::length(q - s.centre), s.radius) << "light " << l << " outside its ancestor's sphere";
        double& f = farthest[node * LIGHT_TREE_WIDTH + slot];
        f = std::max(f, glm::length(q - s.centre));
      }
      EXPECT_NEAR(s.sin_o, std::sqrt(std::max(1.0 - s.cos_o * s.cos_o, 0.0)), 1e-6);
      if (last) {
        EXPECT_EQ(nodes[node].child[slot], l) << "light " << l << "'s trail ends at another light's leaf";
      }
      node = nodes[node].child[slot];
    }
  }
  // Every node but the root fills one slot, and every light one
  size_t slots = 0;
  for (const dev::LightTreeNode& n : nodes)
    for (uint32_t k = 0; k < LIGHT_TREE_WIDTH; ++k) slots += n.intensity[k] > 0.0f ? 1 : 0;
  EXPECT_EQ(slots, nodes.size() - 1 + in_tree);
  uint32_t depth = 0;
  for (const dev::LightTreeTrail& t : trails)
    if (t.depth != LIGHT_TREE_NONE) depth = std::max(depth, t.depth);
  std::printf("%zu lights in the tree, %zu nodes, deepest leaf at depth %u\n", in_tree, nodes.size(), depth);
  // No trail's least pmf (every turn at the least probability a child can get) underflows
  double q = double(nodes[0].min_prob) / (1.0 + 4.0 * double(nodes[0].min_prob));
  EXPECT_GE(depth * std::log2(q) + std::log2(double(nodes[0].share)), -124.01);
  EXPECT_NEAR(nodes[0].share, share, 1e-5);
  EXPECT_EQ(nodes[0].holds_all, in_tree == c.buffers.lights.size() ? 1u : 0u);
  // No sphere larger than the one around its lights' box can be: each coordinate of the box's
  // farthest corner is some light point's, so that corner is within sqrt(3) x the farthest
  // point's distance
  for (size_t i = 0; i < nodes.size(); ++i)
    for (uint32_t k = 0; k < LIGHT_TREE_WIDTH; ++k)
      if (nodes[i].intensity[k] > 0.0f) {
        EXPECT_LE(nodes[i].radius[k], std::sqrt(3.0) * farthest[i * LIGHT_TREE_WIDTH + k] * (1.0 + 1e-6) + 1e-30)
            << "node " << i << " slot " << k;
      }
  // A tree of one light or one planar emitter would pick as the alias table does: none is built
  EXPECT_EQ(nodes[0].cluster, 0u);
  *clusters = 0;
  for (size_t i = 0; i < nodes.size(); ++i) {
    const dev::LightTreeNode& n = nodes[i];
    int filled = 0;
    for (uint32_t k = 0; k < LIGHT_TREE_WIDTH; ++k) {
      if (!(n.intensity[k] > 0.0f)) continue;
      ++filled;
      Slot s = slot_of(n, k);
      if (n.cluster) {  // children by their share of the intensity, clusters too
        if (n.leaf[k] == LIGHT_TREE_INTERIOR) {
          EXPECT_EQ(nodes[n.child[k]].cluster, 1u) << "node " << i;
        }
        double facing = glm::dot(s.axis, slot_of(n, 0).axis);
        EXPECT_NEAR(s.cos_o < -0.5 ? std::abs(facing) : facing, 1.0, 1e-6)
            << "a cluster's lights lie in one plane, facing one way when single-sided";
      }
      if (n.leaf[k] == LIGHT_TREE_LEAF) continue;
      // The slot bounds its child's slots
      const dev::LightTreeNode& m = nodes[n.child[k]];
      for (uint32_t j = 0; j < LIGHT_TREE_WIDTH; ++j) {
        if (!(m.intensity[j] > 0.0f)) continue;
        Slot ch = slot_of(m, j);
        EXPECT_LE(glm::length(ch.centre - s.centre), s.radius) << "node " << i << ": a child's centre outside";
        EXPECT_TRUE(cone_holds(s, ch)) << "node " << i;
        EXPECT_LE(s.cos_e, ch.cos_e);
        EXPECT_GE(s.intensity, 0.999 * ch.intensity);
      }
    }
    EXPECT_GE(filled, 2) << "node " << i << " has one child";
    if (n.cluster) ++*clusters;
  }
}

TEST(LightTree, TrailsLeadToLeavesAndNodesBoundChildren) {
  // many-lights: 4096 emissive quads at different heights, each one planar emitter of two
  // triangles (one cluster node); punctual: three punctual lights
  size_t clusters = 0;
  check_tree(compiled("lights/many-lights.gltf"), &clusters);
  EXPECT_EQ(clusters, 4096u);
  check_tree(compiled("lights/punctual.gltf"), &clusters);
  EXPECT_EQ(clusters, 0u);
}

// A deep tree: triangles in parallel planes at geometric spacing, each twice the size of the
// one before, so that every split cuts off the largest (a chain of binary nodes, which the
// four-wide tree opens three at a time) until the builder turns to median splits. Trails
// then run past level 16, into the trail's second word, and the least-probability floor
// holds at that depth. Every triangle faces +x (single-sided); equal powers, the alias
// table's pmf set as the scene compiler sets it.
constexpr int kDeepLights = 120;
CompiledScene deep_tree_scene(int* depth) {
  CompiledScene c;
  c.buffers.materials.emplace_back();  // single-sided
  std::vector<double> power(kDeepLights, 1.0), pmf;
  c.buffers.light_alias = alias_table(power, &pmf);
  for (int i = 0; i < kDeepLights; ++i) {
    float x = std::ldexp(1.0f, i - 60);
    for (const glm::vec3& v : {glm::vec3(x, 0, 0), glm::vec3(x, x, 0), glm::vec3(x, 0, x)})
      c.buffers.positions.insert(c.buffers.positions.end(), {v.x, v.y, v.z});
    dev::Prim prim{{uint32_t(3 * i), uint32_t(3 * i + 1), uint32_t(3 * i + 2)}, 0u};
    c.buffers.prims.push_back(prim);
    dev::Light light{};
    light.type = LIGHT_TRIANGLE;
    light.index = uint32_t(i);
    light.params.triangle.area = 0.5f * x * x;
    light.pmf = float(pmf[size_t(i)]);
    c.buffers.lights.push_back(light);
  }
  LightTree tree = build_light_tree(c.buffers, power, pmf);
  c.buffers.light_tree = tree.nodes;
  c.buffers.light_trails = tree.trails;
  c.features.light_tree = true;
  *depth = tree.depth;
  return c;
}

TEST(LightTree, DeepTreeTrailsAndFloor) {
  int depth = 0;
  CompiledScene c = deep_tree_scene(&depth);
  size_t clusters = 0;
  check_tree(c, &clusters);
  EXPECT_GT(depth, 16) << "no trail reaches the trail's second word";
}

// One quad light (the Cornell box; a large panel) is one planar emitter: no tree is built,
// and the kernel is compiled without one
TEST(LightTree, NoTreeForOnePlanarEmitter) {
  for (const char* f : {"cornell-box/cornell-box.gltf", "lights/large-light-glossy.gltf"}) {
    SCOPED_TRACE(f);
    CompiledScene c = compiled(f);
    EXPECT_TRUE(c.buffers.light_tree.empty());
    EXPECT_FALSE(c.features.light_tree);
    ASSERT_EQ(c.buffers.light_trails.size(), c.buffers.lights.size());
    for (const dev::LightTreeTrail& t : c.buffers.light_trails) EXPECT_EQ(t.depth, LIGHT_TREE_NONE);
  }
  EXPECT_TRUE(compiled("lights/many-lights.gltf").features.light_tree);
}

// Points that can light p: a point light always, a spot when p lies inside its outer cone,
// a single-sided triangle when p lies in front of its plane (by a margin)
bool can_light(const CompiledScene& c, size_t l, const glm::dvec3& p) {
  const dev::Light& light = c.buffers.lights[l];
  if (light.type == LIGHT_POINT) return true;
  if (light.type == LIGHT_SPOT) {
    const dev::SpotLight& s = light.params.spot;
    glm::dvec3 d = glm::normalize(p - glm::dvec3(s.position[0], s.position[1], s.position[2]));
    double cos_outer = -double(s.cone_offset) / double(s.cone_scale);
    return glm::dot(d, glm::dvec3(s.axis[0], s.axis[1], s.axis[2])) > cos_outer + 1e-3;
  }
  if (light.type != LIGHT_TRIANGLE) return true;
  const dev::Prim& pr = c.buffers.prims[light.index];
  glm::dvec3 v[3];
  for (int k = 0; k < 3; ++k)
    v[k] = {c.buffers.positions[3 * pr.v[k]], c.buffers.positions[3 * pr.v[k] + 1],
            c.buffers.positions[3 * pr.v[k] + 2]};
  glm::dvec3 n = glm::normalize(glm::cross(v[1] - v[0], v[2] - v[0]));
  if (c.buffers.materials[pr.material].flags & MATERIAL_DOUBLE_SIDED) return true;
  return glm::dot(n, p - v[0]) > 1e-3;
}

class LightTreeTest : public DeviceTest {
 protected:
  // A shipped scene, or "deep" (deep_tree_scene)
  void use(const std::string& file) {
    int depth = 0;
    use(file == "deep" ? deep_tree_scene(&depth) : compiled(file));
  }
  void use(CompiledScene c) {
    compiled_ = std::move(c);
    scene_ = std::make_unique<SceneOnDevice>(rig(), compiled_);
  }
  CompiledScene compiled_;
  std::unique_ptr<SceneOnDevice> scene_;
};

// Random shading points over the lights' bounds grown by half (so some lie inside node
// spheres, some outside), with random normals; every fourth in a medium (n = 0). In the deep
// tree's scene (`deep`), points in front of every triangle (x beyond the largest's plane),
// so that every light can light them, down to the deepest trail.
void random_contexts(const CompiledScene& c, int count, std::vector<cl_float4>* ps, std::vector<cl_float4>* ns,
                     bool deep = false) {
  const dev::LightTreeNode& root = c.buffers.light_tree[0];
  glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
  for (uint32_t k = 0; k < LIGHT_TREE_WIDTH; ++k) {
    if (!(root.intensity[k] > 0.0f)) continue;
    lo = glm::min(lo, slot_of(root, k).lo());
    hi = glm::max(hi, slot_of(root, k).hi());
  }
  glm::dvec3 mid = 0.5 * (lo + hi), half = 0.75 * (hi - lo) + 0.5;
  if (deep) {
    mid = glm::dvec3(2.0 * hi.x, 0.0, 0.0);
    half = glm::dvec3(0.5 * hi.x, 2.0 * hi.y, 2.0 * hi.z);
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> g;
  for (int i = 0; i < count; ++i) {
    ps->push_back(f4(mid + glm::dvec3(u(rng), u(rng), u(rng)) * half));
    glm::dvec3 n = glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)));
    ns->push_back(f4(i % 4 == 3 ? glm::dvec3(0.0) : n));
  }
}

TEST_P(LightTreeTest, PmfSumsToOneAndCoversEveryLightThatCanContribute) {
  if (IsSkipped()) return;
  for (const std::string f : {"lights/many-lights.gltf", "lights/punctual.gltf", "deep"}) {
    SCOPED_TRACE(f);
    use(f);
    constexpr int kContexts = 64;
    std::vector<cl_float4> ps, ns;
    random_contexts(compiled_, kContexts, &ps, &ns, f == "deep");
    size_t n = compiled_.buffers.lights.size();
    auto out = rig().output<float>(kContexts * n);
    rig().run("test_lights_select_pmf", kContexts * n, *scene_, rig().input(ps), rig().input(ns), out);
    std::vector<float> pmf = out.read();
    for (int c = 0; c < kContexts; ++c) {
      double sum = 0.0;
      for (size_t l = 0; l < n; ++l) {
        sum += pmf[c * n + l];
        if (can_light(compiled_, l, d3(ps[size_t(c)]))) {
          EXPECT_GT(pmf[c * n + l], 0.0f) << "light " << l << " at context " << c;
        }
      }
      EXPECT_NEAR(sum, 1.0, 1e-4) << "context " << c;
    }
  }
}

TEST_P(LightTreeTest, SelectionFrequenciesMatchPmf) {
  if (IsSkipped()) return;
  for (const std::string f : {"lights/many-lights.gltf", "lights/punctual.gltf", "deep"}) {
    SCOPED_TRACE(f);
    use(f);
    std::vector<cl_float4> ps, ns;
    random_contexts(compiled_, 3, &ps, &ns, f == "deep");
    ns[2] = f4(glm::dvec3(0.0));  // one in a medium
    size_t n = compiled_.buffers.lights.size();
    constexpr size_t kSamples = 1 << 20;
    for (int c = 0; c < 3; ++c) {
      auto out = rig().output<cl_float4>(kSamples);
      rig().run("test_lights_select", kSamples, *scene_, ps[size_t(c)], ns[size_t(c)], cl_uint(11 + c), out);
      std::vector<cl_float4> s = out.read();
      std::vector<double> observed(n, 0.0), expected(n, 0.0);
      for (const cl_float4& x : s) {
        if (x.s[3] == 0.0f) continue;  // selection failed: counted as no light (expected 1 - sum)
        size_t l = size_t(x.s[0]);
        ASSERT_LT(l, n);
        observed[l] += 1.0;
        ASSERT_EQ(x.s[1], x.s[2]) << "the sampled pmf differs from lights_select_pmf";
        expected[l] = double(x.s[2]);
      }
      // Expected counts from lights_select_pmf of every light (also the ones never drawn)
      auto pmf_out = rig().output<float>(n);
      rig().run("test_lights_select_pmf", n, *scene_, rig().input(std::vector<cl_float4>{ps[size_t(c)]}),
                rig().input(std::vector<cl_float4>{ns[size_t(c)]}), pmf_out);
      std::vector<float> pmf = pmf_out.read();
      for (size_t l = 0; l < n; ++l) {
        if (observed[l] > 0.0) {
          EXPECT_EQ(float(expected[l]), pmf[l]);
        }
        expected[l] = double(pmf[l]) * double(kSamples);
      }
      ChiSquare t = chi_square_test(observed, expected);
      EXPECT_GT(t.p_value, kAlpha) << "context " << c << ": chi2 " << t.statistic << " dof " << t.dof;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Devices, LightTreeTest, kernel_devices(), DeviceParamName());

// Renders of `file` with the tree and with selection by power: image means agree within
// 5 standard errors of the two (plus 0.5 %); prints both relMSE against a reference
Film render(const std::string& file, bool tree, Strategy strategy, uint32_t spp, uint32_t seed) {
  Scene scene = load_gltf(scene_path(file));
  auto c = std::make_shared<CompiledScene>(compile_scene(scene));
  if (!tree) drop_light_tree(&c->buffers);
  RenderSettings settings;
  settings.width = 64;
  settings.height = 48;
  settings.strategy = strategy;
  settings.max_depth = 3;
  settings.seed = seed;
  Renderer r(pocl_device(), std::shared_ptr<const CompiledScene>(c), compile_camera(scene, 64, 48), settings);
  return r.render(0, spp).film;
}

void expect_agree(const Film& a, const Film& b, const char* what) {
  Estimate ma = image_mean(a), mb = image_mean(b);
  double se = std::hypot(ma.standard_error, mb.standard_error);
  EXPECT_NEAR(ma.mean, mb.mean, 5.0 * se + 0.005 * mb.mean) << what;
  std::printf("%s: %.5f +- %.5f against %.5f +- %.5f\n", what, ma.mean, ma.standard_error, mb.mean, mb.standard_error);
}

TEST(LightTreeRender, TreeAndPowerSelectionAgree) {
  for (const char* f : {"lights/many-lights.gltf", "lights/punctual.gltf"}) {
    SCOPED_TRACE(f);
    Film tree = render(f, true, Strategy::Nee, 32, 1), power = render(f, false, Strategy::Nee, 32, 2);
    expect_agree(tree, power, f);
  }
}

TEST(LightTreeRender, NeeAndAutoAgreeWithTheTree) {
  for (const char* f : {"lights/many-lights.gltf", "lights/punctual.gltf"}) {
    SCOPED_TRACE(f);
    Film nee = render(f, true, Strategy::Nee, 32, 3), automatic = render(f, true, Strategy::Auto, 32, 4);
    expect_agree(automatic, nee, f);
  }
}

}  // namespace
}  // namespace candela::test
