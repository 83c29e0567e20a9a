// Adaptive sampling: the passes over the active pixels (adaptive.hpp).
#include "render/adaptive.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "base/error.hpp"

namespace candela {

std::vector<uint32_t> launch_order(int width, int height) {
  const uint32_t w = uint32_t(width), h = uint32_t(height);
  std::vector<uint32_t> order(size_t(w) * h);
  for (uint32_t i = 0; i < order.size(); ++i) {
    uint32_t band = i / (8u * w), in_band = i - band * 8u * w;
    uint32_t th = std::min(8u, h - 8u * band);
    uint32_t tile = in_band / (8u * th), k = in_band - tile * 8u * th;
    uint32_t tw = std::min(8u, w - 8u * tile), lx, ly;
    if (tw == 8u && th == 8u) {  // Z-order inside a whole tile
      lx = (k & 1u) | ((k >> 1u) & 2u) | ((k >> 2u) & 4u);
      ly = ((k >> 1u) & 1u) | ((k >> 2u) & 2u) | ((k >> 3u) & 4u);
    } else {
      ly = k / tw;
      lx = k - ly * tw;
    }
    order[i] = (8u * band + ly) * w + 8u * tile + lx;
  }
  return order;
}

double adaptive_error(const float* half_entry, uint32_t n) {
  double mean = half_entry[0], m2 = half_entry[1], count = half_entry[2];
  if (count < 2.0 || n == 0) return std::numeric_limits<double>::infinity();
  double variance = std::max(m2, 0.0) / (count - 1.0);
  return std::sqrt(variance / (double(n) * (mean * mean + 0.01)));
}

std::vector<uint32_t> next_active(const std::vector<uint32_t>& active, const std::vector<float>& half_film, uint32_t n,
                                  int width, int height, double threshold) {
  std::vector<char> above(size_t(width) * height, 0);
  for (uint32_t p : active) above[p] = adaptive_error(&half_film[4 * size_t(p)], n) > threshold;
  std::vector<uint32_t> out;
  out.reserve(active.size());
  for (uint32_t p : active) {
    int x = int(p % uint32_t(width)), y = int(p / uint32_t(width));
    bool go = false;
    for (int dy = -1; dy <= 1 && !go; ++dy)
      for (int dx = -1; dx <= 1 && !go; ++dx) {
        int qx = x + dx, qy = y + dy;
        go = qx >= 0 && qy >= 0 && qx < width && qy < height && above[size_t(qy) * width + qx];
      }
    if (go) out.push_back(p);
  }
  return out;
}

RenderResult render_adaptive(const std::vector<DeviceRenderer*>& workers, uint32_t sample_begin, uint32_t spp,
                             double time_limit, const std::function<void(const RenderProgress&)>& progress,
                             const std::function<bool()>& stop) {
  using Clock = std::chrono::steady_clock;
  if (workers.size() != 1) throw Error("--noise-threshold renders on one device (--device names several)");
  if (spp == 0 && !(time_limit > 0.0)) throw Error("render needs a sample count or a time limit");
  const uint64_t indices_left = (uint64_t(1) << 32) - sample_begin;
  if (spp > indices_left) throw Error("the sample indices would pass 2^32: lower --sample-offset or --spp");
  DeviceRenderer& w = *workers.front();
  const RenderSettings& s = w.settings();
  const uint32_t limit = spp > 0 ? spp : uint32_t(std::min<uint64_t>(kMaxSamplesPerPixel, indices_left));
  const uint32_t first = std::min(limit, kAdaptiveMinSpp);
  const bool timed = spp == 0;
  const auto start = Clock::now();
  auto seconds = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  std::vector<uint32_t> active = launch_order(s.width, s.height);
  RenderResult result;
  uint32_t n = 0;
  double cost = 0.0;  // seconds per sample of one active pixel, measured
  auto out_of_time = [&] { return timed && n > 0 && seconds() >= time_limit; };
  auto report = [&](double partial) {
    if (!progress) return;
    RenderProgress p;
    p.spp_done = n;
    p.spp_partial = partial;
    p.spp_target = spp;
    p.time_limit = timed ? time_limit : 0.0;
    p.seconds = seconds();
    p.worker_spp = {n + partial};
    progress(p);
  };
  while (n < limit) {
    if (stop && stop()) {
      result.interrupted = true;
      break;
    }
    if (out_of_time()) break;
    if (n >= first) {
      active = next_active(active, w.half_film(), n, s.width, s.height, s.noise_threshold);
      if (active.empty()) break;
      w.set_active(active);
    }
    uint32_t count = n < first ? (timed && n == 0 ? 1u : first - n) : std::max(2u, n / 2);
    count = std::min(count, limit - n);
    if (timed && cost > 0.0)
      count = uint32_t(std::clamp((time_limit - seconds()) / (cost * double(active.size())), 1.0, double(count)));
    bool stopped = false;
    auto should_stop = [&] { return (stopped = stop && stop()) || out_of_time(); };
    auto t0 = Clock::now();
    bool whole = w.render_range(sample_begin + n, count, should_stop, [&](double f) { report(f * count); });
    result.samples_taken = n + count;
    if (!whole) {
      result.partial_pass = true;
      result.interrupted = stopped;
      break;
    }
    cost = std::chrono::duration<double>(Clock::now() - t0).count() / (double(count) * double(active.size()));
    n += count;
    report(0.0);
  }
  result.seconds = seconds();
  result.film = w.film();
  double total = 0.0, fewest = result.film.pixels() ? std::numeric_limits<double>::infinity() : 0.0;
  for (size_t p = 0; p < result.film.pixels(); ++p) {
    total += result.film.samples(p);
    fewest = std::min<double>(fewest, result.film.samples_taken(p));
  }
  result.spp = uint32_t(fewest);
  result.worker_samples.push_back(uint64_t(total + 0.5));
  return result;
}

}  // namespace candela
