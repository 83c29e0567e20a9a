#include "support/test_support.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include "base/error.hpp"
#include "device/energy.hpp"
#include "device/kernel_sources.hpp"
#include "device/program_cache.hpp"

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
  ProgramBuild build = build_program(context, device, test_program_source(), "-cl-std=CL1.2");
  program = build.program;
  program_cache_file = build.cache_file;
}

namespace {
template <typename T>
cl::Buffer upload_or_dummy(const cl::Context& ctx, const std::vector<T>& data) {
  std::vector<T> one(1);
  const std::vector<T>& src = data.empty() ? one : data;
  return cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, src.size() * sizeof(T), const_cast<T*>(src.data()));
}
}  // namespace

SceneOnDevice::SceneOnDevice(KernelRig& rig, const CompiledScene& scene) {
#define CD_TEST_UPLOAD(type, name) buffers.push_back(upload_or_dummy(rig.context, scene.buffers.name));
  CD_SCENE_BUFFERS(CD_TEST_UPLOAD)
#undef CD_TEST_UPLOAD
  buffers[unsigned(dev::SceneBuffer::ggx_albedo)] =
      ggx_albedo_table(rig.context, rig.queue, rig.program, rig.program_cache_file).buffer;
  params_host.num_lights = cl_uint(scene.buffers.lights.size());
  params_host.environment_light = scene.environment_light;
  params_host.energy_compensation = 1u;  // as renderers have it by default, with the table above
  params_host.width = params_host.height = 1;
  params = cl::Buffer(rig.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof params_host, &params_host);
}

cl_uint SceneOnDevice::bind(cl::Kernel& kernel, cl_uint first_arg) const {
  cl_uint arg = first_arg;
  for (const cl::Buffer& b : buffers) kernel.setArg(arg++, b);
  kernel.setArg(arg++, params);
  return arg;
}

Estimate region_mean(const Film& f, int c, int x0, int x1, int y0, int y1) {
  double sum = 0.0, var = 0.0;
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      size_t i = size_t(y) * f.width + x;
      sum += f.pixel(i)[c];
      var += f.variance_of_mean(i)[c];
      ++n;
    }
  return {sum / n, std::sqrt(var) / n};
}

Estimate sample_mean(const std::vector<cl_float4>& samples, int c) {
  double sum = 0.0, sum2 = 0.0;
  for (const cl_float4& x : samples) {
    sum += x.s[c];
    sum2 += double(x.s[c]) * x.s[c];
  }
  double n = double(samples.size());
  double mean = sum / n;
  return {mean, std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n)};
}

Estimate image_mean(const Film& f) {
  Estimate e;
  double var = 0.0;
  for (int c = 0; c < 3; ++c) {
    Estimate ec = region_mean(f, c, 0, f.width, 0, f.height);
    e.mean += ec.mean / 3.0;
    var += ec.standard_error * ec.standard_error / 9.0;  // channels as independent: conservative enough for a z-test
  }
  e.standard_error = std::sqrt(var);
  return e;
}

std::string scene_path(const std::string& relative) { return std::string(CANDELA_SOURCE_DIR) + "/scenes/" + relative; }

}  // namespace candela::test

namespace candela::test {

KernelRig& shared_rig(const std::string& name, const DeviceEntry& device) {
  static std::map<std::string, std::unique_ptr<KernelRig>> rigs;
  auto& r = rigs[name];
  if (!r) r = std::make_unique<KernelRig>(device);
  return *r;
}

Film render_film(const Scene& scene, Strategy strategy, int w, int h, uint32_t spp, uint32_t max_depth, uint32_t seed,
                 const DeviceEntry& device) {
  RenderSettings settings;
  settings.width = w;
  settings.height = h;
  settings.strategy = strategy;
  settings.max_depth = max_depth;
  settings.seed = seed;
  return render_result(scene, settings, spp, device).film;
}

RenderResult render_result(const Scene& scene, const RenderSettings& settings, uint32_t spp,
                           const DeviceEntry& device) {
  return scene_renderer(device, scene, settings).render(0, spp);
}

Film render_film(const Scene& scene, Strategy strategy, int w, int h, uint32_t spp, uint32_t max_depth, uint32_t seed) {
  return render_film(scene, strategy, w, h, spp, max_depth, seed, pocl_device());
}

dev::Camera scene_camera(const Scene& scene, const RenderSettings& settings) {
  return compile_camera(scene, settings.width, settings.height);
}

Renderer scene_renderer(const DeviceEntry& device, const Scene& scene, const RenderSettings& settings) {
  return Renderer(device, std::make_shared<const CompiledScene>(compile_scene(scene)), scene_camera(scene, settings),
                  settings);
}

const char* strategy_name(Strategy s) { return enum_name(kStrategyNames, s); }

}  // namespace candela::test
