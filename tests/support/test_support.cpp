#include "support/test_support.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>

#include "base/error.hpp"

namespace candela::test {

ScopedCacheDir::ScopedCacheDir() {
  dir_ = (std::filesystem::temp_directory_path() / ("candela-cache-test-" + std::to_string(::getpid()))).string();
  std::filesystem::remove_all(dir_);
  const char* old = std::getenv("CANDELA_CACHE_DIR");
  if (old) old_ = old;
  had_old_ = old != nullptr;
  setenv("CANDELA_CACHE_DIR", dir_.c_str(), 1);
}

ScopedCacheDir::~ScopedCacheDir() {
  std::error_code ec;
  std::filesystem::remove_all(dir_, ec);
  if (had_old_)
    setenv("CANDELA_CACHE_DIR", old_.c_str(), 1);
  else
    unsetenv("CANDELA_CACHE_DIR");
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

double rel_mse(const Film& f, const Film& reference) {
  double sum = 0.0;
  for (size_t i = 0; i < f.pixels(); ++i)
    for (int c = 0; c < 3; ++c) {
      double r = reference.pixel(i)[c], d = f.pixel(i)[c] - r;
      sum += d * d / (r * r + 0.01);
    }
  return sum / double(3 * f.pixels());
}

std::string scene_path(const std::string& relative) { return std::string(CANDELA_SOURCE_DIR) + "/scenes/" + relative; }

}  // namespace candela::test

namespace candela::test {

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

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace candela::test
