// The device-kernel fixture: the test devices, the test program on each (built once per
// device per test process), buffers from and back to std::vector, and test kernels run with
// their arguments bound in order.
#pragma once

#include <gtest/gtest.h>

#include <CL/opencl.hpp>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "base/device_types.hpp"
#include "compile/scene_compiler.hpp"
#include "device/device.hpp"

namespace candela::test {

// ---- Devices ----------------------------------------------------------------------------

// PoCL, the device every test runs on (a missing PoCL fails the test), or the device that
// CANDELA_TEST_DEVICE selects as --device does (scripts/gpu/check.sh runs the tests on a GPU)
DeviceEntry pocl_device();

// Mesa's rusticl device, if one is installed and enabled
std::optional<DeviceEntry> rusticl_device();

// Device by test-parameter name: "pocl" or "rusticl"; nullopt when absent
std::optional<DeviceEntry> device_by_name(const std::string& name);

// The device named `name`, or the test skipped when it is absent
#define CANDELA_DEVICE_OR_SKIP(name, out)                                         \
  do {                                                                            \
    auto candela_dev_ = ::candela::test::device_by_name(name);                    \
    if (!candela_dev_) GTEST_SKIP() << name << " OpenCL device is not available"; \
    out = *candela_dev_;                                                          \
  } while (0)

// The devices a test runs on, as a test parameter, and the parameter's test name (the
// device's): INSTANTIATE_TEST_SUITE_P(Devices, Suite, kernel_devices(), DeviceParamName());
inline auto kernel_devices() { return ::testing::Values(std::string("pocl"), std::string("rusticl")); }
struct DeviceParamName {
  std::string operator()(const ::testing::TestParamInfo<std::string>& info) const { return info.param; }
};

// ---- The test program on a device -------------------------------------------------------

struct KernelRig;

// The build options of the shared test program: OpenCL C 1.2, with the features whose code
// only their own tests need left out (CD_FEATURE_DISPERSION, CD_FEATURE_IRIDESCENCE and
// CD_FEATURE_ANISOTROPY's table: dispersion_test.cpp, iridescence_test.cpp and
// energy_test.cpp build their programs with them), so that rusticl's slow compile of it
// does not grow with them. Without CD_FEATURE_ANISOTROPY anisotropic lobes still render,
// compensated by the isotropic table.
inline const char* const kTestProgramOptions =
    "-cl-std=CL1.2 -DCD_FEATURE_DISPERSION=0 -DCD_FEATURE_IRIDESCENCE=0 -DCD_FEATURE_ANISOTROPY=0";
// The same with CD_FEATURE_ANISOTROPY (the kernel of a scene with an anisotropic material)
inline const char* const kAnisotropicTestProgramOptions =
    "-cl-std=CL1.2 -DCD_FEATURE_DISPERSION=0 -DCD_FEATURE_IRIDESCENCE=0 -DCD_FEATURE_ANISOTROPY=1";

// A write-only device buffer of `size` T that a kernel fills; read() copies it back
template <typename T>
struct Output {
  const KernelRig* rig;
  cl::Buffer buffer;
  size_t size;
  std::vector<T> read() const;
};

// Context, queue and the test program (real cl/ sources + the test kernels of tests/*/) on one device
struct KernelRig {
  DeviceEntry device;
  cl::Context context;
  cl::CommandQueue queue;
  cl::Program program;
  std::string program_cache_file;  // its entry in the kernel cache (ProgramBuild::cache_file)

  explicit KernelRig(const DeviceEntry& d);  // builds the test program (through the kernel cache)
  KernelRig(const DeviceEntry& d, const cl::Context& c, const cl::Program& p);  // a program built elsewhere

  // A read-only copy of `data` on the device (not empty)
  template <typename T, typename A>
  cl::Buffer input(const std::vector<T, A>& data) const {
    return cl::Buffer(context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, data.size() * sizeof(T),
                      const_cast<T*>(data.data()));
  }
  template <typename T>
  Output<T> output(size_t n) const {
    return {this, cl::Buffer(context, CL_MEM_WRITE_ONLY, n * sizeof(T)), n};
  }
  // The first n T of `buffer`, after every kernel enqueued before
  template <typename T>
  std::vector<T> read(const cl::Buffer& buffer, size_t n) const {
    std::vector<T> v(n);
    queue.enqueueReadBuffer(buffer, CL_TRUE, 0, n * sizeof(T), v.data());
    return v;
  }

  // Enqueues kernel `name` over `global_size` work-items with `args` bound in order: a
  // cl::Buffer or Output<T> is one buffer argument; a type with a member
  // `cl_uint bind(cl::Kernel&, cl_uint first) const` binds its own run of arguments and
  // returns the next index (SceneOnDevice; write one with bind_args); anything else is one
  // value argument (cl_uint, float, cl_float4, a struct...) of exactly its size
  template <typename... Args>
  void run(const char* name, size_t global_size, const Args&... args) const;
};

// The test program on the device called `name` ("pocl", "rusticl"), built on first use and
// kept for the rest of the process; throws if the device is absent
KernelRig& kernel_rig(const std::string& name);
// The same, or null when the device is absent
KernelRig* rig_or_null(const std::string& name);
// The test program built with kAnisotropicTestProgramOptions on PoCL (the context of
// kernel_rig("pocl")), built on first use and kept for the rest of the process
KernelRig& anisotropic_kernel_rig();

// `out` (a KernelRig&) on the device named `name`, or the test skipped when it is absent
#define CANDELA_RIG_OR_SKIP(name, out)                                              \
  ::candela::test::KernelRig* out##_or_null_ = ::candela::test::rig_or_null(name);  \
  if (!out##_or_null_) GTEST_SKIP() << (name) << " OpenCL device is not available"; \
  ::candela::test::KernelRig& out = *out##_or_null_

// Tests parameterized by a device name (instantiated with kernel_devices()): skipped when
// the device is absent, rig() its test program. A SetUp of a derived fixture calls this
// one first and returns if IsSkipped().
class DeviceTest : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override;
  KernelRig& rig() const { return *rig_; }

 private:
  KernelRig* rig_ = nullptr;
};

// ---- A compiled scene for test kernels ----------------------------------------------------

// A compiled scene uploaded for test kernels that take CD_SCENE_BUFFERS(CD_SCENE_PARAM)
// followed by a `__global const RenderParams*` (as render_paths does): as a kernel argument
// it binds all of those
struct SceneOnDevice {
  std::vector<cl::Buffer> buffers;  // CD_SCENE_BUFFERS order
  cl::Buffer params;
  dev::RenderParams params_host{};
  SceneOnDevice(const KernelRig& rig, const CompiledScene& scene);
  cl_uint bind(cl::Kernel& kernel, cl_uint first_arg) const;  // returns the next argument's index
};

// ---- Vectors to and from the device -------------------------------------------------------

inline cl_float4 f4(const glm::dvec3& v, double w = 0.0) { return {{float(v.x), float(v.y), float(v.z), float(w)}}; }
inline glm::dvec3 d3(const cl_float4& v) { return {v.s[0], v.s[1], v.s[2]}; }

// ---- Implementation ---------------------------------------------------------------------------

namespace detail {

template <typename T, typename = void>
struct BindsItself : std::false_type {};
template <typename T>
struct BindsItself<T, std::void_t<decltype(std::declval<const T&>().bind(std::declval<cl::Kernel&>(), cl_uint(0)))>>
    : std::true_type {};

template <typename T>
struct IsOutput : std::false_type {};
template <typename T>
struct IsOutput<Output<T>> : std::true_type {};

template <typename T>
cl_uint bind_arg(cl::Kernel& k, cl_uint index, const T& arg) {
  if constexpr (std::is_base_of_v<cl::Memory, T>) {
    k.setArg(index, arg);
    return index + 1;
  } else if constexpr (IsOutput<T>::value) {
    k.setArg(index, arg.buffer);
    return index + 1;
  } else if constexpr (BindsItself<T>::value) {
    return arg.bind(k, index);
  } else {
    static_assert(std::is_trivially_copyable_v<T>, "a kernel argument is a buffer or plain data");
    static_assert(!std::is_same_v<T, bool>, "OpenCL kernels take no bool: pass a cl_uint");
    static_assert(!std::is_same_v<T, double>, "kernels take float: pass float(x)");
    static_assert(!std::is_same_v<T, size_t> && !std::is_same_v<T, long> && !std::is_same_v<T, long long>,
                  "a 64-bit integer: pass cl_uint(n)");
    k.setArg(index, arg);
    return index + 1;
  }
}

}  // namespace detail

// Binds `args` as KernelRig::run does, from argument `first` on; returns the next index
template <typename... Args>
cl_uint bind_args(cl::Kernel& k, cl_uint first, const Args&... args) {
  cl_uint index = first;
  ((index = detail::bind_arg(k, index, args)), ...);
  return index;
}

template <typename T>
std::vector<T> Output<T>::read() const {
  return rig->template read<T>(buffer, size);
}

template <typename... Args>
void KernelRig::run(const char* name, size_t global_size, const Args&... args) const {
  cl::Kernel k(program, name);
  bind_args(k, 0, args...);
  queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(global_size));
}

}  // namespace candela::test
