#include "device/program_cache.hpp"

#include <unistd.h>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>
#include <utility>
#include <vector>

#include "base/error.hpp"
#include "base/hash.hpp"

namespace fs = std::filesystem;

namespace candela {
namespace {

constexpr char kMagic[8] = {'C', 'N', 'D', 'L', 'B', 'I', 'N', '1'};

std::string hex64(uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", (unsigned long long)v);
  return buf;
}

std::string cache_key(const DeviceEntry& d, const std::string& source, const std::string& options) {
  std::string key;
  for (const std::string& part : {d.platform_name, d.platform_version, d.name, d.version, d.driver_version, options,
                                  std::string(CANDELA_VERSION)}) {
    key += part;
    key += '\x1f';
  }
  return hex64(fnv1a64(source, fnv1a64(key)));
}

// Something other than a regular file where an entry belongs (a directory, a FIFO, a device)
// is left alone and reported once per path: the cache is skipped for that entry, the build
// goes on from source, and opening it is never tried (a FIFO would block)
bool usable_entry_path(const std::string& path) {
  std::error_code ec;
  fs::file_status st = fs::status(path, ec);
  if (ec || !fs::exists(st) || fs::is_regular_file(st)) return true;
  static std::mutex mutex;
  static std::set<std::string> reported;
  std::lock_guard<std::mutex> lock(mutex);
  if (reported.insert(path).second)
    std::fprintf(stderr, "warning: the kernel cache entry %s is not a regular file: not using the cache for it\n",
                 path.c_str());
  return false;
}

// The cached binary, or empty when missing or corrupt (a corrupt file is removed)
std::vector<unsigned char> read_entry(const std::string& path) {
  if (!usable_entry_path(path)) return {};
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  std::vector<unsigned char> data((std::istreambuf_iterator<char>(in)), {});
  const size_t header = sizeof kMagic + 8;
  bool ok = data.size() > header && std::memcmp(data.data(), kMagic, sizeof kMagic) == 0;
  if (ok) {
    uint64_t stored;
    std::memcpy(&stored, data.data() + sizeof kMagic, 8);
    std::string_view payload(reinterpret_cast<const char*>(data.data() + header), data.size() - header);
    ok = stored == fnv1a64(payload);
  }
  if (!ok) {
    std::error_code ec;
    fs::remove(path, ec);
    return {};
  }
  return std::vector<unsigned char>(data.begin() + header, data.end());
}

void write_entry(const std::string& path, const std::vector<unsigned char>& binary) {
  if (!usable_entry_path(path)) return;
  std::error_code ec;
  fs::create_directories(fs::path(path).parent_path(), ec);
  // Unique per process, thread and call: workers of several devices may write at once
  static std::atomic<uint64_t> counter{0};
  std::string tmp = path + ".tmp" + std::to_string(::getpid()) + "-" +
                    std::to_string(std::hash<std::thread::id>()(std::this_thread::get_id())) + "-" +
                    std::to_string(counter++);
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) return;  // an unwritable cache is not an error
    uint64_t h = fnv1a64(std::string_view(reinterpret_cast<const char*>(binary.data()), binary.size()));
    out.write(kMagic, sizeof kMagic);
    out.write(reinterpret_cast<const char*>(&h), 8);
    out.write(reinterpret_cast<const char*>(binary.data()), binary.size());
    if (!out) {
      fs::remove(tmp, ec);
      return;
    }
  }
  fs::rename(tmp, path, ec);
  if (ec) fs::remove(tmp, ec);
}

bool try_build_from_binary(const cl::Context& context, const DeviceEntry& device,
                           const std::vector<unsigned char>& binary, const std::string& options, cl::Program* out) {
  try {
    cl::Program::Binaries bins{binary};
    std::vector<cl_int> status;
    cl::Program program(context, {device.device}, bins, &status);
    if (status.empty() || status[0] != CL_SUCCESS) return false;
    program.build({device.device}, options.c_str());
    *out = program;
    return true;
  } catch (const cl::Error&) {
    return false;
  }
}

}  // namespace

std::vector<unsigned char> read_cache_entry(const std::string& path) { return read_entry(path); }

void write_cache_entry(const std::string& path, const std::vector<unsigned char>& data) { write_entry(path, data); }

std::string kernel_cache_dir() {
  if (const char* dir = std::getenv("CANDELA_CACHE_DIR")) return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::string(xdg) + "/candela/kernels";
  if (const char* home = std::getenv("HOME"); home && *home) return std::string(home) + "/.cache/candela/kernels";
  return "";
}

std::string program_cache_file(const DeviceEntry& device, const std::string& source, const std::string& options) {
  std::string dir = kernel_cache_dir();
  return dir.empty() ? "" : dir + "/" + cache_key(device, source, options) + ".bin";
}

LazyProgram::LazyProgram(cl::Context context, DeviceEntry device, std::string source, std::string options,
                         std::function<void()> before_compile)
    : context_(std::move(context)),
      device_(std::move(device)),
      source_(std::move(source)),
      options_(std::move(options)),
      cache_file_(program_cache_file(device_, source_, options_)),
      before_compile_(std::move(before_compile)) {}

LazyProgram::LazyProgram(cl::Program built, std::string cache_file)
    : cache_file_(std::move(cache_file)), built_(true), program_(std::move(built)) {}

const cl::Program& LazyProgram::get() {
  if (!built_) {
    program_ = build_program(context_, device_, source_, options_, before_compile_, /*use_cache=*/false).program;
    built_ = true;
  }
  return program_;
}

ProgramBuild build_program(const cl::Context& context, const DeviceEntry& device, const std::string& source,
                           const std::string& options, const std::function<void()>& before_compile, bool use_cache) {
  auto start = std::chrono::steady_clock::now();
  ProgramBuild result;
  if (use_cache) result.cache_file = program_cache_file(device, source, options);

  if (!result.cache_file.empty()) {
    std::vector<unsigned char> binary = read_entry(result.cache_file);
    if (!binary.empty() && try_build_from_binary(context, device, binary, options, &result.program)) {
      result.from_cache = true;
    } else if (!binary.empty()) {
      std::error_code ec;
      fs::remove(result.cache_file, ec);  // the driver rejected it: rebuild from source
    }
  }

  if (!result.from_cache) {
    if (before_compile) before_compile();
    cl::Program program(context, source);
    try {
      program.build({device.device}, options.c_str());
    } catch (const cl::Error& e) {
      std::string log;
      try {
        log = program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device.device);
      } catch (const cl::Error&) {
      }
      throw Error("OpenCL kernel build failed on " + device.description() + " (" + cl_error_name(e.err()) +
                  "), build log:\n" + log);
    }
    result.program = program;
    if (!result.cache_file.empty()) {
      try {
        auto binaries = program.getInfo<CL_PROGRAM_BINARIES>();
        if (binaries.size() == 1 && !binaries[0].empty()) write_entry(result.cache_file, binaries[0]);
      } catch (const cl::Error&) {
      }
    }
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

cl::Buffer cached_device_table(const cl::Context& context, const std::string& path, size_t count, float lo, float hi,
                               const std::string& what, const std::function<std::vector<float>(cl::Buffer*)>& compute,
                               bool* from_cache) {
  const size_t bytes = count * sizeof(float);
  auto in_range = [&](const std::vector<float>& values) {
    for (float v : values)
      if (!(v >= lo && v <= hi)) return false;
    return true;
  };
  std::vector<unsigned char> cached = path.empty() ? std::vector<unsigned char>() : read_cache_entry(path);
  std::vector<float> values(cached.size() == bytes ? count : 0);
  if (!values.empty()) std::memcpy(values.data(), cached.data(), bytes);
  *from_cache = !values.empty() && in_range(values);  // the entry's checksum is read_cache_entry's
  if (*from_cache) return cl::Buffer(context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes, values.data());
  cl::Buffer buffer;
  values = compute(&buffer);
  if (values.size() != count || !in_range(values))
    throw Error("the device computed " + what + " outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  if (!path.empty()) {
    std::vector<unsigned char> data(bytes);
    std::memcpy(data.data(), values.data(), bytes);
    write_cache_entry(path, data);
  }
  return buffer;
}

}  // namespace candela
