// The GGX albedo table of multiple-scattering energy compensation (cl/bsdf/energy.cl), the
// ggx_albedo scene buffer: computed on the device by the kernels' own lobes (the tables
// program's table kernels, device/tables_program.hpp), so it describes the lobes exactly as
// the kernels evaluate them, and cached beside that program's cache entry.
#pragma once

#include <CL/opencl.hpp>
#include <string>
#include <vector>

#include "base/device_types.hpp"
#include "device/program_cache.hpp"

namespace candela {

struct GgxAlbedoTable {
  cl::Buffer buffer;  // GGX_ALBEDO_SIZE floats: the GGX and the dielectric tables
  double seconds = 0.0;
  bool from_cache = false;
};

// What the table's anisotropic part (lobes with ax != ay) holds. Only a kernel built with
// CD_FEATURE_ANISOTROPY reads it: `none` (zeros) for any other.
// `exact` integrates it by quadrature (several minutes on rusticl, so only for scenes with an
// anisotropic material); `approximate` fills it with the isotropic table's values at
// alpha = sqrt(ax ay) at next to no cost (the generic kernel of a scene without anisotropy).
// `exact_glass` integrates the anisotropic rough dielectric's part too (the rest fill it
// from the isotropic dielectric table).
enum class AnisotropicAlbedo { none, approximate, exact, exact_glass };

// The part a scene's kernel needs: `none` without the feature, `exact_glass` when some
// material is anisotropic refracting glass (anisotropy strength > 0, transmission > 0, not
// thin-walled), `exact` when some material has anisotropy strength > 0, else `approximate`
AnisotropicAlbedo anisotropic_albedo(bool kernel_feature, const std::vector<dev::Material>& materials);

// The table computed by `program` (which must hold the table kernels: the tables program of
// device/tables_program.hpp, or the tests' program), loaded from the cache entry beside the
// program's (ggx_albedo_cache_file), else computed on the device (the program built only
// then) and stored there. Each anisotropic mode is cached apart.
GgxAlbedoTable ggx_albedo_table(const cl::Context& context, const cl::CommandQueue& queue, LazyProgram& program,
                                AnisotropicAlbedo anisotropic);

// The same for a program built already, whose cache entry is `program_cache_file`
// (ProgramBuild::cache_file; empty: no cache)
GgxAlbedoTable ggx_albedo_table(const cl::Context& context, const cl::CommandQueue& queue, const cl::Program& program,
                                const std::string& program_cache_file,
                                AnisotropicAlbedo anisotropic = AnisotropicAlbedo::none);

// The cache entry of the table in `anisotropic` mode beside a program's entry (empty: no cache)
std::string ggx_albedo_cache_file(const std::string& program_cache_file, AnisotropicAlbedo anisotropic);

}  // namespace candela
