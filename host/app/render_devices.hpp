// The devices of one render: --device LIST|all, the scene summary per device, and each
// device's share of the samples.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "device/device.hpp"
#include "render/renderer.hpp"

namespace candela {

// --device: one selector (device/device.hpp), a comma-separated list of them, or `all`
// (every device `candela devices` lists, each once). A device named twice in a list gets
// two workers (two contexts and queues on it), as asked.
std::vector<DeviceEntry> select_render_devices(const std::string& selector);

// The devices' descriptions joined by " + "
std::string joined_descriptions(const std::vector<DeviceEntry>& devices);

// The scene summary: the single-device lines as before; with several devices one line
// each (its kernel build) and a note for a device named more than once
void print_render_summary(const Renderer& r, const std::vector<DeviceEntry>& devices);

// One worker's samples (summed over pixels), share and rate
struct DeviceShare {
  size_t index = 0;
  std::string selector, description;
  uint64_t samples = 0;
  double share = 0.0;
  double samples_per_second = 0.0;
};
std::vector<DeviceShare> device_shares(const std::vector<DeviceEntry>& devices, const RenderResult& r);

// With several devices, a line for each one's share
void print_device_shares(const std::vector<DeviceShare>& shares);

}  // namespace candela
