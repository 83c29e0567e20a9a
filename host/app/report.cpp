// The record of one render, as --stats JSON and as image metadata (report.hpp).
#include "app/report.hpp"

#include <sys/resource.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string_view>

#include "app/mpi_render.hpp"
#include "app/render_command.hpp"
#include "base/atomic_file.hpp"
#include "base/error.hpp"
#include "base/hash.hpp"
#include "compile/bvh_builder.hpp"
#include "compile/camera.hpp"

namespace candela {
namespace {

// Peak resident set of this process so far (getrusage: kilobytes on Linux)
size_t peak_rss_bytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return size_t(u.ru_maxrss) * 1024;
}

// "grids": each density grid's device memory (a NanoVDB buffer or dense values, and its
// majorant cells)
nlohmann::json grids_json(const std::vector<GridMemory>& grids) {
  nlohmann::json list = nlohmann::json::array();
  for (const GridMemory& g : grids)
    list.push_back({{"source", g.source}, {"grid_bytes", g.grid_bytes}, {"majorant_bytes", g.majorant_bytes}});
  return list;
}

// "devices": each worker's samples (summed over pixels), share and rate
nlohmann::json devices_json(const std::vector<DeviceShare>& shares) {
  nlohmann::json list = nlohmann::json::array();
  for (const DeviceShare& d : shares)
    list.push_back({{"index", d.index},
                    {"selector", d.selector},
                    {"description", d.description},
                    {"samples", d.samples},
                    {"share", d.share},
                    {"samples_per_second", d.samples_per_second}});
  return list;
}

// "camera": the compiled camera (dev::Camera) with unit right and up vectors and the view's
// extent apart: the vertical field of view (perspective; |up| = tan(yfov / 2)) or the
// half-height ymag and half-width xmag (orthographic; |up| = ymag)
nlohmann::json camera_json(const dev::Camera& c) {
  auto vec = [](const float* v) { return nlohmann::json::array({v[0], v[1], v[2]}); };
  auto length = [](const float* v) {
    return std::sqrt(double(v[0]) * v[0] + double(v[1]) * v[1] + double(v[2]) * v[2]);
  };
  auto unit = [&](const float* v) {
    double n = std::max(length(v), 1e-30);
    return nlohmann::json::array({v[0] / n, v[1] / n, v[2] / n});
  };
  bool ortho = c.type == CAMERA_ORTHOGRAPHIC;
  nlohmann::json j = {{"type", ortho ? "orthographic" : "perspective"},
                      {"position", vec(c.origin)},
                      {"forward", vec(c.forward)},
                      {"up", unit(c.up)},
                      {"right", unit(c.right)},
                      {"lens_radius", c.lens_radius},
                      {"focus_distance", c.focus_distance}};
  if (ortho) {
    j["ymag"] = length(c.up);
    j["xmag"] = length(c.right);
  } else {
    const double degrees = 180.0 / 3.14159265358979323846;
    j["yfov_degrees"] = 2.0 * std::atan(length(c.up)) * degrees;
    j["xfov_degrees"] = 2.0 * std::atan(length(c.right)) * degrees;
  }
  return j;
}

double per_triangle(size_t bytes, size_t triangles) { return double(bytes) / double(std::max<size_t>(1, triangles)); }

// The render's settings and what it did
void record_render(const RenderArgs& a, const RenderSettings& settings, const RenderResult& r, RenderReport* out) {
  RenderReport& report = *out;
  report.spp = r.spp;
  report.seconds = r.seconds;
  report.seed = settings.seed;
  report.max_depth = settings.max_depth;
  report.sample_offset = a.sample_offset;
  report.strategy = a.strategy;
  report.light_selection = a.light_selection;
  report.filter = enum_name(kPixelFilterNames, settings.filter);
  report.sampler = enum_name(kSamplerNames, settings.sampler);
  report.energy_compensation = settings.energy_compensation;
  report.dropped_samples = r.film.dropped_samples();
  report.scene = a.scene;
  report.width = settings.width;
  report.height = settings.height;
  report.samples_per_second = r.spp * (double(settings.width) * settings.height) / std::max(r.seconds, 1e-9);
  report.interrupted = r.interrupted;
  report.partial_pass = r.partial_pass;
  report.sample_end = uint64_t(a.sample_offset) + r.samples_taken;
  report.generic_kernel = a.generic;
}

// The compiled scene, its kernels and this process
void record_scene(const Renderer& renderer, RenderReport* report) {
  const CompiledScene& scene = renderer.scene();
  report->kernel_build_seconds = renderer.kernel_build_seconds();
  report->kernel_from_cache = renderer.kernel_from_cache();
  report->kernel_features = scene.features.build_options();
  report->bvh_build_seconds = renderer.bvh_build_seconds();
  report->bvh_sah_cost = scene.bvh_sah_cost;
  report->bvh_threads = bvh_build_threads();
  report->scene_compile_seconds = scene.compile_seconds;
  report->scene_device_bytes = scene.device_bytes;
  report->triangles = renderer.triangles();
  report->lights = renderer.lights();
  report->grids = scene.grids;
  report->peak_rss_bytes = peak_rss_bytes();
}

}  // namespace

RenderReport make_render_report(const RenderArgs& args, const RenderSettings& settings, const Renderer& renderer,
                                const RenderResult& result, const std::vector<DeviceEntry>& devices) {
  RenderReport report;
  record_render(args, settings, result, &report);
  record_scene(renderer, &report);
  report.device = joined_descriptions(devices);
  report.devices = device_shares(devices, result);
  report.mpi_ranks = mpi_ranks();
  return report;
}

namespace {

std::string hex64(uint64_t h) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", (unsigned long long)h);
  return text;
}

template <typename T>
uint64_t hash_bytes(const T* data, size_t count, uint64_t h) {
  return fnv1a64(std::string_view(reinterpret_cast<const char*>(data), count * sizeof(T)), h);
}

}  // namespace

std::string camera_fingerprint(const Scene& scene, int width, int height) {
  dev::Camera camera = compile_camera(scene, width, height);
  return hex64(hash_bytes(&camera, 1, fnv1a64("camera")));
}

std::string lighting_fingerprint(const Scene& scene) {
  uint64_t h = hash_bytes(&scene.background, 1, fnv1a64("lighting"));
  if (const auto& env = scene.environment) {
    h = hash_bytes(env->image.rgbaf.data(), env->image.rgbaf.size(), h);
    h = hash_bytes(env->image.rgba8.data(), env->image.rgba8.size(), h);
    h = hash_bytes(&env->strength, 1, h);
    h = hash_bytes(&env->rotation, 1, h);
  }
  return hex64(h);
}

std::map<std::string, std::string> image_metadata(const RenderReport& r) {
  std::map<std::string, std::string> meta = {{"spp", std::to_string(r.spp)},
                                             {"seconds", std::to_string(r.seconds)},
                                             {"device", r.device},
                                             {"seed", std::to_string(r.seed)},
                                             {"strategy", r.strategy},
                                             {"light_selection", r.light_selection},
                                             {"max_depth", std::to_string(r.max_depth)},
                                             {"dropped_samples", std::to_string(r.dropped_samples)},
                                             {"scene", r.scene},
                                             {"energy_compensation", r.energy_compensation ? "on" : "off"},
                                             {"filter", r.filter},
                                             {"sampler", r.sampler},
                                             {"sample_offset", std::to_string(r.sample_offset)}};
  if (!r.camera.empty()) meta["camera"] = r.camera;
  if (!r.lighting.empty()) meta["lighting"] = r.lighting;
  // Stopped inside a range: its pixels hold up to sample_end (merge refuses overlaps)
  if (r.partial_pass) {
    meta["partial_pass"] = "1";
    meta["sample_ranges"] = std::to_string(r.sample_offset) + ":" + std::to_string(r.sample_end);
  }
  return meta;
}

void write_stats(const RenderReport& r, const std::string& path) {
  nlohmann::json j = {{"spp", r.spp},
                      {"seconds", r.seconds},
                      {"samples_per_second", r.samples_per_second},
                      {"kernel_build_seconds", r.kernel_build_seconds},
                      {"kernel_from_cache", r.kernel_from_cache},
                      {"kernel_features", r.kernel_features},
                      {"bvh_build_seconds", r.bvh_build_seconds},
                      {"scene_compile_seconds", r.scene_compile_seconds},
                      {"scene_device_bytes", r.scene_device_bytes},
                      {"grids", grids_json(r.grids)},
                      {"device_bytes_per_triangle", per_triangle(r.scene_device_bytes, r.triangles)},
                      {"peak_rss_bytes", r.peak_rss_bytes},
                      {"peak_rss_bytes_per_triangle", per_triangle(r.peak_rss_bytes, r.triangles)},
                      {"bvh_sah_cost", r.bvh_sah_cost},
                      {"bvh_threads", r.bvh_threads},
                      {"triangles", r.triangles},
                      {"lights", r.lights},
                      {"device", r.device},
                      {"devices", devices_json(r.devices)},
                      {"sample_offset", r.sample_offset},
                      {"mpi_ranks", r.mpi_ranks},
                      {"width", r.width},
                      {"height", r.height},
                      {"strategy", r.strategy},
                      {"light_selection", r.light_selection},
                      {"energy_compensation", r.energy_compensation},
                      {"filter", r.filter},
                      {"sampler", r.sampler},
                      {"max_depth", r.max_depth},
                      {"seed", r.seed},
                      {"interrupted", r.interrupted},
                      {"partial_pass", r.partial_pass},
                      {"sample_end", r.sample_end},
                      {"dropped_samples", r.dropped_samples},
                      {"generic_kernel", r.generic_kernel}};
  if (r.has_view) j["camera"] = camera_json(r.view);
  write_file_atomically(path, j.dump(2) + "\n");
}

}  // namespace candela
