#include "support/kernels.hpp"

#include <cstdlib>
#include <map>
#include <memory>

#include "base/error.hpp"
#include "device/energy.hpp"
#include "device/kernel_sources.hpp"
#include "device/program_cache.hpp"
#include "device/sheen_albedo.hpp"

namespace candela::test {

DeviceEntry pocl_device() {
  const char* other = std::getenv("CANDELA_TEST_DEVICE");
  return select_device(other && *other ? other : "pocl");
}

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
  // Without KHR_materials_dispersion and _iridescence: their tests build their own programs
  ProgramBuild build = build_program(context, device, test_program_source(), kTestProgramOptions);
  program = build.program;
  program_cache_file = build.cache_file;
}

KernelRig::KernelRig(const DeviceEntry& d, const cl::Context& c, const cl::Program& p)
    : device(d), context(c), queue(c, d.device), program(p) {}

KernelRig* rig_or_null(const std::string& name) {
  static std::map<std::string, std::unique_ptr<KernelRig>> rigs;
  auto& r = rigs[name];
  if (!r) {
    std::optional<DeviceEntry> d = device_by_name(name);
    if (!d) return nullptr;
    r = std::make_unique<KernelRig>(*d);
  }
  return r.get();
}

KernelRig& kernel_rig(const std::string& name) {
  KernelRig* r = rig_or_null(name);
  if (!r) throw Error(name + " OpenCL device is not available");
  return *r;
}

KernelRig& anisotropic_kernel_rig() {
  static std::unique_ptr<KernelRig> rig;
  if (!rig) {
    KernelRig& shared = kernel_rig("pocl");
    ProgramBuild b =
        build_program(shared.context, shared.device, test_program_source(), kAnisotropicTestProgramOptions);
    rig = std::make_unique<KernelRig>(shared.device, shared.context, b.program);
    rig->program_cache_file = b.cache_file;
  }
  return *rig;
}

void DeviceTest::SetUp() {
  rig_ = rig_or_null(GetParam());
  if (!rig_) GTEST_SKIP() << GetParam() << " OpenCL device is not available";
}

namespace {
template <typename T, typename A>
cl::Buffer upload_or_dummy(const cl::Context& ctx, const std::vector<T, A>& data) {
  std::vector<T, A> one(1, T{});
  const std::vector<T, A>& src = data.empty() ? one : data;
  return cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, src.size() * sizeof(T), const_cast<T*>(src.data()));
}
}  // namespace

SceneOnDevice::SceneOnDevice(const KernelRig& rig, const CompiledScene& scene) {
#define CD_TEST_UPLOAD(type, name) buffers.push_back(upload_or_dummy(rig.context, scene.buffers.name));
  CD_SCENE_BUFFERS(CD_TEST_UPLOAD)
#undef CD_TEST_UPLOAD
  buffers[unsigned(dev::SceneBuffer::ggx_albedo)] =
      ggx_albedo_table(rig.context, rig.queue, rig.program, rig.program_cache_file).buffer;
  buffers[unsigned(dev::SceneBuffer::sheen_albedo)] =
      sheen_albedo_table(rig.context, rig.queue, rig.program, rig.program_cache_file).buffer;
  params_host.num_lights = cl_uint(scene.buffers.lights.size());
  params_host.environment_light = scene.environment_light;
  params_host.energy_compensation = 1u;  // as renderers have it by default, with the table above
  params_host.width = params_host.height = 1;
  params = cl::Buffer(rig.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof params_host, &params_host);
}

cl_uint SceneOnDevice::bind(cl::Kernel& kernel, cl_uint first_arg) const {
  cl_uint arg = first_arg;
  for (const cl::Buffer& b : buffers) arg = bind_args(kernel, arg, b);
  return bind_args(kernel, arg, params);
}

}  // namespace candela::test
