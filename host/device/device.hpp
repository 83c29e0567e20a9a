// OpenCL platforms and devices: listing and selection.
#pragma once

#include <CL/opencl.hpp>
#include <string>
#include <vector>

namespace candela {

struct DeviceEntry {
  size_t platform_index = 0;
  size_t device_index = 0;  // within its platform
  size_t global_index = 0;  // across all platforms
  cl::Platform platform;
  cl::Device device;
  std::string platform_name, platform_vendor, platform_version;
  std::string name, type, version, driver_version;
  unsigned compute_units = 0;
  unsigned long long global_memory = 0;
  unsigned long long max_alloc = 0;  // largest single buffer
  std::string opencl_c_version;      // e.g. "OpenCL C 1.2 ..."

  std::string selector() const;     // "P.D"
  std::string description() const;  // "name (platform)"
};

// All devices of all platforms; platforms without devices are skipped. Intel's CPU runtime
// ("Intel(R) OpenCL") comes after the other platforms, whatever order the ICD loader found
// them in, so that adding it keeps the others' selectors.
// Throws Error when no OpenCL platform is installed.
std::vector<DeviceEntry> list_devices();

// SEL: "" (first GPU, else first CPU), an index ("0"), "P.D", a type ("cpu", "gpu",
// "accelerator"), "intel" (a device of Intel's own platforms, never another platform's
// device named after an Intel processor) or a case-insensitive substring of the platform's
// name, vendor or version or of the device's name. Throws Error naming the choices when
// nothing matches.
DeviceEntry select_device(const std::string& selector);

// Platforms that expose no device (e.g. Mesa Clover without a GPU), as "P: name (version)"
std::vector<std::string> list_empty_platforms();

// Intel's OpenCL CPU runtime as scripts/setup.sh installs it (CANDELA_INTEL_OPENCL=1) into
// FOLDER (build/intel-opencl: intel-cpu.icd beside lib/): when that ICD file is there and
// neither OCL_ICD_VENDORS nor OPENCL_VENDOR_PATH is set, makes FOLDER/vendors hold links to
// the system's ICD files (/etc/OpenCL/vendors) and to Intel's, and points OCL_ICD_VENDORS
// at it, so that the ICD loader finds Intel's runtime beside the system's. Call before the
// first OpenCL call; child processes inherit the setting. Returns whether it was added.
bool add_installed_intel_runtime(const std::string& folder);

// Table printed by `candela devices`
std::string format_device_table(const std::vector<DeviceEntry>& devices);

}  // namespace candela
