// The record of one render, as --stats JSON and as image metadata (report.hpp).
#include "app/report.hpp"

#include <sys/resource.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string_view>
#include <variant>

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

// What the render did, and the settings it records (settings.hpp)
void record_render(const RenderArgs& a, const RenderSettings& settings, const RenderResult& r, RenderReport* out) {
  RenderReport& report = *out;
  report.spp = r.spp;
  report.seconds = r.seconds;
  report.dropped_samples = r.film.dropped_samples();
  report.samples_per_second = r.spp * (double(settings.width) * settings.height) / std::max(r.seconds, 1e-9);
  if (settings.noise_threshold > 0.0 && !r.worker_samples.empty())  // adaptive: the samples taken
    report.samples_per_second = double(r.worker_samples.front()) / std::max(r.seconds, 1e-9);
  report.interrupted = r.interrupted;
  report.partial_pass = r.partial_pass;
  report.sample_end = uint64_t(a.sample_offset) + r.samples_taken;
  for (const RenderSetting& s : render_settings())
    if (s.record) report.settings.emplace_back(&s, s.record(a, settings));
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

namespace {

// A value as the metadata spells it: a number in decimal, a flag on|off
template <typename T>
std::string metadata_text(const T& v) {
  return std::to_string(v);
}
std::string metadata_text(const std::string& v) { return v; }
std::string metadata_text(bool v) { return v ? "on" : "off"; }

template <typename T>
bool unset(const T&) {
  return false;
}
bool unset(const std::string& v) { return v.empty(); }

}  // namespace

std::vector<RecordKey> result_keys() {
  std::vector<RecordKey> keys;
#define CD_RESULT_KEY(type, name, where) \
  keys.push_back({#name, ((where)&kInImage) != 0, ((where)&kInStats) != 0, ((where)&kMustAgree) != 0});
  CD_RENDER_RESULTS(CD_RESULT_KEY)
#undef CD_RESULT_KEY
  // Written by hand below: image_metadata's partial pass, write_stats' structured and
  // derived keys
  keys.push_back({"partial_pass", true, false, false, false});
  keys.push_back({"sample_ranges", true, false, false, false});
  for (const char* key : {"grids", "devices", "camera", "device_bytes_per_triangle", "peak_rss_bytes_per_triangle"})
    keys.push_back({key, false, true, false, true});
  return keys;
}

std::vector<std::string> must_match_keys() {
  std::vector<std::string> keys;
  for (const RenderSetting& s : render_settings())
    if (s.must_match && s.metadata) keys.push_back(s.metadata);
  for (const RecordKey& k : result_keys())
    if (k.must_match) keys.push_back(k.key);
  return keys;
}

std::map<std::string, std::string> image_metadata(const RenderReport& r) {
  std::map<std::string, std::string> meta;
  for (const auto& [setting, value] : r.settings)
    if (setting->metadata) meta[setting->metadata] = std::visit([](const auto& v) { return metadata_text(v); }, value);
#define CD_RESULT_METADATA(type, name, where) \
  if (((where)&kInImage) && !(((where)&kIfSet) && unset(r.name))) meta[#name] = metadata_text(r.name);
  CD_RENDER_RESULTS(CD_RESULT_METADATA)
#undef CD_RESULT_METADATA
  // Stopped inside a range: its pixels hold up to sample_end (merge refuses overlaps)
  if (r.partial_pass) {
    meta["partial_pass"] = "1";
    meta["sample_ranges"] = meta.at("sample_offset") + ":" + std::to_string(r.sample_end);
  }
  return meta;
}

void write_stats(const RenderReport& r, const std::string& path) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [setting, value] : r.settings)
    if (setting->stats) j[setting->stats] = std::visit([](const auto& v) { return nlohmann::json(v); }, value);
#define CD_RESULT_STATS(type, name, where) \
  if ((where)&kInStats) j[#name] = r.name;
  CD_RENDER_RESULTS(CD_RESULT_STATS)
#undef CD_RESULT_STATS
  j["grids"] = grids_json(r.grids);
  j["devices"] = devices_json(r.devices);
  j["device_bytes_per_triangle"] = per_triangle(r.scene_device_bytes, r.triangles);
  j["peak_rss_bytes_per_triangle"] = per_triangle(r.peak_rss_bytes, r.triangles);
  if (r.has_view) j["camera"] = camera_json(r.view);
  write_file_atomically(path, j.dump(2) + "\n");
}

}  // namespace candela
