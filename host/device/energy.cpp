#include "device/energy.hpp"

#include <chrono>
#include <cstring>
#include <vector>

#include "base/device_types.hpp"
#include "base/error.hpp"
#include "device/program_cache.hpp"

namespace candela {
namespace {

constexpr size_t kBytes = GGX_ALBEDO_SIZE * sizeof(float);

std::vector<float> compute_table(const cl::Context& context, const cl::CommandQueue& queue, const cl::Program& program,
                                 AnisotropicAlbedo anisotropic, cl::Buffer* buffer) {
  *buffer = cl::Buffer(context, CL_MEM_READ_WRITE, kBytes);
  cl::Kernel albedo(program, "energy_ggx_albedo_table"), average(program, "energy_ggx_average_table");
  albedo.setArg(0, *buffer);
  albedo.setArg(1, cl_uint(GGX_ALBEDO_QUADRATURE));
  average.setArg(0, *buffer);
  queue.enqueueNDRangeKernel(albedo, cl::NullRange, cl::NDRange(GGX_ALBEDO_N, GGX_ALBEDO_N));
  queue.enqueueNDRangeKernel(average, cl::NullRange, cl::NDRange(GGX_ALBEDO_N, 2));
  cl::Kernel diel(program, "energy_dielectric_albedo_table"), diel_average(program, "energy_dielectric_average_table");
  diel.setArg(0, *buffer);
  diel.setArg(1, cl_uint(DIEL_ALBEDO_QUADRATURE));
  diel_average.setArg(0, *buffer);
  queue.enqueueNDRangeKernel(diel, cl::NullRange, cl::NDRange(DIEL_ALBEDO_N, DIEL_ALBEDO_R, 2 * DIEL_ALBEDO_F));
  queue.enqueueNDRangeKernel(diel_average, cl::NullRange, cl::NDRange(DIEL_ALBEDO_R, 2 * DIEL_ALBEDO_F));
  std::vector<float> table(GGX_ALBEDO_SIZE);
  if (anisotropic != AnisotropicAlbedo::none) {
    cl::Kernel aniso(program, "energy_ggx_aniso_table"), aniso_average(program, "energy_ggx_aniso_average_table");
    aniso.setArg(0, *buffer);
    aniso.setArg(1, cl_uint(GGX_ANISO_QUADRATURE));
    aniso.setArg(2, cl_uint(anisotropic != AnisotropicAlbedo::approximate));
    aniso_average.setArg(0, *buffer);
    queue.enqueueNDRangeKernel(aniso, cl::NullRange, cl::NDRange(GGX_ANISO_N, GGX_ANISO_P, GGX_ANISO_R * GGX_ANISO_Q));
    queue.enqueueNDRangeKernel(aniso_average, cl::NullRange, cl::NDRange(GGX_ANISO_R * GGX_ANISO_Q, 2));
    cl::Kernel glass(program, "energy_dielectric_aniso_table"),
        glass_average(program, "energy_dielectric_aniso_average_table");
    glass.setArg(0, *buffer);
    glass.setArg(1, cl_uint(DIEL_ANISO_QUADRATURE));
    glass.setArg(2, cl_uint(anisotropic == AnisotropicAlbedo::exact_glass));
    glass_average.setArg(0, *buffer);
    queue.enqueueNDRangeKernel(glass, cl::NullRange, cl::NDRange(DIEL_ANISO_N, DIEL_ANISO_P, DIEL_ANISO_NODES));
    queue.enqueueNDRangeKernel(glass_average, cl::NullRange, cl::NDRange(DIEL_ANISO_NODES));
  } else {
    // Unread by a kernel without the feature; zeros, so the cached table is well defined
    queue.enqueueFillBuffer(*buffer, 0.0f, GGX_ANISO_OFFSET * sizeof(float),
                            (GGX_ALBEDO_SIZE - GGX_ANISO_OFFSET) * sizeof(float));
  }
  queue.enqueueReadBuffer(*buffer, CL_TRUE, 0, kBytes, table.data());
  return table;
}

}  // namespace

AnisotropicAlbedo anisotropic_albedo(bool kernel_feature, const std::vector<dev::Material>& materials) {
  if (!kernel_feature) return AnisotropicAlbedo::none;
  AnisotropicAlbedo need = AnisotropicAlbedo::approximate;
  for (const dev::Material& m : materials) {
    bool gltf = m.type == MATERIAL_GLTF && m.params.gltf.anisotropy_strength > 0.0f;
    if (gltf && m.params.gltf.transmission > 0.0f && !(m.flags & MATERIAL_THIN_WALLED))
      return AnisotropicAlbedo::exact_glass;
    if (gltf || (m.type == MATERIAL_CONDUCTOR && m.params.conductor.anisotropy_strength > 0.0f))
      need = AnisotropicAlbedo::exact;
  }
  return need;
}

std::string ggx_albedo_cache_file(const std::string& program_cache_file, AnisotropicAlbedo anisotropic) {
  if (program_cache_file.empty()) return "";
  switch (anisotropic) {
    case AnisotropicAlbedo::none:
      return program_cache_file + ".ggx_albedo";
    case AnisotropicAlbedo::approximate:
      return program_cache_file + ".ggx_albedo_aniso_approx";
    case AnisotropicAlbedo::exact:
      return program_cache_file + ".ggx_albedo_aniso";
    case AnisotropicAlbedo::exact_glass:
      return program_cache_file + ".ggx_albedo_aniso_glass";
  }
  return "";
}

GgxAlbedoTable ggx_albedo_table(const cl::Context& context, const cl::CommandQueue& queue, LazyProgram& program,
                                AnisotropicAlbedo anisotropic) {
  auto start = std::chrono::steady_clock::now();
  GgxAlbedoTable t;
  try {
    t.buffer = cached_device_table(
        context, ggx_albedo_cache_file(program.cache_file(), anisotropic), GGX_ALBEDO_SIZE, 0.0f, 1.0f, "GGX albedos",
        [&](cl::Buffer* buffer) { return compute_table(context, queue, program.get(), anisotropic, buffer); },
        &t.from_cache);
  } catch (const cl::Error& e) {
    throw Error(cl_error_message("computing the GGX albedo table", e.err()));
  }
  t.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return t;
}

GgxAlbedoTable ggx_albedo_table(const cl::Context& context, const cl::CommandQueue& queue, const cl::Program& program,
                                const std::string& program_cache_file, AnisotropicAlbedo anisotropic) {
  LazyProgram built(program, program_cache_file);
  return ggx_albedo_table(context, queue, built, anisotropic);
}

}  // namespace candela
