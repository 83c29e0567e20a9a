// OpenCL program builds with an on-disk binary cache.
// Key: platform, device, driver version, build options, source hash and candela version.
// Directory: $CANDELA_CACHE_DIR, else $XDG_CACHE_HOME/candela/kernels, else
// ~/.cache/candela/kernels; CANDELA_CACHE_DIR="" disables the cache.
#pragma once

#include <CL/opencl.hpp>
#include <functional>
#include <string>
#include <vector>

#include "device/device.hpp"

namespace candela {

struct ProgramBuild {
  cl::Program program;
  double seconds = 0.0;
  bool from_cache = false;
  std::string cache_file;  // empty when the cache is disabled or not used
};

// Builds `source` with `options` for the device, through the cache. A corrupt or
// rejected cache entry falls back to a source build. A failed source build throws
// Error with the device's build log. `before_compile` (if set) is called just before a
// build from source (no usable cache entry): what a caller announces before a wait of
// seconds to minutes. `use_cache` false: the cache is neither read nor written (a program
// built from source is otherwise written to it, for which PoCL compiles every kernel of
// the program to give its binary).
ProgramBuild build_program(const cl::Context& context, const DeviceEntry& device, const std::string& source,
                           const std::string& options, const std::function<void()>& before_compile = {},
                           bool use_cache = true);

std::string kernel_cache_dir();

// A program built on first use: the path of its cache entry is known before (data cached
// beside it can be read without building it). It is built from source, and its binary is
// not cached: it computes data that the cache then keeps, and storing the binary would
// compile every one of its kernels.
class LazyProgram {
 public:
  // `before_compile`: as build_program's
  LazyProgram(cl::Context context, DeviceEntry device, std::string source, std::string options,
              std::function<void()> before_compile = {});
  // A program built already, whose cache entry is `cache_file` (empty: no cache)
  LazyProgram(cl::Program built, std::string cache_file);
  const std::string& cache_file() const { return cache_file_; }
  // Built, or loaded from the cache, on the first call
  const cl::Program& get();

 private:
  cl::Context context_;
  DeviceEntry device_;
  std::string source_, options_, cache_file_;
  std::function<void()> before_compile_;
  bool built_ = false;
  cl::Program program_;
};

// The cache entry build_program uses for `source` built with `options` on the device
// (empty: no cache)
std::string program_cache_file(const DeviceEntry& device, const std::string& source, const std::string& options);

// Other data kept in the cache beside a program (e.g. under ProgramBuild::cache_file plus a
// suffix), with the binaries' checks: the payload, or empty when missing or corrupt (a
// corrupt entry is removed); writing is atomic and an unwritable cache is not an error
std::vector<unsigned char> read_cache_entry(const std::string& path);
void write_cache_entry(const std::string& path, const std::vector<unsigned char>& data);

// A table of `count` floats computed on a device and kept in the cache entry `path` (empty:
// no cache). The entry is used when every value lies in [lo, hi] (NaN fails: a corrupt or
// crafted entry is recomputed); else `compute` fills the device buffer and returns the
// values, which must pass the same check (Error naming `what` otherwise) and are cached.
// *from_cache says which happened.
cl::Buffer cached_device_table(const cl::Context& context, const std::string& path, size_t count, float lo, float hi,
                               const std::string& what, const std::function<std::vector<float>(cl::Buffer*)>& compute,
                               bool* from_cache);

}  // namespace candela
