// The kernel binary cache: a second build loads from disk; a corrupt entry falls back
// to a source build; a failing build reports the device's log with file and line.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "base/device_types.hpp"
#include "base/error.hpp"
#include "device/kernel_sources.hpp"
#include "device/program_cache.hpp"
#include "support/test_support.hpp"

namespace fs = std::filesystem;

namespace candela::test {
namespace {

bool kernel_runs(const cl::Context& ctx, const DeviceEntry& d, cl::Program& program) {
  KernelRig rig(d, ctx, program);
  auto out = rig.output<cl_uint>(256);  // room for all of CD_LAYOUT
  rig.run("test_struct_layout", 1, out);
  return rig.read<cl_uint>(out.buffer, 1)[0] == sizeof(dev::BvhNode);
}

}  // namespace

TEST(ProgramCache, SecondBuildComesFromCacheAndCorruptEntriesAreRebuilt) {
  ScopedCacheDir cache;
  DeviceEntry d = pocl_device();
  cl::Context ctx(d.device);
  std::string src = test_program_source();
  ProgramBuild first = build_program(ctx, d, src, "-cl-std=CL1.2");
  EXPECT_FALSE(first.from_cache);
  ASSERT_TRUE(fs::exists(first.cache_file));
  ProgramBuild second = build_program(ctx, d, src, "-cl-std=CL1.2");
  EXPECT_TRUE(second.from_cache);
  EXPECT_TRUE(kernel_runs(ctx, d, second.program));

  // Build options are part of the key
  ProgramBuild other = build_program(ctx, d, src, "-cl-std=CL1.2 -DCD_FEATURE_TEXTURES=0");
  EXPECT_FALSE(other.from_cache);
  EXPECT_NE(other.cache_file, first.cache_file);

  // Flip bytes in the middle of the entry: detected, removed, rebuilt from source
  {
    std::fstream f(first.cache_file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(std::streamoff(fs::file_size(first.cache_file) / 2));
    f.write("garbage!", 8);
  }
  ProgramBuild third = build_program(ctx, d, src, "-cl-std=CL1.2");
  EXPECT_FALSE(third.from_cache);
  EXPECT_TRUE(kernel_runs(ctx, d, third.program));

  // A truncated entry too
  fs::resize_file(first.cache_file, 10);
  ProgramBuild fourth = build_program(ctx, d, src, "-cl-std=CL1.2");
  EXPECT_FALSE(fourth.from_cache);
  EXPECT_TRUE(kernel_runs(ctx, d, fourth.program));
}

TEST(ProgramCache, BuildFailureReportsTheLogWithFileAndLine) {
  ScopedCacheDir cache;
  DeviceEntry d = pocl_device();
  cl::Context ctx(d.device);
  std::string src = renderer_program_source() + "#line 1 \"cl/broken.cl\"\nkernel void k() { int x = ; }\n";
  try {
    build_program(ctx, d, src, "-cl-std=CL1.2");
    FAIL() << "the broken source built";
  } catch (const Error& e) {
    std::string msg = e.what();
    EXPECT_NE(msg.find("build failed"), std::string::npos) << msg;
    EXPECT_NE(msg.find("cl/broken.cl:1"), std::string::npos) << msg;
  }
}

}  // namespace candela::test
