// Kernel sources: embedded at build time (cmake/embed_kernels.cmake) or, while
// developing, read from disk (--kernel-dir or CANDELA_KERNEL_DIR).
#pragma once

#include <string>
#include <vector>

namespace candela {

struct EmbeddedKernelFile {
  const char* path;  // relative to the repository root, e.g. "cl/core/rng.cl"
  const char* text;
};

const std::vector<EmbeddedKernelFile>& embedded_kernel_files();

// Where kernel sources come from: empty = embedded; else the cl/ directory on disk
void set_kernel_source_root(const std::string& root);

// NanoVDB's PNanoVDB.h (its C platform) edited to compile as OpenCL C 1.2; throws Error when
// the text lacks what the edits expect
std::string pnanovdb_opencl_text(std::string text);

// The renderer program: the kernel's default of every feature macro (CD_SCENE_FEATURES), then
// every cl/ file in order, each starting with a #line marker. Its table kernels (those that
// compute the tables of device/energy.hpp and device/sheen_albedo.hpp) are left out
// (CD_TABLE_KERNELS 0): the tables program computes them, and a driver that compiles every
// kernel of a program (PoCL, for the program's binary) compiles the scene's kernel alone.
std::string renderer_program_source();

// The renderer program with its table kernels, followed by the test kernels of tests/cl/
std::string test_program_source();

// The tables program (host/device/tables_program.hpp): the renderer program with its table
// kernels, up to and including kLastTablesFile, the last file with a table kernel
// (cl/program.cmake)
constexpr const char* kLastTablesFile = "cl/bsdf/energy_dielectric.cl";
std::string tables_program_source();

}  // namespace candela
