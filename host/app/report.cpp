// The record of one render, as --stats JSON and as image metadata (report.hpp).
#include "app/report.hpp"

#include <sys/resource.h>
#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>

#include "app/mpi_render.hpp"
#include "app/render_command.hpp"
#include "base/error.hpp"
#include "compile/bvh_builder.hpp"

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
  report.filter = enum_name(kPixelFilterNames, settings.filter);
  report.sampler = enum_name(kSamplerNames, settings.sampler);
  report.energy_compensation = settings.energy_compensation;
  report.dropped_samples = r.film.dropped_samples();
  report.scene = a.scene;
  report.width = settings.width;
  report.height = settings.height;
  report.samples_per_second = r.spp * (double(settings.width) * settings.height) / std::max(r.seconds, 1e-9);
  report.interrupted = r.interrupted;
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

std::map<std::string, std::string> image_metadata(const RenderReport& r) {
  return {{"spp", std::to_string(r.spp)},
          {"seconds", std::to_string(r.seconds)},
          {"device", r.device},
          {"seed", std::to_string(r.seed)},
          {"strategy", r.strategy},
          {"max_depth", std::to_string(r.max_depth)},
          {"dropped_samples", std::to_string(r.dropped_samples)},
          {"scene", r.scene},
          {"energy_compensation", r.energy_compensation ? "on" : "off"},
          {"filter", r.filter},
          {"sampler", r.sampler},
          {"sample_offset", std::to_string(r.sample_offset)}};
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
                      {"energy_compensation", r.energy_compensation},
                      {"filter", r.filter},
                      {"sampler", r.sampler},
                      {"max_depth", r.max_depth},
                      {"seed", r.seed},
                      {"interrupted", r.interrupted},
                      {"dropped_samples", r.dropped_samples},
                      {"generic_kernel", r.generic_kernel}};
  std::ofstream f(path);
  if (!(f << j.dump(2) << "\n")) throw Error("cannot write stats file " + path);
}

}  // namespace candela
