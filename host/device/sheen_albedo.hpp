// The sheen albedo table of KHR_materials_sheen's albedo scaling (cl/bsdf/sheen.cl), the
// sheen_albedo scene buffer: computed on the device by the program's own kernel, so it
// describes the lobe exactly as the kernels evaluate it, and cached beside the program.
#pragma once

#include <CL/opencl.hpp>
#include <string>

#include "device/program_cache.hpp"

namespace candela {

struct SheenAlbedoTable {
  cl::Buffer buffer;  // SHEEN_ALBEDO_SIZE floats
  double seconds = 0.0;
  bool from_cache = false;
};

// The table for `program` (which must hold sheen_albedo_table), whose cache entry is
// `program_cache_file` (ProgramBuild::cache_file; empty: no cache): loaded from beside it,
// else computed on the device and stored there
SheenAlbedoTable sheen_albedo_table(const cl::Context& context, const cl::CommandQueue& queue,
                                    const cl::Program& program, const std::string& program_cache_file);

// The same for the program built on demand (the tables program, host/device/tables_program.hpp):
// built only when the table is not in the cache
SheenAlbedoTable sheen_albedo_table(const cl::Context& context, const cl::CommandQueue& queue, LazyProgram& program);

}  // namespace candela
