#include "kernel_sources.hpp"

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "error.hpp"

namespace candela {
namespace {

std::string& source_root() {
  static std::string root = [] {
    const char* env = std::getenv("CANDELA_KERNEL_DIR");
    return std::string(env ? env : "");
  }();
  return root;
}

std::string file_text(const EmbeddedKernelFile& f) {
  if (source_root().empty()) return f.text;
  // "cl/x.cl" -> DIR/x.cl; "tests/cl/x.cl" -> DIR/../tests/cl/x.cl
  std::string rel = f.path;
  std::string path = rel.rfind("cl/", 0) == 0 ? source_root() + "/" + rel.substr(3)
                                                : source_root() + "/../" + rel;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot read kernel source " + path + " (from --kernel-dir / CANDELA_KERNEL_DIR)");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string program_source(bool with_tests) {
  std::string src;
  for (const auto& f : embedded_kernel_files()) {
    bool is_test = std::string(f.path).rfind("tests/", 0) == 0;
    if (is_test && !with_tests) continue;
    src += "#line 1 \"" + std::string(f.path) + "\"\n";
    src += file_text(f);
    src += "\n";
  }
  return src;
}

}  // namespace

void set_kernel_source_root(const std::string& root) { source_root() = root; }

std::string renderer_program_source() { return program_source(false); }

std::string test_program_source() { return program_source(true); }

}  // namespace candela
