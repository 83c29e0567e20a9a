#include "test_support.hpp"

#include "error.hpp"
#include "kernel_sources.hpp"
#include "program_cache.hpp"

namespace candela::test {

DeviceEntry pocl_device() { return select_device("pocl"); }

std::optional<DeviceEntry> rusticl_device() {
  for (const auto& d : list_devices())
    if (d.platform_name == "rusticl") return d;
  return std::nullopt;
}

std::optional<DeviceEntry> device_by_name(const std::string& name) {
  if (name == "pocl") return pocl_device();
  if (name == "rusticl") return rusticl_device();
  throw Error("unknown test device " + name);
}

KernelRig::KernelRig(const DeviceEntry& d) : device(d) {
  context = cl::Context(device.device);
  queue = cl::CommandQueue(context, device.device);
  program = build_program(context, device, test_program_source(), "-cl-std=CL1.2").program;
}

std::string scene_path(const std::string& relative) {
  return std::string(CANDELA_SOURCE_DIR) + "/scenes/" + relative;
}

}  // namespace candela::test
