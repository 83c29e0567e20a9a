// Sparse density grids on the device (cl/media/nanovdb.cl, MEDIUM_NANOVDB in cl/media/media.cl), with
// grids written here through OpenVDB's and NanoVDB's own host APIs:
//  - ratio tracking through a sparse linear ramp (two blocks of voxels with empty space
//    between them) equals exp(-sigma_t integral of density): the closed form on segments
//    inside the ramp, and a fine quadrature of the trilinear density (host OpenVDB values
//    and transform) on rays through the whole grid; axis-aligned and rotated with a
//    non-uniform scale, .vdb and .nvdb, PoCL and rusticl;
//  - the majorant cells bound the trilinear density everywhere in their cells;
//  - a fog sphere of albedo 1 from a .vdb file (rotated) is invisible under a uniform
//    background (a white furnace);
//  - the loader's errors and the grid memory --stats reports.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/glm.hpp>
#include <random>

#include "base/error.hpp"
#include "render/renderer.hpp"
#include "scene/vdb_grid.hpp"
#include "support/gltf_builder.hpp"
#include "support/scenes.hpp"
#include "support/test_support.hpp"

#ifdef CANDELA_HAVE_OPENVDB
#include <nanovdb/util/IO.h>
#include <nanovdb/util/OpenToNanoVDB.h>
#include <openvdb/openvdb.h>
#endif

namespace candela::test {
namespace {

#ifdef CANDELA_HAVE_OPENVDB

using nlohmann::json;

json medium_with_grid(glm::vec3 sigma_a, glm::vec3 sigma_s, const json& grid) {
  return {
      {"sigma_a", {sigma_a.x, sigma_a.y, sigma_a.z}}, {"sigma_s", {sigma_s.x, sigma_s.y, sigma_s.z}}, {"grid", grid}};
}

// A null boundary (a box of the medium) around [-3, 3]^3, which holds every grid here
Scene grid_scene(const json& medium, const std::string& name, GltfBuilder* builder = nullptr) {
  GltfBuilder local;
  GltfBuilder& g = builder ? *builder : local;
  int m = g.add("materials", null_boundary_material(medium));
  g.add_node({{"mesh", g.add_mesh(box_primitives(glm::vec3(-3.0f), glm::vec3(3.0f), m))}});
  return load_scene(g, "vdb-" + name + ".gltf");
}

// The ramp: voxel (i, j, k) holds 0.2 + 0.02 i on [0, 63] x [0, 23] x [0, 23], and a second
// block of 1.5 on [100, 107] x [0, 7] x [0, 7] (the space between is empty: no nodes)
constexpr int kRampX = 63, kRampYZ = 23;
float ramp_value(int i) { return 0.2f + 0.02f * float(i); }

// Voxel size 0.04, the grid's middle at the origin; rotated about (1, 2, 3) by 0.7 rad after
// a non-uniform scale (1, 1.3, 0.8) when `rotated`
openvdb::math::Transform::Ptr ramp_transform(bool rotated) {
  openvdb::math::Transform::Ptr xf = openvdb::math::Transform::createLinearTransform(0.04);
  if (rotated) {
    xf->postScale(openvdb::Vec3d(1.0, 1.3, 0.8));
    openvdb::math::Mat4d r = openvdb::math::rotation<openvdb::math::Mat4d>(openvdb::Vec3d(1, 2, 3).unitSafe(), 0.7);
    xf->postMult(r);
  }
  xf->postTranslate(-xf->indexToWorld(openvdb::Vec3d(53.5, 11.5, 11.5)));
  return xf;
}

openvdb::FloatGrid::Ptr ramp_grid(bool rotated) {
  openvdb::initialize();
  openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
  grid->setName("density");
  grid->setTransform(ramp_transform(rotated));
  auto acc = grid->getAccessor();
  for (int k = 0; k <= kRampYZ; ++k)
    for (int j = 0; j <= kRampYZ; ++j)
      for (int i = 0; i <= kRampX; ++i) acc.setValue(openvdb::Coord(i, j, k), ramp_value(i));
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 8; ++j)
      for (int i = 100; i < 108; ++i) acc.setValue(openvdb::Coord(i, j, k), 1.5f);
  return grid;
}

// Writes the grid as name.vdb and, converted, name.nvdb; returns the file name for `format`
std::string write_grid(const openvdb::FloatGrid::Ptr& grid, const std::string& name, const std::string& format) {
  std::string base = ::testing::TempDir() + name;
  openvdb::io::File(base + ".vdb").write({grid});
  nanovdb::io::writeGrid(base + ".nvdb", nanovdb::openToNanoVDB(*grid));
  return name + (format == "vdb" ? ".vdb" : ".nvdb");
}

// The host reference: trilinear density at world point p from OpenVDB's values and
// transform, 0 outside the index box the kernel looks in (the active voxels and one around)
double reference_density(const openvdb::FloatGrid& grid, glm::dvec3 p) {
  openvdb::Vec3d q = grid.transform().worldToIndex(openvdb::Vec3d(p.x, p.y, p.z));
  openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
  for (int a = 0; a < 3; ++a)
    if (q[a] < box.min()[a] - 1 || q[a] > box.max()[a] + 1) return 0.0;
  auto acc = grid.getConstAccessor();
  int x = int(std::floor(q[0])), y = int(std::floor(q[1])), z = int(std::floor(q[2]));
  double fx = q[0] - x, fy = q[1] - y, fz = q[2] - z, sum = 0.0;
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        double w = (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy) * (dz ? fz : 1 - fz);
        sum += w * acc.getValue(openvdb::Coord(x + dx, y + dy, z + dz));
      }
  return std::max(sum, 0.0);
}

glm::dvec3 index_to_world(const openvdb::FloatGrid& grid, glm::dvec3 q) {
  openvdb::Vec3d w = grid.transform().indexToWorld(openvdb::Vec3d(q.x, q.y, q.z));
  return {w[0], w[1], w[2]};
}

// Mean and standard error of test_media_transmittance per channel
std::vector<std::pair<double, double>> transmittance(const KernelRig& rig, const SceneOnDevice& sod, glm::dvec3 org,
                                                     glm::dvec3 dir, double tmax, cl_uint seed) {
  const size_t n = 1 << 15;
  auto out = rig.output<cl_float4>(n);
  rig.run("test_media_transmittance", n, sod, f4(org), f4(dir), float(tmax), seed, out);
  std::vector<cl_float4> v = out.read();
  std::vector<std::pair<double, double>> r;
  for (int ch = 0; ch < 3; ++ch) {
    Estimate e = sample_mean(v, ch);
    r.push_back({e.mean, e.standard_error});
  }
  EXPECT_EQ(v[0].s[3], 1.0f) << "the origin lies inside the box's medium";
  return r;
}

class VolumeVdbRamp : public ::testing::TestWithParam<std::tuple<std::string, std::string, bool>> {
 protected:
  void SetUp() override {
    rig_ = rig_or_null(std::get<0>(GetParam()));
    if (!rig_) GTEST_SKIP() << std::get<0>(GetParam()) << " is not available";
  }
  const KernelRig& rig() const { return *rig_; }

 private:
  const KernelRig* rig_ = nullptr;
};

// The kernel's world-to-index map and trilinear lookup (cl/media/nanovdb.cl) against OpenVDB's, at
// random points over the grid's box and beyond
TEST_P(VolumeVdbRamp, LookupsMatchOpenVdb) {
  auto [device, format, rotated] = GetParam();
  openvdb::FloatGrid::Ptr grid = ramp_grid(rotated);
  MediumDesc m;
  std::string file = write_grid(grid, std::string("lookup-") + (rotated ? "rotated" : "aligned"), format);
  if (format == "vdb")
    load_openvdb_density(::testing::TempDir() + file, "density", &m);
  else
    load_nanovdb_density(::testing::TempDir() + file, "density", &m);
  const size_t n = 4096;
  std::vector<cl_float4> points(n);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-3.0, 112.0), v(-3.0, 28.0);
  for (auto& p : points) {
    glm::dvec3 w = index_to_world(*grid, {u(rng), v(rng), v(rng)});
    p = f4(w);
  }
  auto lookups = rig().output<cl_float4>(n);
  rig().run("test_nanovdb_lookup", n, rig().input(m.nanovdb), rig().input(points), lookups);
  std::vector<cl_float4> out = lookups.read();
  auto acc = grid->getConstAccessor();
  for (size_t i = 0; i < n; ++i) {
    openvdb::Vec3d q = grid->transform().worldToIndex(openvdb::Vec3d(points[i].s[0], points[i].s[1], points[i].s[2]));
    for (int a = 0; a < 3; ++a) ASSERT_NEAR(out[i].s[a], q[a], 2e-4 * (1.0 + std::fabs(q[a]))) << "point " << i;
    // the value at the kernel's own index point (no edge flips between the two maps)
    glm::dvec3 qk(out[i].s[0], out[i].s[1], out[i].s[2]);
    int x = int(std::floor(qk.x)), y = int(std::floor(qk.y)), z = int(std::floor(qk.z));
    double f[3] = {qk.x - x, qk.y - y, qk.z - z}, want = 0.0;
    for (int c = 0; c < 8; ++c)
      want += (c & 1 ? f[0] : 1 - f[0]) * (c & 2 ? f[1] : 1 - f[1]) * (c & 4 ? f[2] : 1 - f[2]) *
              acc.getValue(openvdb::Coord(x + (c & 1), y + (c >> 1 & 1), z + (c >> 2)));
    ASSERT_NEAR(out[i].s[3], want, 1e-5) << "point " << i;
  }
}

// Ratio tracking through the sparse ramp: exp(-sigma_t integral of the density)
TEST_P(VolumeVdbRamp, RatioTrackingMatchesTheDensityIntegral) {
  auto [device, format, rotated] = GetParam();
  openvdb::FloatGrid::Ptr grid = ramp_grid(rotated);
  std::string label = std::string("ramp-") + (rotated ? "rotated" : "aligned");
  std::string file = write_grid(grid, label, format);
  const glm::vec3 sigma_t(0.6f, 1.2f, 2.4f);
  Scene scene = grid_scene(medium_with_grid(sigma_t * 0.5f, sigma_t * 0.5f, {{format, file}, {"name", "density"}}),
                           label + "-" + format);
  CompiledScene compiled = compile_scene(scene);
  ASSERT_TRUE(compiled.features.nanovdb);
  ASSERT_EQ(compiled.buffers.media[1].type, MEDIUM_NANOVDB);
  SceneOnDevice sod(rig(), compiled);

  // Segments inside the ramp (index points at least one voxel from its edges): the density
  // is linear along them, so the trapezoid rule is exact
  auto inside = [&](double i, double j, double k) { return index_to_world(*grid, {i, j, k}); };
  struct Segment {
    glm::dvec3 a, b;
  };
  for (const Segment& s : {Segment{inside(2, 5, 5), inside(60, 7, 9)}, Segment{inside(55.5, 20, 3), inside(4, 2.5, 19)},
                           Segment{inside(10, 3, 20), inside(12, 21, 2)}}) {
    glm::dvec3 d = s.b - s.a;
    double len = glm::length(d);
    double integral = 0.5 * (reference_density(*grid, s.a) + reference_density(*grid, s.b)) * len;
    auto tr = transmittance(rig(), sod, s.a, d / len, len, 5);
    for (int ch = 0; ch < 3; ++ch) {
      double want = std::exp(-double(sigma_t[ch]) * integral);
      EXPECT_NEAR(tr[size_t(ch)].first, want, 5.0 * tr[size_t(ch)].second + 1e-6)
          << "inside, channel " << ch << " SE " << tr[size_t(ch)].second;
    }
  }
  // Rays across the whole grid (through both blocks, the gap and the edges) to infinity
  // against a midpoint quadrature of the reference density along the ray to the box [-3, 3]^3
  struct Ray {
    glm::dvec3 org, dir;
  };
  glm::dvec3 through = glm::normalize(inside(104, 4, 4) - inside(-3, 12, 12));
  for (const Ray& r : {Ray{inside(-3, 12, 12), through},
                       Ray{inside(30, 30, -4), glm::normalize(inside(32, -2, 25) - inside(30, 30, -4))}}) {
    ASSERT_LT(glm::length(r.org), 2.9) << "starts inside the null boundary";
    double t_exit = INFINITY;
    for (int a = 0; a < 3; ++a)
      if (r.dir[a] != 0.0) t_exit = std::min(t_exit, ((r.dir[a] > 0 ? 3.0 : -3.0) - r.org[a]) / r.dir[a]);
    const int steps = 200000;
    double integral = 0.0, h = t_exit / steps;
    for (int s = 0; s < steps; ++s) integral += reference_density(*grid, r.org + (s + 0.5) * h * r.dir) * h;
    EXPECT_GT(integral, 0.5) << "the ray crosses the grid";
    auto tr = transmittance(rig(), sod, r.org, r.dir, INFINITY, 6);
    for (int ch = 0; ch < 3; ++ch) {
      double want = std::exp(-double(sigma_t[ch]) * integral);
      EXPECT_NEAR(tr[size_t(ch)].first, want, 5.0 * tr[size_t(ch)].second + 1e-5)
          << "across, channel " << ch << " SE " << tr[size_t(ch)].second;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Grids, VolumeVdbRamp,
                         ::testing::Combine(kernel_devices(), ::testing::Values("vdb", "nanovdb"), ::testing::Bool()),
                         [](const auto& info) {
                           return std::get<0>(info.param) + "_" + std::get<1>(info.param) +
                                  (std::get<2>(info.param) ? "_rotated" : "_aligned");
                         });

// The majorant cells bound the trilinear density at random points of each cell, and the
// cells over the empty gap between the blocks are 0 (skipped at no cost)
TEST(VolumeVdbMajorants, CellsBoundTheTrilinearDensity) {
  openvdb::FloatGrid::Ptr grid = ramp_grid(true);
  MediumDesc m;
  load_openvdb_density(::testing::TempDir() + write_grid(grid, "majorants", "vdb"), "density", &m);
  ASSERT_TRUE(m.is_nanovdb());
  EXPECT_EQ(m.grid_min, glm::vec3(-1.0f));
  EXPECT_EQ(m.grid_max, glm::vec3(108.0f, 24.0f, 24.0f));
  EXPECT_EQ(m.majorant_size, glm::ivec3(16, 16, 16));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  glm::dvec3 width = glm::dvec3(m.grid_max - m.grid_min) / glm::dvec3(m.majorant_size);
  int empty = 0;
  for (int z = 0; z < m.majorant_size.z; ++z)
    for (int y = 0; y < m.majorant_size.y; ++y)
      for (int x = 0; x < m.majorant_size.x; ++x) {
        float bound = m.majorant_density[(size_t(z) * m.majorant_size.y + y) * m.majorant_size.x + x];
        empty += bound == 0.0f;
        double peak = 0.0;
        for (int s = 0; s < 64; ++s) {
          glm::dvec3 q = glm::dvec3(m.grid_min) + (glm::dvec3(x, y, z) + glm::dvec3(u(rng), u(rng), u(rng))) * width;
          if (s < 8)
            q = glm::dvec3(m.grid_min) + (glm::dvec3(x, y, z) + glm::dvec3(s & 1, (s >> 1) & 1, s >> 2)) * width;
          peak = std::max(peak, reference_density(*grid, index_to_world(*grid, q)));
        }
        ASSERT_LE(peak, double(bound) * (1.0 + 1e-6)) << "cell " << x << "," << y << "," << z;
      }
  EXPECT_GT(empty, 16 * 16 * 16 / 4) << "cells over empty space are 0";
}

// A fog sphere (density 1 inside radius 0.5, a thin falloff) from a .vdb file, rotated and
// non-uniformly scaled, scattering with albedo 1 under a background of 1: every pixel 1
TEST(VolumeVdbFurnace, RotatedFogSphereIsInvisible) {
  openvdb::initialize();
  openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
  grid->setName("fog");
  openvdb::math::Transform::Ptr xf = openvdb::math::Transform::createLinearTransform(0.04);
  xf->postScale(openvdb::Vec3d(1.0, 0.7, 1.2));
  xf->postMult(openvdb::math::rotation<openvdb::math::Mat4d>(openvdb::Vec3d(0, 1, 1).unitSafe(), 0.5));
  grid->setTransform(xf);
  auto acc = grid->getAccessor();
  for (int k = -16; k <= 16; ++k)
    for (int j = -16; j <= 16; ++j)
      for (int i = -16; i <= 16; ++i) {
        double r = std::sqrt(double(i * i + j * j + k * k)) / 12.0;
        if (r < 1.2) acc.setValue(openvdb::Coord(i, j, k), float(std::clamp((1.2 - r) / 0.2, 0.0, 1.0)));
      }
  openvdb::io::File(::testing::TempDir() + "fog.vdb").write({grid});
  GltfBuilder g;
  g.add_camera(glm::vec3(0.0f, 0.3f, 2.5f), glm::vec3(0.0f), 0.6f);
  g.set_background(glm::vec3(1.0f));
  json medium = medium_with_grid(glm::vec3(0.0f), glm::vec3(4.0f, 8.0f, 16.0f), {{"vdb", "fog.vdb"}, {"name", "fog"}});
  medium["g"] = 0.3;
  Scene scene = grid_scene(medium, "fog", &g);
  RenderSettings settings;
  settings.width = settings.height = 16;
  settings.max_depth = 1000;
  settings.seed = 17;
  Film f = scene_renderer(*device_by_name("pocl"), scene, settings).render(0, 128).film;
  Estimate e = image_mean(f);
  EXPECT_LT(e.standard_error, 0.01);
  EXPECT_NEAR(e.mean, 1.0, 4.0 * e.standard_error + 1e-5) << "SE " << e.standard_error;
  // The furnace has power: the same sphere absorbing is darker in the middle
  medium["sigma_a"] = {2.0, 2.0, 2.0};
  GltfBuilder g2;
  g2.add_camera(glm::vec3(0.0f, 0.3f, 2.5f), glm::vec3(0.0f), 0.6f);
  g2.set_background(glm::vec3(1.0f));
  Film dark =
      scene_renderer(*device_by_name("pocl"), grid_scene(medium, "fog-absorbing", &g2), settings).render(0, 16).film;
  Estimate mid = region_mean(dark, 0, 5, 11, 5, 11);
  EXPECT_LT(mid.mean + 10.0 * mid.standard_error, 1.0);
}

// Loader errors, and the grid memory of --stats
TEST(VolumeVdbLoader, ErrorsAndGridMemory) {
  openvdb::FloatGrid::Ptr grid = ramp_grid(false);
  openvdb::Vec3SGrid::Ptr vectors = openvdb::Vec3SGrid::create();
  vectors->setName("velocity");
  vectors->getAccessor().setValue(openvdb::Coord(0), openvdb::Vec3s(1.0f));
  openvdb::io::File(::testing::TempDir() + "two.vdb").write({vectors, grid});
  MediumDesc m;
  EXPECT_THROW(load_openvdb_density(::testing::TempDir() + "two.vdb", "missing", &m), Error);
  EXPECT_THROW(load_openvdb_density(::testing::TempDir() + "two.vdb", "velocity", &m), Error);
  EXPECT_THROW(load_openvdb_density(::testing::TempDir() + "absent.vdb", "", &m), Error);
  load_openvdb_density(::testing::TempDir() + "two.vdb", "", &m);  // the first float grid
  EXPECT_NE(m.grid_source.find("density"), std::string::npos);
  openvdb::FloatGrid::Ptr empty = openvdb::FloatGrid::create(0.0f);
  empty->setName("empty");
  openvdb::io::File(::testing::TempDir() + "empty.vdb").write({empty});
  EXPECT_THROW(load_openvdb_density(::testing::TempDir() + "empty.vdb", "", &m), Error);

  Scene scene = grid_scene(
      medium_with_grid(glm::vec3(1.0f), glm::vec3(0.0f), {{"vdb", "two.vdb"}, {"name", "density"}}), "memory");
  CompiledScene c = compile_scene(scene);
  ASSERT_EQ(c.grids.size(), 1u);
  const MediumDesc& md = scene.media[0];
  EXPECT_EQ(c.grids[0].grid_bytes, md.nanovdb.size() * 4);
  EXPECT_EQ(c.grids[0].majorant_bytes, 16u * 16u * 16u * 4u);
  EXPECT_EQ(c.grids[0].grid_bytes, nanovdb::openToNanoVDB(*grid).grid<float>()->gridSize()) << "the NanoVDB buffer";
  EXPECT_EQ(c.buffers.nanovdb.size() % 8, 0u);
  EXPECT_NE(scene.features().build_options().find("-DCD_FEATURE_NANOVDB=1"), std::string::npos);
}

#else

TEST(VolumeVdbLoader, BuiltWithoutOpenVdb) {
  EXPECT_FALSE(openvdb_supported());
  MediumDesc m;
  EXPECT_THROW(load_openvdb_density("smoke.vdb", "", &m), Error);
}

#endif

}  // namespace
}  // namespace candela::test
