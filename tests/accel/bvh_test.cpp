// Kernel ray-triangle intersection and BVH traversal against a brute-force host
// reference in double precision, on random rays and on rays through edges and vertices.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "compile/bvh_builder.hpp"
#include "gltf/gltf_loader.hpp"
#include "support/gltf_builder.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

struct Tri {
  glm::vec3 p[3];
};

// Triangle soup as vertex positions and primitives (prim i = tris[i]), and its BVH
struct Soup {
  std::vector<float> positions;
  std::vector<dev::Prim> prims;
  Bvh bvh;
  explicit Soup(const std::vector<Tri>& tris) {
    for (const Tri& t : tris) {
      dev::Prim p{};
      for (int k = 0; k < 3; ++k) {
        p.v[k] = uint32_t(positions.size() / 3);
        for (int a = 0; a < 3; ++a) positions.push_back(t.p[k][a]);
      }
      prims.push_back(p);
    }
    bvh = build_bvh(positions, prims);
  }
};

struct HostHit {
  double t = INFINITY;
  int tri = -1;
  double margin = 0.0;  // smallest barycentric coordinate, relative: near 0 = near an edge
};

// Moller-Trumbore in double precision over every triangle
HostHit host_closest_hit(const std::vector<Tri>& tris, glm::dvec3 o, glm::dvec3 d, double tmax) {
  HostHit best;
  best.t = tmax;
  for (size_t i = 0; i < tris.size(); ++i) {
    glm::dvec3 v0 = tris[i].p[0], v1 = tris[i].p[1], v2 = tris[i].p[2];
    glm::dvec3 e1 = v1 - v0, e2 = v2 - v0, p = glm::cross(d, e2);
    double det = glm::dot(e1, p);
    if (det == 0.0) continue;
    glm::dvec3 s = o - v0;
    double u = glm::dot(s, p) / det;
    glm::dvec3 q = glm::cross(s, e1);
    double v = glm::dot(d, q) / det;
    double t = glm::dot(e2, q) / det;
    if (u < 0 || v < 0 || u + v > 1 || t <= 0 || t >= best.t) continue;
    best.t = t;
    best.tri = int(i);
    best.margin = std::min({u, v, 1.0 - u - v});
  }
  return best;
}

Tri make_tri(glm::vec3 a, glm::vec3 b, glm::vec3 c) {
  Tri t;
  t.p[0] = a;
  t.p[1] = b;
  t.p[2] = c;
  return t;
}

// Closed icosphere with shared vertices: every edge belongs to two triangles
std::vector<Tri> icosphere(int subdivisions, glm::vec3 center, float radius) {
  GltfBuilder::Primitive p = sphere_primitive(center, radius, subdivisions, 0);
  std::vector<Tri> out;
  for (size_t i = 0; i + 2 < p.indices.size(); i += 3)
    out.push_back(make_tri(p.positions[p.indices[i]], p.positions[p.indices[i + 1]], p.positions[p.indices[i + 2]]));
  return out;
}

struct GpuTrace {
  std::vector<cl_float4> bvh_hits, brute_hits;
  std::vector<cl_float4> packet_hits;  // bvh_intersect8's, eight rays at a time
  std::vector<cl_int> occluded;
};

// rays: pairs (org + tmax, dir)
GpuTrace trace(const KernelRig& rig, const Bvh& bvh, const std::vector<cl_float4>& rays) {
  size_t n = rays.size() / 2;
  cl::Buffer tris = rig.input(bvh.tris), ray_buf = rig.input(rays);
  auto bvh_hits = rig.output<cl_float4>(n), brute_hits = rig.output<cl_float4>(n);
  auto occluded = rig.output<cl_int>(n);
  auto packet_hits = rig.output<cl_float4>(n);
  cl::Buffer nodes = rig.input(bvh.nodes);
  rig.run("test_trace_bvh", n, nodes, tris, ray_buf, bvh_hits, occluded);
  rig.run("test_trace_brute", n, tris, cl_uint(bvh.tris.size()), ray_buf, brute_hits);
  rig.run("test_trace_bvh8", (n + 7) / 8, nodes, tris, ray_buf, cl_uint(n), packet_hits);
  return {bvh_hits.read(), brute_hits.read(), packet_hits.read(), occluded.read()};
}

// A packet's hit is the single ray's bit for bit, unless two triangles lie at the ray's hit
// distance (a ray through their shared edge or vertex): the packet may meet them in another
// order and keep the other one, whose distance differs by rounding only. Returns the number
// of such ties.
int expect_packets_match(const GpuTrace& gpu) {
  int ties = 0;
  for (size_t i = 0; i < gpu.bvh_hits.size(); ++i) {
    const cl_float4 &h = gpu.bvh_hits[i], &p = gpu.packet_hits[i];
    EXPECT_EQ(p.s[3] >= 0, h.s[3] >= 0) << "ray " << i;
    if (p.s[3] != h.s[3]) {
      ++ties;
      EXPECT_NEAR(p.s[0], h.s[0], 1e-6f * std::fabs(h.s[0])) << "ray " << i;
      continue;
    }
    EXPECT_EQ(p.s[0], h.s[0]) << "ray " << i;
    EXPECT_EQ(p.s[1], h.s[1]) << "ray " << i;
    EXPECT_EQ(p.s[2], h.s[2]) << "ray " << i;
  }
  return ties;
}

class BvhTest : public DeviceTest {};

}  // namespace

// Every triangle in exactly one leaf run (ending at a BVH_TRI_LAST triangle), child
// boxes holding their triangles and nodes, and no path pushing more than the kernel's
// traversal stack holds
static void check_bvh(const Bvh& bvh, const std::vector<Tri>& tris) {
  EXPECT_LE(bvh.depth, kMaxBvhDepth);
  ASSERT_EQ(bvh.tris.size(), tris.size());
  std::vector<int> seen(tris.size(), 0);
  for (const auto& t : bvh.tris) seen[t.prim]++;
  for (int s : seen) ASSERT_EQ(s, 1);
  std::vector<int> covered(tris.size(), 0), node_seen(bvh.nodes.size(), 0);
  int max_pushes = 0;
  struct Item {
    int node, pushes;
  };
  std::vector<Item> todo = {{0, 0}};
  while (!todo.empty()) {
    Item item = todo.back();
    todo.pop_back();
    ASSERT_GE(item.node, 0);
    ASSERT_LT(item.node, int(bvh.nodes.size()));
    ASSERT_EQ(node_seen[item.node]++, 0) << "node reached twice";
    const dev::BvhNode& node = bvh.nodes[item.node];
    int used = 0;
    for (int i = 0; i < 4; ++i) used += node.lo_x[i] <= node.hi_x[i];
    int pushes = item.pushes + std::max(0, used - 1);
    max_pushes = std::max(max_pushes, pushes);
    for (int i = 0; i < 4; ++i) {
      glm::vec3 lo(node.lo_x[i], node.lo_y[i], node.lo_z[i]), hi(node.hi_x[i], node.hi_y[i], node.hi_z[i]);
      if (lo.x > hi.x) {  // unused slot: empty on every axis
        ASSERT_GT(lo.y, hi.y);
        ASSERT_GT(lo.z, hi.z);
        continue;
      }
      auto inside = [&](const glm::vec3& p) {
        for (int a = 0; a < 3; ++a)
          if (p[a] < lo[a] || p[a] > hi[a]) return false;
        return true;
      };
      int c = node.child[i];
      if (c < 0) {
        for (int t = ~c;; ++t) {
          ASSERT_LT(t, int(bvh.tris.size()));
          covered[t]++;
          for (const auto& p : tris[bvh.tris[t].prim].p) ASSERT_TRUE(inside(p));
          if (bvh.tris[t].flags & BVH_TRI_LAST) break;
        }
      } else {
        ASSERT_GT(c, 0);
        const dev::BvhNode& child = bvh.nodes[c];
        for (int k = 0; k < 4; ++k) {
          if (child.lo_x[k] > child.hi_x[k]) continue;
          ASSERT_TRUE(inside(glm::vec3(child.lo_x[k], child.lo_y[k], child.lo_z[k])));
          ASSERT_TRUE(inside(glm::vec3(child.hi_x[k], child.hi_y[k], child.hi_z[k])));
        }
        todo.push_back({c, pushes});
      }
    }
  }
  for (int c : covered) ASSERT_EQ(c, 1);
  for (int n : node_seen) ASSERT_EQ(n, 1);
  EXPECT_LE(max_pushes, BVH_STACK_SIZE);
}

TEST(BvhBuilder, EveryTriangleInExactlyOneLeafAndBoxesNest) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Tri> tris;
  for (int i = 0; i < 5000; ++i) {
    glm::vec3 c(u(rng), u(rng), u(rng));
    tris.push_back(
        make_tri(c, c + 0.05f * glm::vec3(u(rng), u(rng), u(rng)), c + 0.05f * glm::vec3(u(rng), u(rng), u(rng))));
  }
  // Many copies of one triangle: no spatial split exists
  for (int i = 0; i < 100; ++i) tris.push_back(tris[0]);
  check_bvh(Soup(tris).bvh, tris);
}

// Motion blur: with three poses a vertex, every pose of every triangle lies inside the boxes
// of its leaf and of the nodes above it, and a leaf's copy of the triangle is pose 0
TEST(BvhBuilder, BoxesBoundEveryPose) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<std::vector<Tri>> poses(3);
  for (int i = 0; i < 2000; ++i) {
    glm::vec3 c(u(rng), u(rng), u(rng)), move(u(rng), u(rng), u(rng));
    Tri t = make_tri(c, c + 0.05f * glm::vec3(u(rng), u(rng), u(rng)), c + 0.05f * glm::vec3(u(rng), u(rng), u(rng)));
    for (int s = 0; s < 3; ++s) {
      Tri moved = t;
      for (glm::vec3& p : moved.p) p += 0.2f * float(s) * move;
      poses[size_t(s)].push_back(moved);
    }
  }
  std::vector<float> positions;  // vertex v's pose s at v 3 + s
  std::vector<dev::Prim> prims;
  for (size_t i = 0; i < poses[0].size(); ++i) {
    dev::Prim p{};
    for (int k = 0; k < 3; ++k) {
      p.v[k] = uint32_t(3 * i + size_t(k));
      for (int s = 0; s < 3; ++s)
        for (int a = 0; a < 3; ++a) positions.push_back(poses[size_t(s)][i].p[k][a]);
    }
    prims.push_back(p);
  }
  Bvh bvh = build_bvh(positions, prims, {}, 0, 3);
  for (const std::vector<Tri>& pose : poses) check_bvh(bvh, pose);
  for (const dev::BvhTriangle& t : bvh.tris) EXPECT_EQ(t.v1[0], poses[0][t.prim].p[1][0]);
}

// A chain of ever smaller triangles, split off a few at a time: a deep tree stays within
// the depth limit and the traversal stack
TEST(BvhBuilder, DeepChainStaysWithinTheStack) {
  std::vector<Tri> tris;
  for (int i = 0; i < 120; ++i) {
    float s = std::ldexp(1.0f, -i), x = s;
    tris.push_back(make_tri(glm::vec3(x, 0, 0), glm::vec3(x + 0.01f * s, 0.01f * s, 0), glm::vec3(x, 0, 0.01f * s)));
  }
  Bvh bvh = Soup(tris).bvh;
  EXPECT_GT(bvh.depth, 30);
  check_bvh(bvh, tris);
}

// The parallel builder gives the same tree, byte for byte, on any number of threads: the
// top of the tree is built with parallel binning and subtrees on threads of their own,
// the rest as jobs on a pool, joined in a fixed order. 150k triangles are enough for
// both (parallel binning from 32768 refs, jobs of at most max(4096, refs / 128)), and for
// the sampled binning of ranges of 16384 refs or more, whose sides' boxes come from the
// partition (check_bvh: every triangle inside its boxes).
TEST(BvhBuilder, SameTreeOnAnyThreadCount) {
  std::vector<Tri> tris = icosphere(6, glm::vec3(0.0f), 1.0f);              // 81920 triangles
  std::vector<Tri> more = icosphere(5, glm::vec3(3.0f, 0.5f, 0.0f), 0.5f);  // 20480, apart
  tris.insert(tris.end(), more.begin(), more.end());
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-4.0f, 4.0f);
  for (int i = 0; i < 50000; ++i) {  // and a cloud of small triangles
    glm::vec3 c(u(rng), u(rng), u(rng));
    tris.push_back(
        make_tri(c, c + 0.02f * glm::vec3(u(rng), u(rng), u(rng)), c + 0.02f * glm::vec3(u(rng), u(rng), u(rng))));
  }
  Soup soup(tris);  // default thread count
  check_bvh(soup.bvh, tris);
  double cost = sah_cost(soup.bvh);
  EXPECT_GT(cost, 1.0);
  for (int threads : {1, 2, 3, 8}) {
    Bvh bvh = build_bvh(soup.positions, soup.prims, {}, threads);
    ASSERT_EQ(bvh.nodes.size(), soup.bvh.nodes.size()) << threads << " threads";
    ASSERT_EQ(bvh.tris.size(), soup.bvh.tris.size());
    EXPECT_EQ(0, std::memcmp(bvh.nodes.data(), soup.bvh.nodes.data(), bvh.nodes.size() * sizeof(bvh.nodes[0])))
        << threads << " threads";
    EXPECT_EQ(0, std::memcmp(bvh.tris.data(), soup.bvh.tris.data(), bvh.tris.size() * sizeof(bvh.tris[0])))
        << threads << " threads";
    EXPECT_EQ(bvh.depth, soup.bvh.depth);
    EXPECT_EQ(sah_cost(bvh), cost);
  }
}

// Random rays (a tenth axis-aligned, a quarter with a finite tmax) from points in the
// box `lo`..`hi`: the BVH's closest hit is the kernel's brute-force loop's exactly, the
// occlusion query agrees with it, and both agree with the double-precision host reference
// away from edges. Returns the rays that hit something.
static int check_random_rays(const KernelRig& rig, const std::vector<Tri>& scene, glm::vec3 lo, glm::vec3 hi, int count,
                             uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), u01(0.0f, 1.0f);
  Bvh bvh = Soup(scene).bvh;
  std::vector<cl_float4> rays;
  float size = glm::length(hi - lo);
  for (int i = 0; i < count; ++i) {
    glm::vec3 o = lo + (hi - lo) * glm::vec3(u01(rng), u01(rng), u01(rng));
    glm::vec3 d = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)));
    if (i % 10 == 0) d = glm::vec3(0, 0, 0), d[i % 3] = u(rng) < 0 ? -1.0f : 1.0f;  // axis-aligned
    float tmax = i % 4 == 0 ? size * (0.2f + 0.8f * u01(rng)) : INFINITY;
    rays.push_back(f4(o, tmax));
    rays.push_back(f4(d, 0));
  }
  GpuTrace gpu = trace(rig, bvh, rays);
  EXPECT_LE(expect_packets_match(gpu), count / 1000);
  int hits = 0, checked = 0;
  for (size_t i = 0; i < rays.size() / 2; ++i) {
    glm::dvec3 o(rays[2 * i].s[0], rays[2 * i].s[1], rays[2 * i].s[2]);
    glm::dvec3 d(rays[2 * i + 1].s[0], rays[2 * i + 1].s[1], rays[2 * i + 1].s[2]);
    HostHit ref = host_closest_hit(scene, o, d, rays[2 * i].s[3]);
    const cl_float4& h = gpu.bvh_hits[i];
    // BVH and brute force in the kernel share one intersection routine: identical
    EXPECT_EQ(h.s[3], gpu.brute_hits[i].s[3]) << "ray " << i;
    EXPECT_EQ(h.s[0], gpu.brute_hits[i].s[0]) << "ray " << i;
    EXPECT_EQ(gpu.occluded[i], h.s[3] >= 0 ? 1 : 0) << "ray " << i;
    if (ref.tri >= 0 && ref.margin < 1e-5) continue;  // within float error of an edge
    ++checked;
    EXPECT_EQ(h.s[3] >= 0, ref.tri >= 0) << "ray " << i << " host t " << ref.t;
    if (ref.tri < 0 || h.s[3] < 0) continue;
    ++hits;
    EXPECT_NEAR(h.s[0], ref.t, 1e-5 * (1.0 + ref.t)) << "ray " << i;
    int kernel_tri = int(h.s[3]);  // stable primitive index
    if (kernel_tri != ref.tri) {
      // Another triangle at the same distance (overlapping soup): accept only a tie
      HostHit alt = host_closest_hit({scene[kernel_tri]}, o, d, INFINITY);
      EXPECT_NEAR(alt.t, ref.t, 1e-5 * (1.0 + ref.t)) << "ray " << i;
    }
  }
  EXPECT_GT(checked, count * 95 / 100);
  return hits;
}

TEST_P(BvhTest, RandomRaysMatchBruteForceReference) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Tri> scene = icosphere(2, glm::vec3(0.3f, -0.2f, 0.1f), 0.6f);
  for (int i = 0; i < 2000; ++i) {
    glm::vec3 c(u(rng), u(rng), u(rng));
    float s = 0.02f + 0.15f * std::fabs(u(rng));
    scene.push_back(make_tri(c, c + s * glm::vec3(u(rng), u(rng), u(rng)), c + s * glm::vec3(u(rng), u(rng), u(rng))));
  }
  EXPECT_GT(check_random_rays(rig(), scene, glm::vec3(-1.5f), glm::vec3(1.5f), 20000, 12), 3000);
}

// The same on real meshes: every mesh of the shipped materials scene (spheres, a ground,
// shared vertices at many scales), rays from inside its bounds
TEST_P(BvhTest, RandomRaysOnRealMeshesMatchBruteForceReference) {
  Scene s = load_gltf(scene_path("materials/materials.gltf"));
  std::vector<Tri> scene;
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  for (const MeshDesc& m : s.meshes)
    for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
      scene.push_back(
          make_tri(m.positions[m.indices[i]], m.positions[m.indices[i + 1]], m.positions[m.indices[i + 2]]));
      for (const glm::vec3& p : scene.back().p) lo = glm::min(lo, p), hi = glm::max(hi, p);
    }
  ASSERT_GT(scene.size(), 5000u);
  glm::vec3 c = 0.5f * (lo + hi), e = 0.5f * (hi - lo);
  EXPECT_GT(check_random_rays(rig(), scene, c - 0.8f * e, c + 0.8f * e, 5000, 13), 1200);
}

TEST_P(BvhTest, RaysThroughSharedEdgesAndVerticesNeverLeak) {
  glm::vec3 center(0.1f, 0.2f, -0.3f);
  std::vector<Tri> sphere = icosphere(3, center, 2.0f);
  Bvh bvh = Soup(sphere).bvh;
  // From points inside, aim exactly at every vertex and every edge midpoint
  std::vector<glm::vec3> origins = {center, center + glm::vec3(0.3f, -0.5f, 0.2f),
                                    center + glm::vec3(-1.1f, 0.4f, 0.6f)};
  std::vector<cl_float4> rays;
  for (const auto& o : origins)
    for (const auto& t : sphere)
      for (int k = 0; k < 3; ++k) {
        for (glm::vec3 target : {t.p[k], 0.5f * (t.p[k] + t.p[(k + 1) % 3])}) {
          rays.push_back(f4(o, INFINITY));
          rays.push_back(f4(glm::normalize(target - o), 0));
        }
      }
  GpuTrace gpu = trace(rig(), bvh, rays);
  expect_packets_match(gpu);  // ties are expected here: every ray meets an edge or a vertex
  int leaks = 0;
  for (size_t i = 0; i < rays.size() / 2; ++i) {
    const cl_float4& h = gpu.bvh_hits[i];
    glm::vec3 o(rays[2 * i].s[0], rays[2 * i].s[1], rays[2 * i].s[2]);
    glm::vec3 d(rays[2 * i + 1].s[0], rays[2 * i + 1].s[1], rays[2 * i + 1].s[2]);
    if (h.s[3] < 0 || gpu.packet_hits[i].s[3] < 0) {
      ++leaks;
      continue;
    }
    // The hit lies on the sphere's surface, between inscribed facets and the sphere
    float r = glm::length(o + h.s[0] * d - center);
    EXPECT_LE(r, 2.0f * 1.0001f);
    EXPECT_GE(r, 2.0f * 0.99f);
  }
  EXPECT_EQ(leaks, 0) << "of " << rays.size() / 2 << " rays through edges and vertices";
}

INSTANTIATE_TEST_SUITE_P(Devices, BvhTest, kernel_devices(), DeviceParamName());

}  // namespace candela::test
