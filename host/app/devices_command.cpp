// `candela devices`: the OpenCL platforms and devices, and the platforms without any.
#include <cstdio>

#include "app/commands.hpp"
#include "device/device.hpp"

namespace candela {

CLI::App* add_devices_command(CLI::App* app) {
  return app->add_subcommand("devices", "List OpenCL platforms and devices");
}

int run_devices_command() {
  std::printf("%s", format_device_table(list_devices()).c_str());
  for (const auto& p : list_empty_platforms()) {
    std::printf("platform %s has no devices\n", p.c_str());
    if (p.find("rusticl") != std::string::npos)
      std::printf("  (rusticl shows its CPU device with RUSTICL_ENABLE=llvmpipe)\n");
  }
  return 0;
}

}  // namespace candela
