#include "device/tables_program.hpp"

#include <chrono>
#include <utility>
#include <vector>

#include "base/device_types.hpp"
#include "base/error.hpp"
#include "device/kernel_sources.hpp"
#include "device/sheen_albedo.hpp"
#include "device/tables_program_passes.hpp"

namespace candela {

std::string tables_program_options() { return "-cl-std=CL1.2 -DCD_FEATURE_ANISOTROPY=1"; }

// clang-format off
const TablePass kTablePasses[9] = {
    // The GGX table: the isotropic GGX albedos and their averages, then the dielectric's
    {AlbedoTable::ggx, "energy_ggx_albedo_table", {GGX_ALBEDO_N, GGX_ALBEDO_N, 0}, GGX_ALBEDO_QUADRATURE, false,
     AnisotropicAlbedo::none},
    {AlbedoTable::ggx, "energy_ggx_average_table", {GGX_ALBEDO_N, 2, 0}, 0, false, AnisotropicAlbedo::none},
    {AlbedoTable::ggx, "energy_dielectric_albedo_table", {DIEL_ALBEDO_N, DIEL_ALBEDO_R, 2 * DIEL_ALBEDO_F},
     DIEL_ALBEDO_QUADRATURE, false, AnisotropicAlbedo::none},
    {AlbedoTable::ggx, "energy_dielectric_average_table", {DIEL_ALBEDO_R, 2 * DIEL_ALBEDO_F, 0}, 0, false,
     AnisotropicAlbedo::none},
    // Its anisotropic part (zeros in AnisotropicAlbedo::none)
    {AlbedoTable::ggx, "energy_ggx_aniso_table", {GGX_ANISO_N, GGX_ANISO_P, GGX_ANISO_R * GGX_ANISO_Q},
     GGX_ANISO_QUADRATURE, true, AnisotropicAlbedo::exact},
    {AlbedoTable::ggx, "energy_ggx_aniso_average_table", {GGX_ANISO_R * GGX_ANISO_Q, 2, 0}, 0, true,
     AnisotropicAlbedo::none},
    {AlbedoTable::ggx, "energy_dielectric_aniso_table", {DIEL_ANISO_N, DIEL_ANISO_P, DIEL_ANISO_NODES},
     DIEL_ANISO_QUADRATURE, true, AnisotropicAlbedo::exact_glass},
    {AlbedoTable::ggx, "energy_dielectric_aniso_average_table", {DIEL_ANISO_NODES, 0, 0}, 0, true,
     AnisotropicAlbedo::none},
    // The sheen table
    {AlbedoTable::sheen, "sheen_albedo_table", {SHEEN_ALBEDO_N, SHEEN_ALBEDO_N, 0}, SHEEN_ALBEDO_QUADRATURE, false,
     AnisotropicAlbedo::none},
};
// clang-format on

namespace {

// Each table's buffer: its size in floats, the range its values lie in, and its names
struct TableSpec {
  size_t floats;
  float lo, hi;
  const char* what;     // in cached_device_table's errors
  const char* title;    // in the error of a failed computation
  size_t aniso_offset;  // the first float of the anisotropic part (floats: none)
};
TableSpec table_spec(AlbedoTable table) {
  if (table == AlbedoTable::ggx)
    return {GGX_ALBEDO_SIZE, 0.0f, 1.0f, "GGX albedos", "the GGX albedo table", GGX_ANISO_OFFSET};
  return {SHEEN_ALBEDO_SIZE, 0.0f, 100.0f, "sheen albedos", "the sheen albedo table", SHEEN_ALBEDO_SIZE};
}

cl::NDRange pass_range(const TablePass& p) {
  if (!p.range[1]) return cl::NDRange(p.range[0]);
  if (!p.range[2]) return cl::NDRange(p.range[0], p.range[1]);
  return cl::NDRange(p.range[0], p.range[1], p.range[2]);
}

// The table's passes into a new buffer, and its values read back
std::vector<float> compute_table(const cl::Context& context, const cl::CommandQueue& queue, const cl::Program& program,
                                 AlbedoTable table, AnisotropicAlbedo anisotropic, cl::Buffer* buffer) {
  const TableSpec spec = table_spec(table);
  *buffer = cl::Buffer(context, CL_MEM_READ_WRITE, spec.floats * sizeof(float));
  for (const TablePass& p : kTablePasses) {
    if (p.table != table || (p.anisotropic && anisotropic == AnisotropicAlbedo::none)) continue;
    cl::Kernel kernel(program, p.kernel);
    kernel.setArg(0, *buffer);
    if (p.quadrature) kernel.setArg(1, p.quadrature);
    if (p.exact_from != AnisotropicAlbedo::none) kernel.setArg(2, cl_uint(anisotropic >= p.exact_from));
    queue.enqueueNDRangeKernel(kernel, cl::NullRange, pass_range(p));
  }
  if (anisotropic == AnisotropicAlbedo::none && spec.aniso_offset < spec.floats) {
    // Unread by a kernel without the feature; zeros, so the cached table is well defined
    queue.enqueueFillBuffer(*buffer, 0.0f, spec.aniso_offset * sizeof(float),
                            (spec.floats - spec.aniso_offset) * sizeof(float));
  }
  std::vector<float> values(spec.floats);
  queue.enqueueReadBuffer(*buffer, CL_TRUE, 0, spec.floats * sizeof(float), values.data());
  return values;
}

}  // namespace

cl::Buffer albedo_table(const cl::Context& context, const cl::CommandQueue& queue, LazyProgram& program,
                        AlbedoTable table, AnisotropicAlbedo anisotropic, const std::string& cache_path,
                        bool* from_cache, double* seconds) {
  auto start = std::chrono::steady_clock::now();
  const TableSpec spec = table_spec(table);
  cl::Buffer buffer;
  try {
    buffer = cached_device_table(
        context, cache_path, spec.floats, spec.lo, spec.hi, spec.what,
        [&](cl::Buffer* b) { return compute_table(context, queue, program.get(), table, anisotropic, b); }, from_cache);
  } catch (const cl::Error& e) {
    throw Error(cl_error_message(std::string("computing ") + spec.title, e.err()));
  }
  *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return buffer;
}

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
