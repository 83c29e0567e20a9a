// Adaptive sampling (--noise-threshold E): every pixel gets the first kAdaptiveMinSpp samples
// (all of them when fewer are asked for); then passes of half the samples so far go only to
// the pixels whose estimated relative error of the mean still exceeds E, somewhere in their
// 3x3 neighbourhood, until none does, the most samples per pixel are reached or the time
// is up. The error is estimated from the odd-indexed samples alone (the kernel's half film),
// so whether a pixel stops does not depend on its even-indexed half; the image is the mean
// of all its samples (docs/integrator.md, Adaptive sampling, measures the bias).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "render/renderer.hpp"

namespace candela {

constexpr uint32_t kAdaptiveMinSpp = 16;

// The pixels in render_paths' launch order (pixel_of_launch_index, cl/integrator/render_paths.cl)
std::vector<uint32_t> launch_order(int width, int height);

// The estimated relative error of a pixel's mean over n samples, from its half film entry
// (mean, squared deviations, count of the odd-indexed samples' channel average):
// sigma / sqrt(n (mu^2 + 0.01)), the 0.01 that of relMSE; infinite under 2 such samples
double adaptive_error(const float* half_entry, uint32_t n);

// The pixels of `active` (n samples each) that go on: some pixel of their 3x3 neighbourhood
// among `active` has an error above `threshold`; in the order of `active`
std::vector<uint32_t> next_active(const std::vector<uint32_t>& active, const std::vector<float>& half_film, uint32_t n,
                                  int width, int height, double threshold);

// render_samples (renderer.hpp) for workers whose settings have a noise_threshold: the
// most samples a pixel gets is spp (with time_limit and spp 0, as many as fit the time).
// One worker only. result.spp is the fewest samples a pixel got.
RenderResult render_adaptive(const std::vector<DeviceRenderer*>& workers, uint32_t sample_begin, uint32_t spp,
                             double time_limit, const std::function<void(const RenderProgress&)>& progress,
                             const std::function<bool()>& stop);

}  // namespace candela
