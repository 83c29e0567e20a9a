#include "device/kernel_sources.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "base/device_types.hpp"
#include "base/error.hpp"

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
  std::string path = rel.rfind("cl/", 0) == 0 ? source_root() + "/" + rel.substr(3) : source_root() + "/../" + rel;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot read kernel source " + path + " (from --kernel-dir / CANDELA_KERNEL_DIR)");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// System headers embedded beside the kernel files (cmake/embed_kernels.cmake's SYSTEM)
bool is_system_header(const EmbeddedKernelFile& f) { return std::string(f.path).rfind("nanovdb/", 0) == 0; }

const EmbeddedKernelFile* pnanovdb_header() {
  for (const auto& f : embedded_kernel_files())
    if (std::string(f.path) == "nanovdb/PNanoVDB.h") return &f;
  return nullptr;
}

// Replaces the line that is exactly `line` (a trailing CR allowed) by `by`; false: none
bool replace_line(std::string* text, const std::string& line, const std::string& by) {
  bool found = false;
  for (size_t at = text->find(line); at != std::string::npos; at = text->find(line, at + by.size())) {
    size_t end = at + line.size();
    if (end < text->size() && (*text)[end] == '\r') ++end;
    bool starts = at == 0 || (*text)[at - 1] == '\n';
    bool ends = end == text->size() || (*text)[end] == '\n';
    if (!starts || !ends) {
      at += 1;
      continue;
    }
    text->replace(at, end - at, by);
    found = true;
  }
  return found;
}

// Replaces every identifier `word` (not part of a longer identifier) by `by`; the count
size_t replace_word(std::string* text, const std::string& word, const std::string& by) {
  auto ident = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  size_t n = 0;
  for (size_t at = text->find(word); at != std::string::npos; at = text->find(word, at)) {
    size_t end = at + word.size();
    if ((at > 0 && ident((*text)[at - 1])) || (end < text->size() && ident((*text)[end]))) {
      at = end;
      continue;
    }
    text->replace(at, word.size(), by);
    at += by.size();
    ++n;
  }
  return n;
}

// The file's text with `#include <nanovdb/PNanoVDB.h>` (cl/media/nanovdb.cl) replaced by the
// header's text, between #line markers
std::string resolve_includes(const std::string& path, std::string text) {
  const std::string include = "#include <nanovdb/PNanoVDB.h>";
  size_t at = text.find(include);
  if (at == std::string::npos) return text;
  const EmbeddedKernelFile* h = pnanovdb_header();
  if (!h) throw Error(path + " includes nanovdb/PNanoVDB.h, but candela was built without NanoVDB (libnanovdb-dev)");
  size_t line = 1 + size_t(std::count(text.begin(), text.begin() + at, '\n'));
  std::string body = "#line 1 \"nanovdb/PNanoVDB.h\"\n" + pnanovdb_opencl_text(h->text) + "\n#line " +
                     std::to_string(line + 1) + " \"" + path + "\"";
  text.replace(at, include.size(), body);
  return text;
}

// The kernel's default of every CD_SCENE_FEATURES macro, for a build that does not set it
std::string feature_defaults() {
  std::string text;
#define CD_FEATURE_DEFAULT(name, macro, fallback, needs) \
  text += "#ifndef " #macro "\n#define " #macro " " #fallback "\n#endif\n";
  CD_SCENE_FEATURES(CD_FEATURE_DEFAULT)
#undef CD_FEATURE_DEFAULT
  return text;
}

// The program's files in order, with the test kernels or without, with the table kernels
// (CD_TABLE_KERNELS) or without; `last` (if set): only up to and including that file
std::string program_source(bool with_tests, bool table_kernels, const char* last = nullptr) {
  std::string src = std::string("#define CD_PNANOVDB_AVAILABLE ") + (pnanovdb_header() ? "1" : "0") + "\n";
  src += std::string("#define CD_TABLE_KERNELS ") + (table_kernels ? "1" : "0") + "\n";
  src += feature_defaults();
  bool reached = false;
  for (const auto& f : embedded_kernel_files()) {
    if (is_system_header(f)) continue;
    bool is_test = std::string(f.path).rfind("tests/", 0) == 0;
    if (is_test && !with_tests) continue;
    src += "#line 1 \"" + std::string(f.path) + "\"\n";
    src += resolve_includes(f.path, file_text(f));
    src += "\n";
    if (last && std::string(f.path) == last) {
      reached = true;
      break;
    }
  }
  if (last && !reached) throw Error(std::string("the kernel program has no file ") + last);
  return src;
}

}  // namespace

// PNanoVDB.h's C platform (PNANOVDB_C) as OpenCL C 1.2 takes three edits: its `#include
// <stdint.h>` lines go (PoCL has no stdint.h, and rusticl's is glibc's, which does not
// compile as OpenCL; cl/media/nanovdb.cl typedefs the fixed-width types), its program-scope
// tables become __constant (OpenCL C 1.2 keeps program-scope data in the constant space), and
// its type `double` becomes pnanovdb_double_t, which cl/media/nanovdb.cl defines (devices
// without cl_khr_fp64 reject `double`; a macro named like the keyword is not portable C).
std::string pnanovdb_opencl_text(std::string text) {
  bool ok = replace_line(&text, "#include <stdint.h>", "");
  ok = replace_line(&text, "#define PNANOVDB_STATIC_CONST static const", "#define PNANOVDB_STATIC_CONST __constant") &&
       ok;
  ok = replace_word(&text, "double", "pnanovdb_double_t") > 0 && ok;
  if (!ok)
    throw Error(
        "nanovdb/PNanoVDB.h: not the layout candela adapts to OpenCL C (its stdint.h include, "
        "PNANOVDB_STATIC_CONST and double)");
  return text;
}

void set_kernel_source_root(const std::string& root) { source_root() = root; }

std::string renderer_program_source() { return program_source(false, false); }

std::string test_program_source() { return program_source(true, true); }

std::string tables_program_source() { return program_source(false, true, kLastTablesFile); }

}  // namespace candela
