// Inputs the fuzzer (tests/fuzz, scripts/fuzz) once crashed on, and the glTF-Validator
// test corpus (tests/fuzz/validator: hand-made valid and invalid files): each must load
// and compile, or fail with candela::Error, in the normal build too.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
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

// The glTF-Validator's test files, loaded from their paths (relative URIs resolve in
// their folders; most name a .bin or image that is not there, which must fail cleanly).
// A file may load or be rejected with a message; nothing else may happen: no other
// exception, no crash, no hang (ctest's timeout).
TEST(FuzzRegressions, ValidatorCorpusLoadsOrFailsWithError) {
  fs::path dir = fs::path(CANDELA_SOURCE_DIR) / "tests" / "fuzz" / "validator";
  std::vector<fs::path> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    if (entry.is_regular_file() && entry.path().extension() == ".gltf") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 300u) << "the validator corpus is missing from " << dir;

  std::map<std::string, std::string> rejected;  // file -> message
  std::set<std::string> names;
  size_t loaded = 0;
  for (const fs::path& file : files) {
    std::string name = fs::relative(file, dir).generic_string();
    names.insert(name);
    SCOPED_TRACE(name);
    auto start = std::chrono::steady_clock::now();
    try {
      CompiledScene compiled = compile_scene(load_gltf(file.string()));
      EXPECT_GT(compiled.triangles, 0u);
      ++loaded;
    } catch (const Error& e) {
      EXPECT_STRNE(e.what(), "");  // rejected, with a message
      rejected[name] = e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << "threw something other than candela::Error: " << e.what();
    } catch (...) {
      ADD_FAILURE() << "threw something other than candela::Error";
    }
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_LT(seconds, 5.0) << "a file of a few kB took too long";
  }

  // Files the validator reports free of errors (numErrors 0 in their .report.json). Their
  // meshes read POSITION accessors without a bufferView, which are all zeros: every
  // triangle has zero area and is skipped, so each may only be rejected for having
  // nothing to draw, never for its skins, morph weights, node transforms or materials.
  const std::set<std::string> valid_without_area = {
      "node/valid.gltf",
      "node/node_weights_override.gltf",
      "node/node_skinned_mesh_without_skin.gltf",
      "skin/ignored_animated_transform.gltf",
      "skin/ignored_local_transform.gltf",
      "skin/ignored_parent_transform.gltf",
      "ext/KHR_materials_ior/material/valid.gltf",
      "ext/KHR_materials_specular/material/valid.gltf",
  };
  for (const std::string& name : valid_without_area) {
    SCOPED_TRACE(name);
    EXPECT_EQ(names.count(name), 1u) << "not in the corpus";
    auto it = rejected.find(name);
    if (it != rejected.end()) {
      EXPECT_EQ(it->second, "the scene has no triangles to render");
    }
  }
  std::cout << files.size() << " validator corpus files: " << loaded << " loaded, " << rejected.size() << " rejected\n";
}

}  // namespace candela::test
