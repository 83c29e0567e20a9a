// The sheen albedo table of KHR_materials_sheen's albedo scaling (cl/bsdf/sheen.cl), the
// sheen_albedo scene buffer: computed on the device by the kernels' own lobe (the tables
// program's sheen_albedo_table, device/tables_program.hpp), so it describes the lobe exactly
// as the kernels evaluate it, and cached beside that program's cache entry.
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

// The table computed by `program` (which must hold sheen_albedo_table), loaded from the cache
// entry beside the program's, else computed on the device (the program built only then) and
// stored there
SheenAlbedoTable sheen_albedo_table(const cl::Context& context, const cl::CommandQueue& queue, LazyProgram& program);

// The same for a program built already, whose cache entry is `program_cache_file`
// (ProgramBuild::cache_file; empty: no cache)
SheenAlbedoTable sheen_albedo_table(const cl::Context& context, const cl::CommandQueue& queue,
                                    const cl::Program& program, const std::string& program_cache_file);

}  // namespace candela
