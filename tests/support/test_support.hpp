// Shared helpers for tests: the device-kernel fixture (support/kernels.hpp), renders and
// their estimates, scene paths.
#pragma once

#include <CL/opencl.hpp>
#include <functional>
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
#include "support/kernels.hpp"

namespace candela::test {

// CANDELA_CACHE_DIR set to an empty folder of the test's own for its lifetime (removed, and
// the variable restored, after)
class ScopedCacheDir {
 public:
  ScopedCacheDir();
  ~ScopedCacheDir();
  ScopedCacheDir(const ScopedCacheDir&) = delete;
  ScopedCacheDir& operator=(const ScopedCacheDir&) = delete;
  const std::string& path() const { return dir_; }

 private:
  std::string dir_, old_;
  bool had_old_ = false;
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

// relMSE of f against a reference: the mean over pixels and channels of (x - r)^2 / (r^2 + 0.01)
double rel_mse(const Film& f, const Film& reference);

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

// The message of the candela::Error that f throws; "" when it throws none
std::string error_of(const std::function<void()>& f);

}  // namespace candela::test
