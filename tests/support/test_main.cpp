#include <gtest/gtest.h>

#include <unistd.h>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "device/device.hpp"

int main(int argc, char** argv) {
  // Mesa's rusticl exposes llvmpipe only when asked; set before the ICD loader runs
  setenv("RUSTICL_ENABLE", "llvmpipe", 0);
  // Intel's OpenCL CPU runtime, where scripts/setup.sh installs it (CANDELA_TEST_DEVICE=intel)
  candela::add_installed_intel_runtime(CANDELA_BINARY_DIR "/intel-opencl");
  // A temporary directory of this process's own: ctest runs tests in parallel processes,
  // and tests that write scene files under ::testing::TempDir() by a fixed name would
  // otherwise overwrite each other's (parameterized variants share names)
  std::string own_dir;
  if (!std::getenv("TEST_TMPDIR")) {
    std::string dir = "/tmp/candela-test-XXXXXX";
    if (mkdtemp(dir.data())) {
      own_dir = dir;
      setenv("TEST_TMPDIR", (dir + "/").c_str(), 1);
    }
  }
  ::testing::InitGoogleTest(&argc, argv);
  int result = RUN_ALL_TESTS();
  std::error_code ignored;
  if (!own_dir.empty()) std::filesystem::remove_all(own_dir, ignored);
  return result;
}
