#include "device/sheen_albedo.hpp"

#include <string>

#include "device/program_cache.hpp"
#include "device/tables_program_passes.hpp"

namespace candela {

SheenAlbedoTable sheen_albedo_table(const cl::Context& context, const cl::CommandQueue& queue, LazyProgram& program) {
  SheenAlbedoTable t;
  std::string path = program.cache_file().empty() ? "" : program.cache_file() + ".sheen_albedo";
  t.buffer = albedo_table(context, queue, program, AlbedoTable::sheen, AnisotropicAlbedo::none, path, &t.from_cache,
                          &t.seconds);
  return t;
}

SheenAlbedoTable sheen_albedo_table(const cl::Context& context, const cl::CommandQueue& queue,
                                    const cl::Program& program, const std::string& program_cache_file) {
  LazyProgram built(program, program_cache_file);
  return sheen_albedo_table(context, queue, built);
}

}  // namespace candela
