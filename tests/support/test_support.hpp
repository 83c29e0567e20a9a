// Shared helpers for kernel tests: devices, the test program, scene paths.
#pragma once

#include <CL/opencl.hpp>
#include <optional>
#include <string>
#include <vector>

#include "base/device_types.hpp"
#include "compile/camera.hpp"
#include "compile/scene_compiler.hpp"
#include "device/device.hpp"
#include "render/film.hpp"
#include "render/renderer.hpp"
#include "support/gltf_builder.hpp"

namespace candela::test {

// PoCL, the device every test runs on (a missing PoCL fails the test)
DeviceEntry pocl_device();

// Mesa's rusticl device, if one is installed and enabled
std::optional<DeviceEntry> rusticl_device();

// Device by test-parameter name: "pocl" or "rusticl"; skips the test when absent
#define CANDELA_DEVICE_OR_SKIP(name, out)                                         \
  do {                                                                            \
    auto candela_dev_ = ::candela::test::device_by_name(name);                    \
    if (!candela_dev_) GTEST_SKIP() << name << " OpenCL device is not available"; \
    out = *candela_dev_;                                                          \
  } while (0)
std::optional<DeviceEntry> device_by_name(const std::string& name);

// Context, queue and the test program (real cl/ sources + the test kernels of tests/*/) on one device
struct KernelRig {
  DeviceEntry device;
  cl::Context context;
  cl::CommandQueue queue;
  cl::Program program;
  std::string program_cache_file;  // its entry in the kernel cache (ProgramBuild::cache_file)
  explicit KernelRig(const DeviceEntry& d);
};

// The test program on the device called `name` ("pocl", "rusticl"), built on first use and
// kept for the rest of the process
KernelRig& shared_rig(const std::string& name, const DeviceEntry& device);

// A compiled scene uploaded for test kernels that take CD_SCENE_BUFFERS(CD_SCENE_PARAM)
// followed by a `__global const RenderParams*` (as render_paths does): bind() sets those
// arguments from `first_arg` on and returns the index of the next argument.
struct SceneOnDevice {
  std::vector<cl::Buffer> buffers;  // CD_SCENE_BUFFERS order
  cl::Buffer params;
  dev::RenderParams params_host{};
  SceneOnDevice(KernelRig& rig, const CompiledScene& scene);
  cl_uint bind(cl::Kernel& kernel, cl_uint first_arg) const;
};

// A mean over pixels with its standard error from the per-pixel sample variances
struct Estimate {
  double mean = 0.0;
  double standard_error = 0.0;
};
Estimate region_mean(const Film& f, int c, int x0, int x1, int y0, int y1);  // channel c
Estimate image_mean(const Film& f);                                          // all pixels, channels averaged
// The mean of component c of a kernel's samples, with its standard error
Estimate sample_mean(const std::vector<cl_float4>& samples, int c);

std::string scene_path(const std::string& relative);  // relative to scenes/

// The device camera of `scene` for a settings.width x settings.height image
dev::Camera scene_camera(const Scene& scene, const RenderSettings& settings);

// A Renderer of `scene`, compiled, through its camera, on `device`
Renderer scene_renderer(const DeviceEntry& device, const Scene& scene, const RenderSettings& settings);

// A render of `scene` with `settings`, `spp` samples per pixel (sample indices [0, spp))
RenderResult render_result(const Scene& scene, const RenderSettings& settings, uint32_t spp, const DeviceEntry& device);

// A w x h render of `scene` with `spp` samples per pixel (sample indices [0, spp)) on
// `device`; every other setting is RenderSettings' default
Film render_film(const Scene& scene, Strategy strategy, int w, int h, uint32_t spp, uint32_t max_depth, uint32_t seed,
                 const DeviceEntry& device);
Film render_film(const Scene& scene, Strategy strategy, int w, int h, uint32_t spp, uint32_t max_depth,
                 uint32_t seed);  // on PoCL

const char* strategy_name(Strategy s);  // "nee", "bsdf" or "auto", as the CLI spells them

}  // namespace candela::test
