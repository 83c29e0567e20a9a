// The tables program (host/device/tables_program.hpp): the renderer's program leaves the
// table kernels out; the tables program holds them all and computes the same tables as the
// test program's kernels; KernelPrebuild computes the common table into the kernel cache
// while a long load goes on and leaves it to the renderer after a short one; renderers of
// scenes with different kernel features read one cache entry.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "device/energy.hpp"
#include "device/kernel_sources.hpp"
#include "device/sheen_albedo.hpp"
#include "device/tables_program.hpp"
#include "device/tables_program_passes.hpp"
#include "gltf/gltf_loader.hpp"
#include "support/test_support.hpp"

namespace fs = std::filesystem;

namespace candela::test {
namespace {

std::set<std::string> kernel_names(const cl::Program& program) {
  std::set<std::string> names;
  std::stringstream list(program.getInfo<CL_PROGRAM_KERNEL_NAMES>());
  for (std::string name; std::getline(list, name, ';');)
    if (!name.empty()) names.insert(name);
  return names;
}

// The largest difference between two tables, and where
double max_difference(const std::vector<float>& a, const std::vector<float>& b, size_t* at) {
  double worst = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    double d = std::fabs(double(a[i]) - double(b[i]));
    if (!(d <= worst)) {
      worst = d;
      *at = i;
    }
  }
  return worst;
}

size_t files_ending(const std::string& dir, const std::string& suffix) {
  size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    std::string name = e.path().filename().string();
    n += name.size() >= suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
  }
  return n;
}

}  // namespace

TEST(TablesProgram, RendererProgramHoldsOnlyTheSceneKernelAndTheTablesProgramEveryTableKernel) {
  ScopedCacheDir cache;
  DeviceEntry d = pocl_device();
  cl::Context ctx(d.device);
  ProgramBuild renderer = build_program(ctx, d, renderer_program_source(), "-cl-std=CL1.2", {}, false);
  EXPECT_EQ(kernel_names(renderer.program), std::set<std::string>{"render_paths"});
  LazyProgram tables = tables_program(ctx, d);
  EXPECT_EQ(kernel_names(tables.get()),
            (std::set<std::string>{"energy_ggx_albedo_table", "energy_ggx_average_table", "energy_ggx_aniso_table",
                                   "energy_ggx_aniso_average_table", "energy_dielectric_albedo_table",
                                   "energy_dielectric_average_table", "energy_dielectric_aniso_table",
                                   "energy_dielectric_aniso_average_table", "sheen_albedo_table"}));
  // The list of table passes (kTablePasses) runs exactly these kernels, each once
  std::set<std::string> listed;
  for (const TablePass& p : kTablePasses) EXPECT_TRUE(listed.insert(p.kernel).second) << p.kernel << " listed twice";
  EXPECT_EQ(listed, kernel_names(tables.get()));
  EXPECT_FALSE(fs::exists(tables.cache_file())) << "the tables program's binary is not stored";
}

// The tables program's tables are those of the test program's kernels, bit for bit (the
// same cl/ sources compiled into another program, with CD_FEATURE_ANISOTROPY on: the
// feature adds kernels, not code to the isotropic ones)
TEST(TablesProgram, ComputesTheTablesOfTheTestProgram) {
  KernelRig& rig = kernel_rig("pocl");  // from the tests' own kernel cache
  ScopedCacheDir cache;
  LazyProgram tables = tables_program(rig.context, rig.device);
  GgxAlbedoTable ggx = ggx_albedo_table(rig.context, rig.queue, tables, AnisotropicAlbedo::none);
  EXPECT_FALSE(ggx.from_cache);
  GgxAlbedoTable ggx_test = ggx_albedo_table(rig.context, rig.queue, rig.program, "");
  size_t at = 0;
  double worst = max_difference(rig.read<float>(ggx.buffer, GGX_ALBEDO_SIZE),
                                rig.read<float>(ggx_test.buffer, GGX_ALBEDO_SIZE), &at);
  std::printf("GGX and dielectric albedos: largest difference %.3g at %zu\n", worst, at);
  EXPECT_EQ(worst, 0.0) << "at entry " << at;
  SheenAlbedoTable sheen = sheen_albedo_table(rig.context, rig.queue, tables);
  SheenAlbedoTable sheen_test = sheen_albedo_table(rig.context, rig.queue, rig.program, "");
  worst = max_difference(rig.read<float>(sheen.buffer, SHEEN_ALBEDO_SIZE),
                         rig.read<float>(sheen_test.buffer, SHEEN_ALBEDO_SIZE), &at);
  std::printf("sheen albedos: largest difference %.3g at %zu\n", worst, at);
  EXPECT_EQ(worst, 0.0) << "at entry " << at;
  // Now in the cache, beside the tables program's entry
  EXPECT_TRUE(fs::exists(common_tables_cache_file(rig.device)));
  EXPECT_TRUE(ggx_albedo_table(rig.context, rig.queue, tables, AnisotropicAlbedo::none).from_cache);
  // The generic kernel's table (its anisotropic part filled) is an entry of its own, with the
  // same isotropic part
  GgxAlbedoTable approximate = ggx_albedo_table(rig.context, rig.queue, tables, AnisotropicAlbedo::approximate);
  EXPECT_FALSE(approximate.from_cache);
  std::vector<float> a = rig.read<float>(approximate.buffer, GGX_ANISO_OFFSET);
  std::vector<float> n = rig.read<float>(ggx.buffer, GGX_ANISO_OFFSET);
  EXPECT_EQ(max_difference(a, n, &at), 0.0) << "at entry " << at;
}

TEST(TablesProgram, PrebuildComputesTheCommonTableDuringALongLoadOnly) {
  ScopedCacheDir cache;
  DeviceEntry d = pocl_device();
  RenderSettings settings;
  const std::string entry = common_tables_cache_file(d);
  ASSERT_FALSE(entry.empty());
  {
    KernelPrebuild short_load;
    short_load.loaded();  // before start_tables: however late the thread runs, the load is over
    short_load.start_tables(d, settings);
    short_load.wait();
  }
  EXPECT_FALSE(fs::exists(entry)) << "a short load leaves the tables to the renderer";
  {
    KernelPrebuild long_load;
    long_load.start_tables(d, settings);
    std::this_thread::sleep_for(std::chrono::duration<double>(KernelPrebuild::kTablesAfterLoading + 1.0));
    long_load.loaded();
    long_load.wait();
  }
  ASSERT_TRUE(fs::exists(entry)) << "a long load computes them meanwhile";
  const auto written = fs::last_write_time(entry);

  // Renderers of scenes with other kernel features read that entry and add no other
  settings.width = settings.height = 8;
  for (const char* name : {"cornell-box/cornell-box.gltf", "furnace/white-objects.gltf"}) {
    Scene scene = load_gltf(scene_path(name));
    Renderer renderer = scene_renderer(d, scene, settings);
    EXPECT_EQ(renderer.render(0, 1).spp, 1u);
  }
  EXPECT_EQ(files_ending(cache.path(), ".bin"), 2u) << "the two scenes' kernels, not the tables program";
  EXPECT_EQ(files_ending(cache.path(), ""), 3u) << "and the one table";
  EXPECT_TRUE(fs::last_write_time(entry) == written) << "read, not computed again";
}

}  // namespace candela::test
