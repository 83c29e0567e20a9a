// Prints the renderer's OpenCL program exactly as the host hands it to a driver
// (renderer_program_source()); scripts/gpu/compile.sh compiles it offline for GPU targets.
// The sources are the embedded ones, or those of CANDELA_KERNEL_DIR when set.
//
// Usage: candela_kernel_source > program.cl
#include <cstdio>
#include <exception>
#include <string>

#include "device/kernel_sources.hpp"

int main(int argc, char** argv) {
  if (argc != 1) {
    std::fprintf(stderr, "usage: %s > program.cl\n", argv[0]);
    return 2;
  }
  try {
    std::string src = candela::renderer_program_source();
    if (std::fwrite(src.data(), 1, src.size(), stdout) != src.size() || std::fflush(stdout) != 0) {
      std::fprintf(stderr, "candela_kernel_source: cannot write the program\n");
      return 1;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "candela_kernel_source: %s\n", e.what());
    return 1;
  }
  return 0;
}
