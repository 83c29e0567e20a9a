// The GGX albedo table of multiple-scattering energy compensation (cl/bsdf/energy.cl), the
// ggx_albedo scene buffer: computed on the device by the program's own kernels, so it
// describes the lobes exactly as the kernels evaluate them, and cached beside the program.
#pragma once

#include <CL/opencl.hpp>
#include <string>

namespace candela {

struct GgxAlbedoTable {
  cl::Buffer buffer;  // GGX_ALBEDO_SIZE floats: the GGX and the dielectric tables
  double seconds = 0.0;
  bool from_cache = false;
};

// The table for `program`, whose cache entry is `program_cache_file`
// (ProgramBuild::cache_file; empty: no cache): loaded from beside it, else computed on the
// device and stored there
GgxAlbedoTable ggx_albedo_table(const cl::Context& context, const cl::CommandQueue& queue, const cl::Program& program,
                                const std::string& program_cache_file);

}  // namespace candela
