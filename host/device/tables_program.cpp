#include "device/tables_program.hpp"

#include <utility>

#include "device/kernel_sources.hpp"
#include "device/sheen_albedo.hpp"

namespace candela {

std::string tables_program_options() { return "-cl-std=CL1.2 -DCD_FEATURE_ANISOTROPY=1"; }

LazyProgram tables_program(const cl::Context& context, const DeviceEntry& device,
                           std::function<void()> before_compile) {
  return LazyProgram(context, device, tables_program_source(), tables_program_options(), std::move(before_compile));
}

DeviceTables device_tables(const cl::Context& context, const cl::CommandQueue& queue, const DeviceEntry& device,
                           bool energy_compensation, AnisotropicAlbedo anisotropic, bool sheen,
                           const std::function<void()>& before_compute) {
  DeviceTables t;
  if (!energy_compensation && !sheen) return t;
  LazyProgram program = tables_program(context, device, before_compute);
  if (energy_compensation) t.ggx_albedo = ggx_albedo_table(context, queue, program, anisotropic).buffer;
  if (sheen) t.sheen_albedo = sheen_albedo_table(context, queue, program).buffer;
  return t;
}

std::string common_tables_cache_file(const DeviceEntry& device) {
  return ggx_albedo_cache_file(program_cache_file(device, tables_program_source(), tables_program_options()),
                               AnisotropicAlbedo::none);
}

void compute_common_tables(const DeviceEntry& device) {
  cl::Context context(device.device);
  cl::CommandQueue queue(context, device.device);
  LazyProgram program = tables_program(context, device);
  ggx_albedo_table(context, queue, program, AnisotropicAlbedo::none);
}

}  // namespace candela
