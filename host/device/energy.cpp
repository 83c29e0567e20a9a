#include "device/energy.hpp"

#include <vector>

#include "base/device_types.hpp"
#include "device/program_cache.hpp"
#include "device/tables_program_passes.hpp"

namespace candela {

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
  GgxAlbedoTable t;
  t.buffer = albedo_table(context, queue, program, AlbedoTable::ggx, anisotropic,
                          ggx_albedo_cache_file(program.cache_file(), anisotropic), &t.from_cache, &t.seconds);
  return t;
}

GgxAlbedoTable ggx_albedo_table(const cl::Context& context, const cl::CommandQueue& queue, const cl::Program& program,
                                const std::string& program_cache_file, AnisotropicAlbedo anisotropic) {
  LazyProgram built(program, program_cache_file);
  return ggx_albedo_table(context, queue, built, anisotropic);
}

}  // namespace candela
