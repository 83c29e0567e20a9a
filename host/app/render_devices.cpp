// The devices of one render (render_devices.hpp).
#include "app/render_devices.hpp"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "app/options.hpp"
#include "base/error.hpp"

namespace candela {
namespace {

// A comma-separated list of selectors, each a device; `all` stands alone
std::vector<DeviceEntry> select_device_list(const std::string& list, const std::string& selector) {
  std::vector<DeviceEntry> devices;
  std::stringstream ss(list);
  for (std::string sel; std::getline(ss, sel, ',');) {
    if (sel.find_first_not_of(" \t") == std::string::npos)
      throw Error("--device has an empty entry: '" + selector + "'");
    if (lowercase(trim_blanks(sel)) == "all")
      throw Error("--device all stands alone, not in a list: '" + selector + "'");
    devices.push_back(select_device(sel));
  }
  if (list.back() == ',') throw Error("--device has an empty entry: '" + selector + "'");
  return devices;
}

}  // namespace

std::vector<DeviceEntry> select_render_devices(const std::string& selector) {
  std::string trimmed = trim_blanks(selector);
  if (lowercase(trimmed) == "all") {
    std::vector<DeviceEntry> all = list_devices();
    if (all.empty()) throw Error("--device all: OpenCL platforms are installed but none has a device");
    return all;
  }
  if (trimmed.find(',') == std::string::npos) return {select_device(trimmed)};
  return select_device_list(trimmed, selector);
}

std::string joined_descriptions(const std::vector<DeviceEntry>& devices) {
  std::string s;
  for (size_t i = 0; i < devices.size(); ++i) s += (i ? " + " : "") + devices[i].description();
  return s;
}

void print_render_summary(const Renderer& r, const std::vector<DeviceEntry>& devices) {
  if (devices.size() == 1) {
    std::fprintf(stderr, "scene: %zu triangles, %zu lights, BVH %.2fs; kernel build %.2fs%s\n", r.triangles(),
                 r.lights(), r.bvh_build_seconds(), r.kernel_build_seconds(), r.kernel_from_cache() ? " (cached)" : "");
    return;
  }
  for (size_t i = 0; i < devices.size(); ++i) {
    const DeviceRenderer& w = r.worker(i);
    std::fprintf(stderr, "device %zu: %s [%s]; kernel build %.2fs%s\n", i, devices[i].description().c_str(),
                 devices[i].selector().c_str(), w.kernel_build_seconds(), w.kernel_from_cache() ? " (cached)" : "");
    for (size_t j = 0; j < i; ++j)
      if (devices[j].global_index == devices[i].global_index) {
        std::fprintf(stderr, "note: device %zu is device %zu again: two workers share its compute units\n", i, j);
        break;
      }
  }
  std::fprintf(stderr, "scene: %zu triangles, %zu lights, BVH %.2fs; %zu devices\n", r.triangles(), r.lights(),
               r.bvh_build_seconds(), devices.size());
}

std::vector<DeviceShare> device_shares(const std::vector<DeviceEntry>& devices, const RenderResult& r) {
  double total = 0.0;
  for (uint64_t n : r.worker_samples) total += double(n);
  std::vector<DeviceShare> shares;
  for (size_t i = 0; i < devices.size(); ++i) {
    DeviceShare d;
    d.index = i;
    d.selector = devices[i].selector();
    d.description = devices[i].description();
    d.samples = i < r.worker_samples.size() ? r.worker_samples[i] : 0;
    d.share = total > 0 ? double(d.samples) / total : 0.0;
    d.samples_per_second = double(d.samples) / std::max(r.seconds, 1e-9);
    shares.push_back(d);
  }
  return shares;
}

void print_device_shares(const std::vector<DeviceShare>& shares) {
  if (shares.size() < 2) return;
  for (const DeviceShare& d : shares)
    std::printf("  device %zu: %.1f%% of the samples, %.3f Msamples/s, %s\n", d.index, 100.0 * d.share,
                d.samples_per_second * 1e-6, d.description.c_str());
}

}  // namespace candela
