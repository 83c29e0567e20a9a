// What one render did, recorded once when it ends: written as the --stats JSON and as the
// images' candela:* metadata (which `candela merge` reads back).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "app/render_devices.hpp"
#include "app/settings.hpp"
#include "base/device_types.hpp"
#include "compile/compiled_scene.hpp"
#include "render/renderer.hpp"
#include "scene/scene.hpp"

namespace candela {

// What a render measured and found, beside the settings it records (settings.hpp): one
// line per field, X(type, name, where), `where` a sum of kInImage (the candela:NAME metadata;
// with kIfSet only when not empty), kInStats (NAME in the --stats JSON) and kMustAgree
// (`candela merge` merges only images that agree on it). camera and lighting are
// fingerprints (FNV-1a of the device camera record; of the background and environment map).
// One entry per line, columns aligned:
// clang-format off
#define CD_RENDER_RESULTS(X)                                    \
  X(uint32_t,    spp,                   kInImage | kInStats)    \
  X(double,      seconds,               kInImage | kInStats)    \
  X(double,      samples_per_second,    kInStats)               \
  X(std::string, device,                kInImage | kInStats)    \
  X(uint64_t,    dropped_samples,       kInImage | kInStats)    \
  X(bool,        interrupted,           kInStats)               \
  X(bool,        partial_pass,          kInStats)               \
  X(uint64_t,    sample_end,            kInStats)               \
  X(int,         mpi_ranks,             kInStats)               \
  X(double,      kernel_build_seconds,  kInStats)               \
  X(bool,        kernel_from_cache,     kInStats)               \
  X(std::string, kernel_features,       kInStats)               \
  X(double,      bvh_build_seconds,     kInStats)               \
  X(double,      bvh_sah_cost,          kInStats)               \
  X(int,         bvh_threads,           kInStats)               \
  X(double,      scene_compile_seconds, kInStats)               \
  X(size_t,      scene_device_bytes,    kInStats)               \
  X(size_t,      triangles,             kInStats)               \
  X(size_t,      lights,                kInStats)               \
  X(size_t,      peak_rss_bytes,        kInStats)               \
  X(std::string, camera,                kInImage | kIfSet | kMustAgree) \
  X(std::string, lighting,              kInImage | kIfSet | kMustAgree)
// clang-format on
enum RecordWhere : unsigned { kInImage = 1, kInStats = 2, kIfSet = 4, kMustAgree = 8 };

struct RenderReport {
#define CD_RESULT_MEMBER(type, name, where) type name{};
  CD_RENDER_RESULTS(CD_RESULT_MEMBER)
#undef CD_RESULT_MEMBER
  // The recorded settings with their values, in the table's order
  std::vector<std::pair<const RenderSetting*, SettingValue>> settings;
  // In the stats only: partial_pass and sample_end also give the metadata's partial_pass
  // and sample_ranges; "camera" is the compiled camera the render used
  dev::Camera view{};
  bool has_view = false;
  std::vector<GridMemory> grids;
  std::vector<DeviceShare> devices;
};

// A key of the record: in the metadata, in the stats, required to match by merge, and
// whether every render writes it (else only some, e.g. one stopped inside a pass)
struct RecordKey {
  std::string key;
  bool metadata = false, stats = false, must_match = false, always = true;
};
// The keys of the record besides the settings': CD_RENDER_RESULTS and the ones written
// by hand (grids, devices, camera, the per-triangle figures, sample_ranges)
std::vector<RecordKey> result_keys();
// The metadata `candela merge` requires to agree: the settings' and the results', in order
std::vector<std::string> must_match_keys();

// The fingerprints of the camera and the lighting of a scene about to be compiled
std::string camera_fingerprint(const Scene& scene, int width, int height);
std::string lighting_fingerprint(const Scene& scene);

RenderReport make_render_report(const RenderArgs& args, const RenderSettings& settings, const Renderer& renderer,
                                const RenderResult& result, const std::vector<DeviceEntry>& devices);

// The candela:KEY attributes of the images (KEY without the prefix)
std::map<std::string, std::string> image_metadata(const RenderReport& report);

// --stats: the report as JSON; throws Error when the file cannot be written
void write_stats(const RenderReport& report, const std::string& path);

}  // namespace candela
