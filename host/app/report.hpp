// What one render did, recorded once when it ends: written as the --stats JSON and as the
// images' candela:* metadata (which `candela merge` reads back).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "app/render_devices.hpp"
#include "base/device_types.hpp"
#include "compile/compiled_scene.hpp"
#include "render/renderer.hpp"
#include "scene/scene.hpp"

namespace candela {

struct RenderArgs;

struct RenderReport {
  // The render: in the metadata and the stats
  uint32_t spp = 0;
  double seconds = 0.0;
  std::string device;  // every device's description, joined by " + "
  uint32_t seed = 0, max_depth = 0, sample_offset = 0;
  std::string strategy, light_selection, filter, sampler;
  bool energy_compensation = true;
  uint64_t dropped_samples = 0;
  bool partial_pass = false;  // stopped inside a range of samples
  uint64_t sample_end = 0;    // no pixel holds a sample index at or past this one
  // In the metadata only
  std::string scene;  // the scene file
  // Fingerprints (FNV-1a of the device camera record; of the background and environment
  // map): renders that `candela merge` combines must agree on them
  std::string camera, lighting;
  // In the stats only
  dev::Camera view{};  // the compiled camera the render used ("camera" in the stats)
  bool has_view = false;
  int width = 0, height = 0;
  double samples_per_second = 0.0;
  bool interrupted = false;
  bool generic_kernel = false;
  int mpi_ranks = 0;  // 0: not under --mpi
  double kernel_build_seconds = 0.0;
  bool kernel_from_cache = false;
  std::string kernel_features;  // the kernel's build options
  double bvh_build_seconds = 0.0, bvh_sah_cost = 0.0, scene_compile_seconds = 0.0;
  int bvh_threads = 0;
  size_t triangles = 0, lights = 0;
  size_t scene_device_bytes = 0;
  size_t peak_rss_bytes = 0;  // of this process, when the render ended
  std::vector<GridMemory> grids;
  std::vector<DeviceShare> devices;
};

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
