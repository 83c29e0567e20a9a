// The albedo tables as one list: every pass of every table (kTablePasses), computed and
// cached by one pipeline (albedo_table), which device/energy.hpp's GGX table and
// device/sheen_albedo.hpp's sheen table run. A new table, or a new part of one, is an entry
// here, its kernel (under CD_TABLE_KERNELS in the tables program's files) and its size.
#pragma once

#include <CL/opencl.hpp>
#include <string>

#include "device/energy.hpp"
#include "device/program_cache.hpp"

namespace candela {

// The albedo tables, each a scene buffer of floats: the GGX table (the GGX, dielectric and
// anisotropic albedos of energy compensation, device/energy.hpp) and the sheen table
// (device/sheen_albedo.hpp)
enum class AlbedoTable { ggx, sheen };

// One pass of a table's computation: a table kernel of the tables program over its range,
// writing into its table's buffer (argument 0). kTablePasses lists every pass of every table
// in the order they run; the tables program's kernels are exactly theirs.
struct TablePass {
  AlbedoTable table;
  const char* kernel;
  size_t range[3];     // its NDRange, 0 past its dimensions
  cl_uint quadrature;  // argument 1: its quadrature's node count; 0: none (an average pass)
  bool anisotropic;    // of the anisotropic part: not run in AnisotropicAlbedo::none
  // argument 2 (where not `none`): 1 where the table's mode is at least this one (exact
  // integration), else 0 (the approximate fill)
  AnisotropicAlbedo exact_from;
};
extern const TablePass kTablePasses[9];

// A table computed by `program` (which must hold the table kernels: the tables program, or
// the tests' program) in anisotropic mode `anisotropic` (the GGX table's; none for the
// sheen's), loaded from the cache entry `cache_path` (empty: no cache), else computed by its
// passes on the device (the program built only then) and stored there. *from_cache says
// which, *seconds how long it took.
cl::Buffer albedo_table(const cl::Context& context, const cl::CommandQueue& queue, LazyProgram& program,
                        AlbedoTable table, AnisotropicAlbedo anisotropic, const std::string& cache_path,
                        bool* from_cache, double* seconds);

}  // namespace candela
