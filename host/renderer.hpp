// Runs the megakernel on one device: uploads the scene, launches sample batches sized to
// a target duration, and reads back the film.
#pragma once

#include <CL/opencl.hpp>
#include <cstdint>
#include <functional>
#include <string>

#include "device.hpp"
#include "film.hpp"
#include "scene.hpp"

namespace candela {

enum class Strategy : uint32_t { Nee = STRATEGY_NEE, Bsdf = STRATEGY_BSDF };

// The film's per-pixel sample count is a float: exact up to 2^24
constexpr uint32_t kMaxSamplesPerPixel = 1u << 24;

struct RenderSettings {
  int width = 512, height = 512;
  uint32_t seed = 0;
  uint32_t max_depth = 16;  // scattering events
  uint32_t rr_depth = 3;  // Russian roulette after this many bounces
  Strategy strategy = Strategy::Nee;
  double launch_seconds = 0.2;  // target duration of one launch
};

struct RenderProgress {
  uint32_t spp_done = 0;
  double spp_partial = 0.0;  // fraction of the pass under way, in samples per pixel
  uint32_t spp_target = 0;  // 0 when rendering for a time budget
  double seconds = 0.0;
  double time_limit = 0.0;
};

struct RenderResult {
  Film film;
  uint32_t spp = 0;  // samples every pixel received
  double seconds = 0.0;
  bool interrupted = false;  // stopped by the caller
  bool partial_pass = false;  // stopped inside a pass: some pixels hold one batch more
};

class Renderer {
 public:
  // Builds the BVH, light table and kernel program and uploads the scene.
  Renderer(const DeviceEntry& device, const Scene& scene, const RenderSettings& settings);

  // Renders sample indices [sample_begin, sample_begin + spp) of every pixel, or for
  // time_limit seconds when spp == 0. `stop` is polled between launches; a stopped
  // render keeps the samples already done. After a result with partial_pass, some
  // pixels already hold sample indices from sample_begin + result.spp on: do not
  // resume that film from there.
  RenderResult render(uint32_t sample_begin, uint32_t spp, double time_limit = 0.0,
                      const std::function<void(const RenderProgress&)>& progress = {},
                      const std::function<bool()>& stop = {});

  double kernel_build_seconds() const { return kernel_build_seconds_; }
  bool kernel_from_cache() const { return kernel_from_cache_; }
  double bvh_build_seconds() const { return bvh_build_seconds_; }
  size_t triangles() const { return triangles_; }
  size_t lights() const { return num_lights_; }
  const DeviceEntry& device() const { return device_; }

 private:
  void launch(uint32_t sample_begin, uint32_t count, size_t pixel_begin, size_t pixel_end);

  DeviceEntry device_;
  RenderSettings settings_;
  cl::Context context_;
  cl::CommandQueue queue_;
  cl::Kernel kernel_;
  cl::Buffer nodes_, tris_, shading_, colors_, materials_, textures_, texels_, srgb_table_, lights_,
      light_thresholds_;
  cl::Buffer params_, film_mean_, film_m2_;
  dev::RenderParams params_host_{};
  size_t local_size_ = 1;
  double kernel_build_seconds_ = 0.0, bvh_build_seconds_ = 0.0;
  bool kernel_from_cache_ = false;
  size_t triangles_ = 0, num_lights_ = 0;
};

}  // namespace candela
