// The tables program: the kernels that compute the tables a renderer binds beside the scene
// (the GGX and dielectric albedos of energy compensation, device/energy.hpp; the sheen
// albedos, device/sheen_albedo.hpp). It is the renderer program's files up to the last table
// kernel (tables_program_source, device/kernel_sources.hpp), built with options of its own
// that no scene changes: the same code as the scene kernels' lookups read, one program and
// one set of cached tables per device for every scene's kernel variant, and ready to run
// before a scene's kernel features are known (KernelPrebuild starts it while the scene loads).
#pragma once

#include <CL/opencl.hpp>
#include <functional>
#include <string>

#include "device/device.hpp"
#include "device/energy.hpp"
#include "device/program_cache.hpp"

namespace candela {

// Every table kernel compiled in (the anisotropic ones with CD_FEATURE_ANISOTROPY)
std::string tables_program_options();

// The tables program on `device`, built when first needed (`before_compile` called then:
// a table is about to be computed)
LazyProgram tables_program(const cl::Context& context, const DeviceEntry& device,
                           std::function<void()> before_compile = {});

// The tables a renderer binds, from the kernel cache or computed by the tables program
struct DeviceTables {
  cl::Buffer ggx_albedo;    // with energy compensation
  cl::Buffer sheen_albedo;  // with the sheen feature
};
// `before_compute`: called once before the first table that is not in the cache is computed
DeviceTables device_tables(const cl::Context& context, const cl::CommandQueue& queue, const DeviceEntry& device,
                           bool energy_compensation, AnisotropicAlbedo anisotropic, bool sheen,
                           const std::function<void()>& before_compute = {});

// The cache entry of the table every scene with energy compensation binds on `device` (GGX
// and dielectric albedos, no anisotropic part); empty without a cache
std::string common_tables_cache_file(const DeviceEntry& device);

// Computes that table into the kernel cache (in a context of its own): the work
// KernelPrebuild::start_tables does beside the scene's loading
void compute_common_tables(const DeviceEntry& device);

}  // namespace candela
