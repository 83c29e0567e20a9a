#include "device/sheen_albedo.hpp"

#include <chrono>
#include <cmath>
#include <cstring>
#include <vector>

#include "base/device_types.hpp"
#include "base/error.hpp"
#include "device/program_cache.hpp"

namespace candela {
namespace {

constexpr size_t kBytes = SHEEN_ALBEDO_SIZE * sizeof(float);

std::vector<float> compute_table(const cl::Context& context, const cl::CommandQueue& queue, const cl::Program& program,
                                 cl::Buffer* buffer) {
  *buffer = cl::Buffer(context, CL_MEM_READ_WRITE, kBytes);
  cl::Kernel albedo(program, "sheen_albedo_table");
  albedo.setArg(0, *buffer);
  albedo.setArg(1, cl_uint(SHEEN_ALBEDO_QUADRATURE));
  queue.enqueueNDRangeKernel(albedo, cl::NullRange, cl::NDRange(SHEEN_ALBEDO_N, SHEEN_ALBEDO_N));
  std::vector<float> table(SHEEN_ALBEDO_SIZE);
  queue.enqueueReadBuffer(*buffer, CL_TRUE, 0, kBytes, table.data());
  return table;
}

}  // namespace

SheenAlbedoTable sheen_albedo_table(const cl::Context& context, const cl::CommandQueue& queue, LazyProgram& program) {
  auto start = std::chrono::steady_clock::now();
  SheenAlbedoTable t;
  std::string path = program.cache_file().empty() ? "" : program.cache_file() + ".sheen_albedo";
  try {
    t.buffer = cached_device_table(
        context, path, SHEEN_ALBEDO_SIZE, 0.0f, 100.0f, "sheen albedos",
        [&](cl::Buffer* buffer) { return compute_table(context, queue, program.get(), buffer); }, &t.from_cache);
  } catch (const cl::Error& e) {
    throw Error(cl_error_message("computing the sheen albedo table", e.err()));
  }
  t.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return t;
}

SheenAlbedoTable sheen_albedo_table(const cl::Context& context, const cl::CommandQueue& queue,
                                    const cl::Program& program, const std::string& program_cache_file) {
  LazyProgram built(program, program_cache_file);
  return sheen_albedo_table(context, queue, built);
}

}  // namespace candela
