#include "device/device.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <sstream>

#include "base/error.hpp"

namespace candela {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::string trim(std::string s) {
  while (!s.empty() && (s.back() == '\0' || std::isspace((unsigned char)s.back()))) s.pop_back();
  return s;
}

std::string type_name(cl_device_type t) {
  if (t & CL_DEVICE_TYPE_GPU) return "gpu";
  if (t & CL_DEVICE_TYPE_CPU) return "cpu";
  if (t & CL_DEVICE_TYPE_ACCELERATOR) return "accelerator";
  return "other";
}

bool parse_index(const std::string& s, size_t* out) {
  if (s.empty() || s.size() > 9 || !std::all_of(s.begin(), s.end(), ::isdigit)) return false;
  *out = std::stoul(s);
  return true;
}

// Intel's CPU runtime's platform (its GPU platforms are "Intel(R) OpenCL Graphics" and the like)
bool is_intel_cpu_runtime(const std::string& platform_name) { return platform_name == "Intel(R) OpenCL"; }

// The platforms in the order candela numbers them: the loader's, Intel's CPU runtime last
std::vector<cl::Platform> ordered_platforms() {
  std::vector<cl::Platform> platforms;
  cl::Platform::get(&platforms);
  std::stable_partition(platforms.begin(), platforms.end(), [](const cl::Platform& p) {
    return !is_intel_cpu_runtime(trim(p.getInfo<CL_PLATFORM_NAME>()));
  });
  return platforms;
}

}  // namespace

bool add_installed_intel_runtime(const std::string& folder) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path icd = fs::path(folder) / "intel-cpu.icd";
  if (std::getenv("OCL_ICD_VENDORS") || std::getenv("OPENCL_VENDOR_PATH") || !fs::exists(icd, ec)) return false;
  const fs::path vendors = fs::path(folder) / "vendors";
  fs::create_directories(vendors, ec);
  std::set<std::string> wanted;
  bool complete = true;
  auto link = [&](const fs::path& target, const std::string& name) {
    wanted.insert(name);
    const fs::path l = vendors / name;
    std::error_code e;
    if (fs::is_symlink(l, e) && fs::read_symlink(l, e) == target) return;
    fs::remove(l, e);
    fs::create_symlink(target, l, e);
    if (e) complete = false;
  };
  // Refreshed at every start: a driver installed or removed later is seen
  for (const auto& entry : fs::directory_iterator("/etc/OpenCL/vendors", ec))
    if (entry.path().extension() == ".icd") link(entry.path(), entry.path().filename().string());
  link(fs::absolute(icd, ec), "candela-intel-cpu.icd");
  for (const auto& entry : fs::directory_iterator(vendors, ec))
    if (!wanted.count(entry.path().filename().string())) fs::remove(entry.path(), ec);
  if (!complete) return false;  // e.g. a read-only build folder: the system's ICDs alone
  setenv("OCL_ICD_VENDORS", vendors.c_str(), 0);
  return true;
}

std::string DeviceEntry::selector() const {
  return std::to_string(platform_index) + "." + std::to_string(device_index);
}

std::string DeviceEntry::description() const { return name + " (" + platform_name + ")"; }

std::vector<DeviceEntry> list_devices() {
  cl_uint num_platforms = 0;
  cl_int err = clGetPlatformIDs(0, nullptr, &num_platforms);
  if (err == CL_PLATFORM_NOT_FOUND_KHR || (err == CL_SUCCESS && num_platforms == 0))
    throw Error(
        "no OpenCL platform found: install an OpenCL driver, e.g. `apt-get install "
        "pocl-opencl-icd` (scripts/demo does this)");
  if (err != CL_SUCCESS) throw Error(cl_error_message("clGetPlatformIDs", err));

  std::vector<cl::Platform> platforms = ordered_platforms();
  std::vector<DeviceEntry> out;
  for (size_t p = 0; p < platforms.size(); ++p) {
    std::vector<cl::Device> devices;
    try {
      platforms[p].getDevices(CL_DEVICE_TYPE_ALL, &devices);
    } catch (const cl::Error&) {
      continue;  // CL_DEVICE_NOT_FOUND: a platform without devices (e.g. Mesa Clover)
    }
    for (size_t d = 0; d < devices.size(); ++d) {
      DeviceEntry e;
      e.platform_index = p;
      e.device_index = d;
      e.global_index = out.size();
      e.platform = platforms[p];
      e.device = devices[d];
      e.platform_name = trim(platforms[p].getInfo<CL_PLATFORM_NAME>());
      e.platform_vendor = trim(platforms[p].getInfo<CL_PLATFORM_VENDOR>());
      e.platform_version = trim(platforms[p].getInfo<CL_PLATFORM_VERSION>());
      e.name = trim(devices[d].getInfo<CL_DEVICE_NAME>());
      e.type = type_name(devices[d].getInfo<CL_DEVICE_TYPE>());
      e.version = trim(devices[d].getInfo<CL_DEVICE_VERSION>());
      e.driver_version = trim(devices[d].getInfo<CL_DRIVER_VERSION>());
      e.compute_units = devices[d].getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
      e.global_memory = devices[d].getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
      e.max_alloc = devices[d].getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
      e.opencl_c_version = trim(devices[d].getInfo<CL_DEVICE_OPENCL_C_VERSION>());
      out.push_back(e);
    }
  }
  return out;
}

std::vector<std::string> list_empty_platforms() {
  std::vector<cl::Platform> platforms = ordered_platforms();
  std::vector<std::string> out;
  for (size_t p = 0; p < platforms.size(); ++p) {
    std::vector<cl::Device> devices;
    try {
      platforms[p].getDevices(CL_DEVICE_TYPE_ALL, &devices);
    } catch (const cl::Error&) {
    }
    if (devices.empty())
      out.push_back(std::to_string(p) + ": " + trim(platforms[p].getInfo<CL_PLATFORM_NAME>()) + " (" +
                    trim(platforms[p].getInfo<CL_PLATFORM_VERSION>()) + ")");
  }
  return out;
}

DeviceEntry select_device(const std::string& selector) {
  std::vector<DeviceEntry> devices = list_devices();
  if (devices.empty()) throw Error("OpenCL platforms are installed but none has a device");
  std::string sel = lower(trim(selector));
  auto first_of_type = [&](const std::string& type) -> const DeviceEntry* {
    for (const auto& d : devices)
      if (d.type == type) return &d;
    return nullptr;
  };

  if (sel.empty() || sel == "default") {
    if (auto d = first_of_type("gpu")) return *d;
    if (auto d = first_of_type("cpu")) return *d;
    return devices.front();
  }
  // Numbers select by position and never fall through to name matching
  size_t index = 0;
  if (parse_index(sel, &index)) {
    if (index < devices.size()) return devices[index];
    throw Error("--device " + selector + ": there are only " + std::to_string(devices.size()) + " OpenCL devices:\n" +
                format_device_table(devices));
  }
  auto dot = sel.find('.');
  size_t p = 0, d = 0;
  if (dot != std::string::npos && parse_index(sel.substr(0, dot), &p) && parse_index(sel.substr(dot + 1), &d)) {
    for (const auto& e : devices)
      if (e.platform_index == p && e.device_index == d) return e;
    throw Error("--device " + selector + ": no such platform.device; available devices:\n" +
                format_device_table(devices));
  }
  if (sel == "cpu" || sel == "gpu" || sel == "accelerator") {
    if (auto e = first_of_type(sel)) return *e;
  }
  // Intel's own platforms only: PoCL's device names carry the processor's, "...Intel(R) Xeon(R)..."
  if (sel == "intel") {
    for (const auto& e : devices)
      if (lower(e.platform_name).find("intel") != std::string::npos ||
          lower(e.platform_vendor).find("intel") != std::string::npos)
        return e;
    throw Error(
        "--device intel: Intel's OpenCL CPU runtime is not installed; install it into the build folder with "
        "`CANDELA_INTEL_OPENCL=1 bash scripts/setup.sh`");
  }
  for (const auto& e : devices) {
    for (const std::string& field : {e.platform_name, e.platform_vendor, e.platform_version, e.name})
      if (lower(field).find(sel) != std::string::npos) return e;
  }
  throw Error("no OpenCL device matches --device '" + selector + "'; available devices:\n" +
              format_device_table(devices));
}

std::string format_device_table(const std::vector<DeviceEntry>& devices) {
  std::ostringstream os;
  char line[512];
  std::snprintf(line, sizeof line, "%-4s %-6s %-4s %-12s %5s %9s  %s\n", "#", "select", "type", "opencl", "units",
                "memory", "device (platform)");
  os << line;
  for (const auto& d : devices) {
    std::string cl_version = d.version.rfind("OpenCL ", 0) == 0 ? d.version.substr(7) : d.version;
    cl_version = cl_version.substr(0, cl_version.find(' '));
    std::snprintf(line, sizeof line, "%-4zu %-6s %-4s %-12s %5u %6.1f GiB  %s\n", d.global_index, d.selector().c_str(),
                  d.type.c_str(), ("OpenCL " + cl_version).c_str(), d.compute_units, d.global_memory / 1073741824.0,
                  d.description().c_str());
    os << line;
  }
  return os.str();
}

}  // namespace candela
