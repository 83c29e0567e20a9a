// Inputs the fuzzer (tests/fuzz, scripts/fuzz) once crashed on: each must now load and
// compile, or fail with candela::Error, in the normal build too.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "base/error.hpp"
#include "compile/scene_compiler.hpp"
#include "gltf/gltf_loader.hpp"

namespace fs = std::filesystem;

namespace candela::test {

TEST(FuzzRegressions, EveryCrashInputLoadsOrFailsWithError) {
  fs::path dir = fs::path(CANDELA_SOURCE_DIR) / "tests" / "fuzz" / "regressions";
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_regular_file() && entry.path().filename() != "README.md") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  for (const fs::path& file : files) {
    SCOPED_TRACE(file.filename().string());
    std::ifstream in(file, std::ios::binary);
    std::stringstream bytes;
    bytes << in.rdbuf();
    try {
      CompiledScene compiled = compile_scene(load_gltf_from_memory(bytes.str(), ""));
      EXPECT_GT(compiled.triangles, 0u);
    } catch (const Error& e) {
      EXPECT_STRNE(e.what(), "");  // rejected, with a message
    }
  }
  std::cout << files.size() << " regression inputs\n";
}

}  // namespace candela::test
