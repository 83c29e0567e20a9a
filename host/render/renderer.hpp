// Rendering a compiled scene through a device camera: a DeviceRenderer per device (context,
// queue, program, buffers, film) renders given ranges of sample indices; render_samples hands
// ranges out to one or more of them and merges their films. Renderer bundles the common
// case: one compiled scene on one device or several.
#pragma once

#include <CL/opencl.hpp>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "base/device_types.hpp"
#include "base/enum_names.hpp"
#include "compile/compiled_scene.hpp"
#include "device/device.hpp"
#include "render/film.hpp"

namespace candela {

enum class Strategy : uint32_t { Nee = STRATEGY_NEE, Bsdf = STRATEGY_BSDF, Auto = STRATEGY_AUTO };

// Pixel filter, importance-sampled by the kernel (cl/camera/filter.cl)
enum class PixelFilter : uint32_t { Box = FILTER_BOX, Tent = FILTER_TENT, Gaussian = FILTER_GAUSSIAN };

// Where the kernels' random numbers come from (cl/core/rng.cl): Owen-scrambled Sobol
// (stratified) or independent hashes; a build option of the kernel program
enum class Sampler : uint32_t { Sobol, Independent };

// Each enum's names (the CLI's options, --stats, the EXR metadata) and help notes
inline constexpr EnumName<Strategy> kStrategyNames[] = {
    {Strategy::Nee, "nee", "next-event estimation"},
    {Strategy::Bsdf, "bsdf", "BSDF sampling only"},
    {Strategy::Auto, "auto", "per vertex and light: whichever of the two has the lower variance; default"}};
inline constexpr EnumName<PixelFilter> kPixelFilterNames[] = {{PixelFilter::Box, "box", "default"},
                                                              {PixelFilter::Tent, "tent", "radius 1 pixel"},
                                                              {PixelFilter::Gaussian, "gaussian", "sigma 0.5 pixel"}};
inline constexpr EnumName<Sampler> kSamplerNames[] = {
    {Sampler::Sobol, "sobol", "Owen-scrambled Sobol, stratified; default"}, {Sampler::Independent, "independent", ""}};

// The film's per-pixel sample count is a float: exact up to 2^24
constexpr uint32_t kMaxSamplesPerPixel = 1u << 24;

// The settings the kernel reads as they are, one line each: X(type, name, default). Each is
// a RenderSettings member and the dev::RenderParams field of the same name (an unsigned int:
// an enum's value, a flag's 0 or 1), which DeviceRenderer sets from it. A command-line option
// sets them (host/app/settings.cpp). One entry per line, columns aligned:
// clang-format off
#define CD_KERNEL_SETTINGS(X)                               \
  X(uint32_t,    seed,                0)                    \
  X(uint32_t,    max_depth,           16) /* scattering events */ \
  X(uint32_t,    rr_depth,            3)  /* Russian roulette after this many bounces */ \
  X(Strategy,    strategy,            Strategy::Auto)       \
  X(bool,        energy_compensation, true) /* multiple scattering of GGX lobes (cl/bsdf/energy.cl) */ \
  X(PixelFilter, filter,              PixelFilter::Box)
// clang-format on

struct RenderSettings {
  int width = 512, height = 512;
#define CD_KERNEL_SETTING_MEMBER(type, name, default_value) type name = default_value;
  CD_KERNEL_SETTINGS(CD_KERNEL_SETTING_MEMBER)
#undef CD_KERNEL_SETTING_MEMBER
  Sampler sampler = Sampler::Sobol;  // a build option: CD_SAMPLER_SOBOL (render_kernel_options)
  // Build options (render_kernel_options): the AOVs beside the film (CD_AOV, Film::aov), and
  // the environment seen through see-through paths left out (CD_TRANSPARENT; needs aov)
  bool aov = false;
  bool transparent = false;
  // Adaptive sampling above 0 (render/adaptive.hpp): the estimated relative error at which
  // a pixel stops; a build option (CD_ADAPTIVE: the active-pixel list and the half film)
  double noise_threshold = 0.0;
  // Motion blur (CD_MOTION_STEPS): the poses across the shutter less one, 0 without blur; the
  // compiled scene then holds that many + 1 poses of its vertices and cameras
  uint32_t motion_steps = 0;
  double launch_seconds = 0.2;  // target duration of one launch
  // > 0: a launch covers at most this many times the pixels of the one before (the live
  // view: a cheap launch over the sky does not make the next one over the model long)
  double launch_growth = 0.0;
  // Camera rays in packets of eight on CPU devices (render_packets); false: one pixel per
  // work-item on every device (the same samples: tests compare the two kernels)
  bool packets = true;
  // Called with the device's description before its kernel is built from source (not in
  // the kernel cache): seconds on PoCL, minutes on rusticl
  std::function<void(const std::string&)> before_kernel_compile;
  // Called with the device's description before albedo tables not in the kernel cache are
  // computed on it (once per device: seconds on PoCL, minutes on rusticl)
  std::function<void(const std::string&)> before_tables_compute;
};

struct RenderProgress {
  uint32_t spp_done = 0;
  double spp_partial = 0.0;  // samples per pixel of the ranges under way
  uint32_t spp_target = 0;   // 0 when rendering for a time budget
  double seconds = 0.0;
  double time_limit = 0.0;
  std::vector<double> worker_spp;  // per worker: samples per pixel done and under way
};

struct RenderResult {
  Film film;
  uint32_t spp = 0;  // samples every pixel received
  double seconds = 0.0;
  bool interrupted = false;              // stopped by the caller
  bool partial_pass = false;             // stopped inside a range: some pixels hold more samples
  uint32_t samples_taken = 0;            // ranges handed out, from the first sample: no pixel holds an
                                         // index at or past sample_begin + samples_taken
  std::vector<uint64_t> worker_samples;  // per worker: samples it added, summed over pixels
};

// The render kernel program's build options for kernel features, settings and device
std::string render_kernel_options(const SceneFeatures& features, const RenderSettings& settings,
                                  const DeviceEntry& device);
// Whether render_paths traces camera rays in packets of eight on the device (CD_PACKETS):
// on CPU devices, where packets are what puts the traversal's tests in SIMD lanes, unless
// the settings turn them off or ask for motion blur
bool render_packets(const DeviceEntry& device, const RenderSettings& settings);

// Builds the render kernel program into the kernel cache on threads of their own, while
// the caller goes on (compiling the scene): a DeviceRenderer made after wait() finds the
// program there. Only programs not in the cache yet are built, each once (a device listed
// twice, or two alike, share a cache entry). Nothing is built without a writable kernel
// cache directory, or for a device the renderer would refuse; a failed build is left to
// the renderer's own, which reports it.
class KernelPrebuild {
 public:
  struct Result {
    bool built = false;  // this start built the program from source, successfully
    double seconds = 0.0;
  };
  KernelPrebuild() = default;
  KernelPrebuild(const KernelPrebuild&) = delete;
  KernelPrebuild& operator=(const KernelPrebuild&) = delete;
  ~KernelPrebuild() {
    loaded();
    wait();
  }
  void start(const DeviceEntry& device, const SceneFeatures& features, const RenderSettings& settings);
  // Computes the tables that every scene with energy compensation binds into the cache
  // (device/tables_program.hpp: common_tables_cache_file), unless there: work that needs no
  // scene, so it runs while a long load goes on. It starts once the load has lasted
  // kTablesAfterLoading; a scene loaded before that (loaded()) leaves them to the renderer,
  // after its kernel: PoCL compiles one program at a time, and the scene's comes first.
  // Once started it runs to its end (seconds), even when the load then fails. Adds no result().
  void start_tables(const DeviceEntry& device, const RenderSettings& settings);
  static constexpr double kTablesAfterLoading = 0.25;  // seconds
  // The scene is loaded: tables not started yet are left to the renderer
  void loaded();
  void wait();
  // The i-th start's build, once wait() returned
  const Result& result(size_t i) const { return *results_.at(i); }
  size_t size() const { return results_.size(); }

 private:
  std::vector<std::thread> threads_;
  std::vector<std::unique_ptr<Result>> results_;
  // Whether to start filling cache entry `entry`: not there yet, nor started; then started
  bool claim(const std::string& entry);
  std::vector<std::string> started_;  // cache entries being built or computed
  std::mutex mutex_;
  std::condition_variable loaded_signal_;
  bool loaded_ = false;
};

// One device's worker: renders ranges of sample indices of a compiled scene into its film
class DeviceRenderer {
 public:
  // Builds the kernel program for the scene's features, uploads the scene buffers and,
  // with energy compensation, the GGX albedo table (host/device/energy.hpp), and with a sheen
  // the sheen albedo table (host/device/sheen_albedo.hpp). `camera`:
  // the device record for settings.width x settings.height (compile/camera.hpp).
  // `release`: the same scene, whose host arrays are freed one by one once uploaded (for
  // the last device that uploads them; CompiledScene::release_host_arrays); a CPU device
  // takes the BVH's arrays over as its buffers instead of copying them
  DeviceRenderer(const DeviceEntry& device, const CompiledScene& scene, const dev::Camera& camera,
                 const RenderSettings& settings, CompiledScene* release = nullptr);
  // Waits for the device's work when buffers use host arrays that are about to be freed
  ~DeviceRenderer();
  DeviceRenderer(const DeviceRenderer&) = delete;
  DeviceRenderer& operator=(const DeviceRenderer&) = delete;

  // Adds sample indices [sample_begin, sample_begin + count) to every pixel, in launches
  // of about settings.launch_seconds over ranges of launch indices (8x8 tiles of pixels,
  // pixel_of_launch_index). `stop` is polled between launches; returns false when it stopped
  // the range part way (some tiles hold the range's samples, the others not). `progress` gets the fraction done.
  bool render_range(uint32_t sample_begin, uint32_t count, const std::function<bool()>& stop,
                    const std::function<void(double)>& progress);

  // Samples per pixel for the next range: about launch_seconds of work once measured,
  // and no more than fit in `seconds_left`
  uint32_t suggested_batch(double seconds_left) const;

  // Renders through `camera` at width x height from now on, the film cleared (the live
  // view: a preview size while the camera moves, the full one once it rests)
  void set_view(const dev::Camera& camera, int width, int height);
  // The kernel settings (CD_KERNEL_SETTINGS) from now on; set_view clears the film after
  void set_kernel_settings(const RenderSettings& settings);

  Film film();  // reads the film back from the device
  // With noise_threshold: the pixels that the next ranges render (launch index i renders
  // pixel active[i]; at first every pixel, in pixel_of_launch_index order), and per pixel
  // the (mean, squared deviations, count) of the odd-indexed samples' channel average
  void set_active(const std::vector<uint32_t>& active);
  std::vector<float> half_film();
  const RenderSettings& settings() const { return settings_; }
  // How many of the scene's buffers are host arrays taken over in place (adopt)
  size_t adopted_buffers() const { return host_arrays_.size(); }
  double kernel_build_seconds() const { return kernel_build_seconds_; }
  bool kernel_from_cache() const { return kernel_from_cache_; }
  // A KernelPrebuild built this worker's program from source and this worker loaded it
  // from the cache: that build counts as this worker's (its time added to the load's)
  void count_prebuild(const KernelPrebuild::Result& r) {
    if (!r.built || !kernel_from_cache_) return;
    kernel_build_seconds_ += r.seconds;
    kernel_from_cache_ = false;
  }
  const DeviceEntry& device() const { return device_; }

 private:
  void allocate_film(size_t pixels);
  void launch(uint32_t sample_begin, uint32_t count, size_t pixel_begin, size_t pixel_end);
  // Appends the buffer of one scene array (`data`); `released`: the same array when the
  // scene releases it (freed once copied, or taken over in place when `adopts` and it can be)
  template <typename V>
  void add_scene_buffer(const V& data, V* released, bool adopts, const char* what);

  DeviceEntry device_;
  RenderSettings settings_;
  // The memory of the buffers made over host arrays (declared before the OpenCL objects:
  // freed after them)
  std::vector<std::shared_ptr<void>> host_arrays_;
  cl::Context context_;
  cl::CommandQueue queue_;
  cl::Kernel kernel_;
  std::vector<cl::Buffer> scene_buffers_;  // CD_SCENE_BUFFERS order
  cl::Buffer params_, film_mean_, film_m2_, film_aov_, active_, film_half_;
  size_t launches_ = 0;  // launch indices of a range: every pixel, or the active ones
  dev::RenderParams params_host_{};
  size_t local_size_ = 1;
  size_t pixels_per_item_ = 1;  // 8 with packets (render_packets)
  size_t group_pixels_ = 1;     // launch indices per work-group: local_size_ x pixels_per_item_
  size_t chunk_ = 1;            // launch indices (pixels) per launch
  size_t film_pixels_ = 0;      // the film buffers' size
  uint32_t batch_ = 1;          // samples per pixel for the next range
  double pass_seconds_ = 0.0;   // one sample of every pixel, measured; 0 = not yet
  double kernel_build_seconds_ = 0.0;
  bool kernel_from_cache_ = false;
};

// Renders sample indices [sample_begin, sample_begin + spp) of every pixel, or for
// time_limit seconds when spp == 0, handing ranges out to the workers (one thread each)
// and merging their films by sample count. A time limit never ends the first range.
// `stop` is polled between launches; a stopped render keeps the samples already done.
// After a result with partial_pass, some pixels already hold sample indices from
// sample_begin + result.spp on: do not resume that film from there.
RenderResult render_samples(const std::vector<DeviceRenderer*>& workers, uint32_t sample_begin, uint32_t spp,
                            double time_limit = 0.0, const std::function<void(const RenderProgress&)>& progress = {},
                            const std::function<bool()>& stop = {});

// A scene compiled once and rendered through one camera on one device, or on several
// (one worker each, sharing the ranges of sample indices)
class Renderer {
 public:
  Renderer(const DeviceEntry& device, std::shared_ptr<const CompiledScene> scene, const dev::Camera& camera,
           const RenderSettings& settings);
  // One DeviceRenderer per entry (an entry listed twice gets two workers); builds the
  // kernels one device after the other. Throws Error when `devices` is empty.
  Renderer(const std::vector<DeviceEntry>& devices, std::shared_ptr<const CompiledScene> scene,
           const dev::Camera& camera, const RenderSettings& settings);
  // The same, and then the scene's host arrays are freed as the last device uploads them
  // (CompiledScene::release_host_arrays): for a caller that needs them no more (the CLI)
  Renderer(const std::vector<DeviceEntry>& devices, std::shared_ptr<CompiledScene> scene, const dev::Camera& camera,
           const RenderSettings& settings, bool release_host_arrays);

  RenderResult render(uint32_t sample_begin, uint32_t spp, double time_limit = 0.0,
                      const std::function<void(const RenderProgress&)>& progress = {},
                      const std::function<bool()>& stop = {});

  const CompiledScene& scene() const { return *scene_; }
  DeviceRenderer& worker() { return *workers_.front(); }
  const DeviceRenderer& worker() const { return *workers_.front(); }
  size_t worker_count() const { return workers_.size(); }
  DeviceRenderer& worker(size_t i) { return *workers_.at(i); }
  const DeviceRenderer& worker(size_t i) const { return *workers_.at(i); }
  // Every worker's DeviceRenderer::set_view, set_kernel_settings
  void set_view(const dev::Camera& camera, int width, int height);
  void set_kernel_settings(const RenderSettings& settings);
  // The first worker's kernel build; with several devices, the sum of all of them
  double kernel_build_seconds() const;
  bool kernel_from_cache() const;  // every worker's kernel came from the cache
  double bvh_build_seconds() const { return scene_->bvh_build_seconds; }
  size_t triangles() const { return scene_->triangles; }
  size_t lights() const { return scene_->buffers.lights.size(); }

 private:
  std::shared_ptr<const CompiledScene> scene_;
  std::vector<std::unique_ptr<DeviceRenderer>> workers_;
};

}  // namespace candela
