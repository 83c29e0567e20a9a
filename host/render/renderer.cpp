// Rendering a compiled scene on devices (renderer.hpp): the device workers and the sample scheduler.
#include "render/renderer.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <thread>

#include "base/error.hpp"
#include "base/uninit_vector.hpp"
#include "device/energy.hpp"
#include "device/kernel_sources.hpp"
#include "device/program_cache.hpp"
#include "device/tables_program.hpp"
#include "render/adaptive.hpp"

namespace candela {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::string format_mib(uint64_t bytes) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f MiB", bytes / 1048576.0);
  return buf;
}

void check_buffer_size(const DeviceEntry& device, size_t bytes, const char* what) {
  if (bytes > device.max_alloc)
    throw Error(std::string("the scene's ") + what + " need " + format_mib(bytes) + " in one buffer, more than " +
                device.description() + " allows (" + format_mib(device.max_alloc) + ")");
}

// A read-only buffer holding `data`, or one dummy element when it is empty
template <typename T, typename A>
cl::Buffer upload(const cl::Context& ctx, const DeviceEntry& device, const std::vector<T, A>& data, const char* what) {
  std::vector<T, A> one(1, T{});
  const std::vector<T, A>& src = data.empty() ? one : data;
  size_t bytes = src.size() * sizeof(T);
  check_buffer_size(device, bytes, what);
  try {
    return cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes, const_cast<T*>(src.data()));
  } catch (const cl::Error& e) {
    throw Error(cl_error_message(std::string("uploading ") + what, e.err()));
  }
}

// A read-only buffer over the memory of `held` itself (CL_MEM_USE_HOST_PTR), which the
// caller keeps alive as long as the buffer: for a CPU device, which reads host memory, where
// a copy would cost the time and the memory of the array once more (its size checked
// already: adoptable)
template <typename T, typename A>
cl::Buffer adopt(const cl::Context& ctx, std::vector<T, A>& held, const char* what) {
  try {
    return cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR, held.size() * sizeof(T), held.data());
  } catch (const cl::Error& e) {
    throw Error(cl_error_message(std::string("uploading ") + what, e.err()));
  }
}

// Whether a scene's arrays may become the device's buffers in place (adopt): a CPU device
// that shares the host's memory, with an alignment the arrays meet
bool adopts_host_arrays(const DeviceEntry& device) {
  try {
    return (device.device.getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_CPU) &&
           device.device.getInfo<CL_DEVICE_HOST_UNIFIED_MEMORY>() &&
           device.device.getInfo<CL_DEVICE_MEM_BASE_ADDR_ALIGN>() / 8 <= kHostArrayAlignment;
  } catch (const cl::Error&) {
    return false;
  }
}

// Whether `v` may become a buffer in place (adopt): an UninitVector, whose allocator aligns
// it as adopts_host_arrays asks, not empty and within the device's largest buffer (else an
// Error, before anything is moved)
template <typename T, typename A>
bool adoptable(const DeviceEntry&, const std::vector<T, A>&, const char*) {
  return false;
}
template <typename T>
bool adoptable(const DeviceEntry& device, const UninitVector<T>& v, const char* what) {
  if (v.empty() || reinterpret_cast<uintptr_t>(v.data()) % kHostArrayAlignment != 0) return false;
  check_buffer_size(device, v.size() * sizeof(T), what);
  return true;
}

void check_device(const DeviceEntry& device) {
  if (device.opencl_c_version.rfind("OpenCL C 1.0", 0) == 0 || device.opencl_c_version.rfind("OpenCL C 1.1", 0) == 0)
    throw Error(device.description() + " supports only " + device.opencl_c_version + "; candela needs OpenCL C 1.2");
}

void check_settings(const DeviceEntry& device, const RenderSettings& settings) {
  if (settings.width <= 0 || settings.height <= 0 || settings.width > 65536 || settings.height > 65536 ||
      uint64_t(settings.width) * settings.height > (uint64_t(1) << 28))
    throw Error("image size must be between 1x1 and 65536x65536 with at most 2^28 pixels");
  check_device(device);
}

// A kernel cache that the prebuilds can write and the renderers read back
bool writable_cache() {
  std::string dir = kernel_cache_dir();
  std::error_code ec;
  return !dir.empty() && (std::filesystem::create_directories(dir, ec), ::access(dir.c_str(), W_OK) == 0);
}

}  // namespace

bool render_packets(const DeviceEntry& device, const RenderSettings& settings) {
  return settings.packets && settings.motion_steps == 0 &&
         (device.device.getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_CPU) != 0;
}

std::string render_kernel_options(const SceneFeatures& features, const RenderSettings& settings,
                                  const DeviceEntry& device) {
  std::string options = "-cl-std=CL1.2 " + features.build_options();
  options += settings.sampler == Sampler::Sobol ? " -DCD_SAMPLER_SOBOL=1" : " -DCD_SAMPLER_SOBOL=0";
  if (render_packets(device, settings)) options += " -DCD_PACKETS=1";
  if (settings.aov || settings.transparent) options += " -DCD_AOV=1";
  if (settings.transparent) options += " -DCD_TRANSPARENT=1";
  if (settings.noise_threshold > 0.0) options += " -DCD_ADAPTIVE=1";
  if (settings.motion_steps > 0) options += " -DCD_MOTION_STEPS=" + std::to_string(settings.motion_steps);
  return options;
}

void KernelPrebuild::start(const DeviceEntry& device, const SceneFeatures& features, const RenderSettings& settings) {
  results_.push_back(std::make_unique<Result>());
  try {
    check_settings(device, settings);
  } catch (const Error&) {
    return;  // the renderer reports it
  }
  // Only into a cache the renderer can read back (else the program would be built twice),
  // and only what is not there yet
  if (!writable_cache()) return;
  std::string options = render_kernel_options(features, settings, device);
  std::string entry = program_cache_file(device, renderer_program_source(), options);
  if (!claim(entry)) return;
  std::function<void(const std::string&)> note = settings.before_kernel_compile;
  Result* result = results_.back().get();
  try {
    threads_.emplace_back([device, options, note, result] {
      try {
        cl::Context context(device.device);
        ProgramBuild build = build_program(context, device, renderer_program_source(), options, [&] {
          if (note) note(device.description());
        });
        result->seconds = build.seconds;
        result->built = !build.from_cache;
      } catch (...) {  // the renderer's own build reports it
      }
    });
  } catch (const std::system_error&) {  // no thread: the renderer builds it
  }
}

void KernelPrebuild::start_tables(const DeviceEntry& device, const RenderSettings& settings) {
  if (!settings.energy_compensation) return;
  try {
    check_device(device);
  } catch (const Error&) {
    return;  // the renderer reports it
  }
  if (!writable_cache()) return;
  std::string entry;
  try {
    entry = common_tables_cache_file(device);  // the sources read (--kernel-dir) may fail
  } catch (const Error&) {
    return;  // the renderer reports it
  }
  if (!claim(entry)) return;
  try {
    threads_.emplace_back([this, device] {
      std::unique_lock<std::mutex> lock(mutex_);
      auto delay = std::chrono::duration<double>(kTablesAfterLoading);
      if (loaded_signal_.wait_for(lock, delay, [this] { return loaded_; })) return;
      lock.unlock();
      try {
        compute_common_tables(device);
      } catch (...) {  // the renderer computes them, and reports what fails
      }
    });
  } catch (const std::system_error&) {  // no thread: the renderer computes them
  }
}

bool KernelPrebuild::claim(const std::string& entry) {
  std::error_code ec;
  if (std::filesystem::exists(entry, ec) || ec) return false;
  if (std::find(started_.begin(), started_.end(), entry) != started_.end()) return false;
  started_.push_back(entry);
  return true;
}

void KernelPrebuild::loaded() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    loaded_ = true;
  }
  loaded_signal_.notify_all();
}

void KernelPrebuild::wait() {
  for (std::thread& t : threads_) t.join();
  threads_.clear();
}

template <typename V>
void DeviceRenderer::add_scene_buffer(const V& data, V* released, bool adopts, const char* what) {
  if (released && adopts && adoptable(device_, *released, what)) {
    auto held = std::make_shared<V>(std::move(*released));
    host_arrays_.push_back(held);
    scene_buffers_.push_back(adopt(context_, *held, what));
    return;
  }
  scene_buffers_.push_back(upload(context_, device_, data, what));
  if (released) V().swap(*released);
}

DeviceRenderer::DeviceRenderer(const DeviceEntry& device, const CompiledScene& scene, const dev::Camera& camera,
                               const RenderSettings& settings, CompiledScene* release)
    : device_(device), settings_(settings) {
  check_settings(device, settings);
  try {
    context_ = cl::Context(device_.device);
    queue_ = cl::CommandQueue(context_, device_.device);
  } catch (const cl::Error& e) {
    throw Error(cl_error_message("creating a context on " + device_.description(), e.err()));
  }
  ProgramBuild build = build_program(context_, device_, renderer_program_source(),
                                     render_kernel_options(scene.features, settings, device_), [&] {
                                       if (settings.before_kernel_compile)
                                         settings.before_kernel_compile(device_.description());
                                     });
  kernel_build_seconds_ = build.seconds;
  kernel_from_cache_ = build.from_cache;
  kernel_ = cl::Kernel(build.program, "render_paths");
  const bool aov = settings.aov || settings.transparent;
  const bool adaptive = settings.noise_threshold > 0.0;
  // + params and the film's two buffers, the AOVs' one, the active pixels and the half film
  const unsigned want_args = dev::kSceneBufferCount + 3 + (aov ? 1 : 0) + (adaptive ? 2 : 0);
  if (kernel_.getInfo<CL_KERNEL_NUM_ARGS>() != want_args)
    throw Error("render_paths takes " + std::to_string(kernel_.getInfo<CL_KERNEL_NUM_ARGS>()) +
                " arguments, but the host binds " + std::to_string(want_args) +
                " (CD_SCENE_BUFFERS out of step with the kernel)");
  // Work-groups of 64 launch indices (with packets, 8 work-items of 8)
  pixels_per_item_ = render_packets(device_, settings) ? 8 : 1;
  local_size_ =
      std::min<size_t>(64 / pixels_per_item_, kernel_.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(device_.device));
  group_pixels_ = local_size_ * pixels_per_item_;

  const AnisotropicAlbedo anisotropic = anisotropic_albedo(scene.features.anisotropy, scene.buffers.materials);
  // On a CPU device, the UninitVector arrays (the BVH's) that the scene releases become the
  // buffers in place (kept in host_arrays_); the others are copied, and released one by one
  const bool adopts = release && adopts_host_arrays(device_);
  host_arrays_.reserve(dev::kSceneBufferCount);
#define CD_UPLOAD(type, name)                                                                                          \
  add_scene_buffer(scene.buffers.name, (release && std::string(#name) != "lights") ? &release->buffers.name : nullptr, \
                   adopts, #name);
  CD_SCENE_BUFFERS(CD_UPLOAD)
#undef CD_UPLOAD
  DeviceTables tables =
      device_tables(context_, queue_, device_, settings.energy_compensation, anisotropic, scene.features.sheen, [&] {
        if (settings.before_tables_compute) settings.before_tables_compute(device_.description());
      });
  if (settings.energy_compensation) scene_buffers_[unsigned(dev::SceneBuffer::ggx_albedo)] = tables.ggx_albedo;
  if (scene.features.sheen) scene_buffers_[unsigned(dev::SceneBuffer::sheen_albedo)] = tables.sheen_albedo;

  params_host_.camera = camera;
  params_host_.width = uint32_t(settings.width);
  params_host_.height = uint32_t(settings.height);
#define CD_SET_KERNEL_SETTING(type, name, default_value) params_host_.name = uint32_t(settings.name);
  CD_KERNEL_SETTINGS(CD_SET_KERNEL_SETTING)
#undef CD_SET_KERNEL_SETTING
  params_host_.num_lights = uint32_t(scene.buffers.lights.size());  // kept by release
  params_host_.environment_light = scene.environment_light;

  size_t pixels = size_t(settings.width) * settings.height;
  launches_ = pixels;
  chunk_ = std::min(pixels, std::max<size_t>(group_pixels_, 4096));
  try {
    params_ = cl::Buffer(context_, CL_MEM_READ_ONLY, sizeof(dev::RenderParams));
    cl_uint arg = 0;
    for (const cl::Buffer& b : scene_buffers_) kernel_.setArg(arg++, b);
    kernel_.setArg(arg, params_);
  } catch (const cl::Error& e) {
    throw Error(cl_error_message("allocating the render parameters", e.err()));
  }
  allocate_film(pixels);
}

// The film's buffers for `pixels` pixels (cleared) bound as the kernel's last arguments
void DeviceRenderer::allocate_film(size_t pixels) {
  const bool aov = settings_.aov || settings_.transparent;
  size_t film_bytes = pixels * 4 * sizeof(float);
  try {
    film_mean_ = cl::Buffer(context_, CL_MEM_READ_WRITE, film_bytes);
    film_m2_ = cl::Buffer(context_, CL_MEM_READ_WRITE, film_bytes);
    queue_.enqueueFillBuffer(film_mean_, 0.0f, 0, film_bytes);
    queue_.enqueueFillBuffer(film_m2_, 0.0f, 0, film_bytes);
    cl_uint arg = dev::kSceneBufferCount + 1;
    for (const cl::Buffer* b : {&film_mean_, &film_m2_}) kernel_.setArg(arg++, *b);
    if (aov) {
      film_aov_ = cl::Buffer(context_, CL_MEM_READ_WRITE, 2 * film_bytes);
      queue_.enqueueFillBuffer(film_aov_, 0.0f, 0, 2 * film_bytes);
      kernel_.setArg(arg++, film_aov_);
    }
    if (settings_.noise_threshold > 0.0) {  // adaptive: the active pixels and the half film
      std::vector<uint32_t> order = launch_order(settings_.width, settings_.height);
      active_ = cl::Buffer(context_, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, pixels * sizeof(uint32_t), order.data());
      film_half_ = cl::Buffer(context_, CL_MEM_READ_WRITE, film_bytes);
      queue_.enqueueFillBuffer(film_half_, 0.0f, 0, film_bytes);
      kernel_.setArg(arg++, active_);
      kernel_.setArg(arg++, film_half_);
    }
    queue_.finish();
  } catch (const cl::Error& e) {
    throw Error(cl_error_message("allocating the film", e.err()));
  }
  film_pixels_ = pixels;
}

void DeviceRenderer::set_view(const dev::Camera& camera, int width, int height) {
  size_t pixels = size_t(width) * height;
  // The first launch: about launch_seconds at the cost per pixel measured before, if any
  size_t first = 4096;
  size_t before = size_t(params_host_.width) * params_host_.height;
  if (pass_seconds_ > 0.0 && before > 0)
    first = size_t(settings_.launch_seconds / std::max(pass_seconds_ / double(before), 1e-12));
  first = (first + group_pixels_ - 1) / group_pixels_ * group_pixels_;
  settings_.width = width;
  settings_.height = height;
  params_host_.camera = camera;
  params_host_.width = uint32_t(width);
  params_host_.height = uint32_t(height);
  chunk_ = std::clamp(first, std::min(group_pixels_, pixels), pixels);
  batch_ = 1;
  pass_seconds_ = 0.0;
  if (pixels > film_pixels_) return allocate_film(pixels);
  size_t bytes = pixels * 4 * sizeof(float);
  try {
    queue_.enqueueFillBuffer(film_mean_, 0.0f, 0, bytes);
    queue_.enqueueFillBuffer(film_m2_, 0.0f, 0, bytes);
    if (settings_.aov || settings_.transparent) queue_.enqueueFillBuffer(film_aov_, 0.0f, 0, 2 * bytes);
    queue_.finish();
  } catch (const cl::Error& e) {
    throw Error(cl_error_message("clearing the film", e.err()));
  }
}

void DeviceRenderer::set_kernel_settings(const RenderSettings& settings) {
#define CD_SET_KERNEL_SETTING(type, name, default_value) \
  settings_.name = settings.name;                        \
  params_host_.name = uint32_t(settings.name);
  CD_KERNEL_SETTINGS(CD_SET_KERNEL_SETTING)
#undef CD_SET_KERNEL_SETTING
}

DeviceRenderer::~DeviceRenderer() {
  if (host_arrays_.empty()) return;
  try {
    queue_.finish();
  } catch (const cl::Error&) {  // a lost device: nothing left to wait for
  }
}

void DeviceRenderer::launch(uint32_t sample_begin, uint32_t count, size_t pixel_begin, size_t pixel_end) {
  params_host_.sample_begin = sample_begin;
  params_host_.sample_count = count;
  params_host_.pixel_begin = uint32_t(pixel_begin);
  params_host_.pixel_end = uint32_t(pixel_end);
  try {
    queue_.enqueueWriteBuffer(params_, CL_TRUE, 0, sizeof params_host_, &params_host_);
    // Work-groups of local_size_ work-items, each taking pixels_per_item_ launch indices;
    // the kernel skips the padding at the end
    size_t items = (pixel_end - pixel_begin + pixels_per_item_ - 1) / pixels_per_item_;
    size_t global = (items + local_size_ - 1) / local_size_ * local_size_;
    queue_.enqueueNDRangeKernel(kernel_, cl::NullRange, cl::NDRange(global), cl::NDRange(local_size_));
    queue_.finish();
  } catch (const cl::Error& e) {
    throw Error(cl_error_message("running the path tracing kernel", e.err()));
  }
}

bool DeviceRenderer::render_range(uint32_t sample_begin, uint32_t count, const std::function<bool()>& stop,
                                  const std::function<void(double)>& progress) {
  const size_t pixels = launches_;
  if (pixels == 0) return true;
  double seconds = 0.0;
  for (size_t begin = 0, end = 0; begin < pixels; begin = end) {
    if (begin > 0 && stop && stop()) return false;
    end = std::min(pixels, begin + chunk_);
    auto t0 = Clock::now();
    launch(sample_begin, count, begin, end);
    double dt = seconds_since(t0);
    seconds += dt;
    // Next launch: about launch_seconds of pixels at the measured cost
    double cost = dt / (double(end - begin) * count);
    size_t want = size_t(settings_.launch_seconds / std::max(cost * count, 1e-12));
    size_t most = pixels;
    if (settings_.launch_growth > 0.0) most = std::min(pixels, size_t(double(end - begin) * settings_.launch_growth));
    chunk_ = std::clamp((want + group_pixels_ - 1) / group_pixels_ * group_pixels_, std::min(group_pixels_, pixels),
                        std::max(most, std::min(group_pixels_, pixels)));
    if (end < pixels && progress) progress(double(end) / double(pixels));
  }
  // Next range: whole-image launches of several samples once one sample is cheap enough
  pass_seconds_ = seconds / count;
  double want = settings_.launch_seconds / std::max(pass_seconds_, 1e-12);
  batch_ = uint32_t(std::clamp(want, 1.0, std::min(2.0 * count, 4096.0)));
  if (want >= 1.0) chunk_ = pixels;
  return true;
}

uint32_t DeviceRenderer::suggested_batch(double seconds_left) const {
  if (pass_seconds_ <= 0.0) return batch_;
  return uint32_t(std::clamp(seconds_left / pass_seconds_, 1.0, double(batch_)));
}

void DeviceRenderer::set_active(const std::vector<uint32_t>& active) {
  if (!active_()) throw Error("set_active needs a renderer with noise_threshold");
  try {
    if (!active.empty())
      queue_.enqueueWriteBuffer(active_, CL_TRUE, 0, active.size() * sizeof(uint32_t), active.data());
  } catch (const cl::Error& e) {
    throw Error(cl_error_message("writing the active pixels", e.err()));
  }
  launches_ = active.size();
  chunk_ = std::min(chunk_, std::max<size_t>(launches_, 1));
}

std::vector<float> DeviceRenderer::half_film() {
  std::vector<float> out(size_t(settings_.width) * settings_.height * 4);
  try {
    queue_.enqueueReadBuffer(film_half_, CL_TRUE, 0, out.size() * sizeof(float), out.data());
  } catch (const cl::Error& e) {
    throw Error(cl_error_message("reading back the film", e.err()));
  }
  return out;
}

Film DeviceRenderer::film() {
  Film film(settings_.width, settings_.height);
  try {
    queue_.enqueueReadBuffer(film_mean_, CL_TRUE, 0, film.mean.size() * sizeof(float), film.mean.data());
    queue_.enqueueReadBuffer(film_m2_, CL_TRUE, 0, film.m2.size() * sizeof(float), film.m2.data());
    if (settings_.aov || settings_.transparent) {
      film.aov.resize(film.pixels() * 8);
      queue_.enqueueReadBuffer(film_aov_, CL_TRUE, 0, film.aov.size() * sizeof(float), film.aov.data());
    }
  } catch (const cl::Error& e) {
    throw Error(cl_error_message("reading back the film", e.err()));
  }
  return film;
}

namespace {

// Hands out disjoint ranges of sample indices to the workers and keeps the count of
// samples that every pixel has received
class SampleScheduler {
 public:
  // `indices_left`: sample indices left before the 32-bit index would wrap
  SampleScheduler(uint32_t spp, double time_limit, size_t workers, uint64_t indices_left)
      : limit_(spp > 0 ? spp : uint32_t(std::min<uint64_t>(kMaxSamplesPerPixel, indices_left))),
        time_limit_(spp > 0 ? 0.0 : time_limit),
        partial_(workers, 0.0),
        done_by_(workers, 0),
        start_(Clock::now()) {}

  // The next range (offsets from the render's first sample) for a worker that wants
  // `want` samples per pixel; false when the render is over
  bool take(DeviceRenderer* w, uint32_t* begin, uint32_t* count) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (ended_ || next_ >= limit_ || out_of_time()) return false;
    *begin = next_;
    *count = std::min(w->suggested_batch(time_limit_ > 0 ? time_limit_ - seconds() : 1e30), limit_ - next_);
    next_ += *count;
    return true;
  }

  // A time limit ends the render only once every pixel has a sample
  bool out_of_time() const { return time_limit_ > 0.0 && done_ > 0 && seconds() >= time_limit_; }
  bool out_of_time_locked() {
    std::lock_guard<std::mutex> lock(mutex_);
    return out_of_time();
  }

  void finish(size_t worker, uint32_t count, bool whole, bool interrupted) {
    std::lock_guard<std::mutex> lock(mutex_);
    partial_[worker] = 0.0;
    if (whole) done_ += count;
    if (whole) done_by_[worker] += count;
    if (!whole) partial_pass_ = ended_ = true;
    if (interrupted) interrupted_ = ended_ = true;
  }

  void report(size_t worker, double spp_partial, const std::function<void(const RenderProgress&)>& progress,
              uint32_t spp) {
    std::lock_guard<std::mutex> lock(mutex_);
    partial_[worker] = spp_partial;
    if (!progress) return;
    RenderProgress p;
    p.spp_done = done_;
    for (double v : partial_) p.spp_partial += v;
    p.worker_spp.resize(partial_.size());
    for (size_t i = 0; i < partial_.size(); ++i) p.worker_spp[i] = done_by_[i] + partial_[i];
    p.spp_target = spp;
    p.time_limit = time_limit_;
    p.seconds = seconds();
    progress(p);
  }

  double seconds() const { return seconds_since(start_); }
  uint32_t done() const { return done_; }
  uint32_t taken() const { return next_; }
  bool interrupted() const { return interrupted_; }
  bool partial_pass() const { return partial_pass_; }

 private:
  std::mutex mutex_;
  const uint32_t limit_;
  const double time_limit_;
  std::vector<double> partial_;
  std::vector<uint32_t> done_by_;  // whole ranges per worker, samples per pixel
  Clock::time_point start_;
  uint32_t next_ = 0, done_ = 0;
  bool ended_ = false, interrupted_ = false, partial_pass_ = false;
};

}  // namespace

RenderResult render_samples(const std::vector<DeviceRenderer*>& workers, uint32_t sample_begin, uint32_t spp,
                            double time_limit, const std::function<void(const RenderProgress&)>& progress,
                            const std::function<bool()>& stop) {
  if (workers.empty()) throw Error("render_samples needs a device");
  if (spp == 0 && !(time_limit > 0.0)) throw Error("render needs a sample count or a time limit");
  uint64_t indices_left = (uint64_t(1) << 32) - sample_begin;
  if (spp > indices_left) throw Error("the sample indices would pass 2^32: lower --sample-offset or --spp");
  SampleScheduler sched(spp, time_limit, workers.size(), indices_left);
  std::vector<std::exception_ptr> errors(workers.size());
  auto work = [&](size_t i) {
    try {
      DeviceRenderer* w = workers[i];
      uint32_t begin, count;
      while (sched.take(w, &begin, &count)) {
        bool stopped = false;
        auto should_stop = [&] { return (stopped = stop && stop()) || sched.out_of_time_locked(); };
        bool whole = w->render_range(sample_begin + begin, count, should_stop,
                                     [&](double f) { sched.report(i, f * count, progress, spp); });
        sched.finish(i, count, whole, stopped);
        sched.report(i, 0.0, progress, spp);
        if (stop && stop()) sched.finish(i, 0, true, true);
      }
    } catch (...) {
      errors[i] = std::current_exception();
      sched.finish(i, 0, true, true);
    }
  };
  if (workers.size() == 1) {
    work(0);
  } else {
    std::vector<std::thread> threads;
    for (size_t i = 0; i < workers.size(); ++i) threads.emplace_back(work, i);
    for (auto& t : threads) t.join();
  }
  for (auto& e : errors)
    if (e) std::rethrow_exception(e);

  RenderResult result;
  result.spp = sched.done();
  result.seconds = sched.seconds();
  result.interrupted = sched.interrupted();
  result.partial_pass = sched.partial_pass();
  result.samples_taken = sched.taken();
  // Each worker's share: the samples its film holds (partial ranges included)
  for (size_t i = 0; i < workers.size(); ++i) {
    Film f = workers[i]->film();
    double total = 0.0;
    for (size_t p = 0; p < f.pixels(); ++p) total += f.samples(p);
    result.worker_samples.push_back(uint64_t(total + 0.5));
    result.film = i == 0 ? std::move(f) : merge_films(result.film, f);
  }
  return result;
}

Renderer::Renderer(const DeviceEntry& device, std::shared_ptr<const CompiledScene> scene, const dev::Camera& camera,
                   const RenderSettings& settings)
    : Renderer(std::vector<DeviceEntry>{device}, std::move(scene), camera, settings) {}

Renderer::Renderer(const std::vector<DeviceEntry>& devices, std::shared_ptr<const CompiledScene> scene,
                   const dev::Camera& camera, const RenderSettings& settings)
    : scene_(std::move(scene)) {
  if (devices.empty()) throw Error("a render needs at least one device");
  for (const auto& d : devices) workers_.push_back(std::make_unique<DeviceRenderer>(d, *scene_, camera, settings));
}

Renderer::Renderer(const std::vector<DeviceEntry>& devices, std::shared_ptr<CompiledScene> scene,
                   const dev::Camera& camera, const RenderSettings& settings, bool release_host_arrays)
    : scene_(scene) {
  if (devices.empty()) throw Error("a render needs at least one device");
  for (size_t i = 0; i < devices.size(); ++i)
    workers_.push_back(std::make_unique<DeviceRenderer>(
        devices[i], *scene_, camera, settings, release_host_arrays && i + 1 == devices.size() ? scene.get() : nullptr));
  if (release_host_arrays) scene->release_host_arrays();
}

void Renderer::set_view(const dev::Camera& camera, int width, int height) {
  for (auto& w : workers_) w->set_view(camera, width, height);
}

void Renderer::set_kernel_settings(const RenderSettings& settings) {
  for (auto& w : workers_) w->set_kernel_settings(settings);
}

double Renderer::kernel_build_seconds() const {
  double s = 0.0;
  for (const auto& w : workers_) s += w->kernel_build_seconds();
  return s;
}

bool Renderer::kernel_from_cache() const {
  for (const auto& w : workers_)
    if (!w->kernel_from_cache()) return false;
  return true;
}

RenderResult Renderer::render(uint32_t sample_begin, uint32_t spp, double time_limit,
                              const std::function<void(const RenderProgress&)>& progress,
                              const std::function<bool()>& stop) {
  std::vector<DeviceRenderer*> workers;
  for (auto& w : workers_) workers.push_back(w.get());
  if (workers.front()->settings().noise_threshold > 0.0)
    return render_adaptive(workers, sample_begin, spp, time_limit, progress, stop);
  return render_samples(workers, sample_begin, spp, time_limit, progress, stop);
}

}  // namespace candela
