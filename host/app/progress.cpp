// The render's progress bar (progress.hpp).
#include "app/progress.hpp"

#include <unistd.h>
#include <algorithm>
#include <cstdio>
#include <string>

namespace candela {
namespace {

std::string format_duration(double s) {
  char buf[32];
  if (s < 60)
    std::snprintf(buf, sizeof buf, "%.1fs", s);
  else
    std::snprintf(buf, sizeof buf, "%dm%02ds", int(s) / 60, int(s) % 60);
  return buf;
}

// "  devices 0: 52% 1: 48%": each worker's share of the samples so far
std::string format_device_shares(const RenderProgress& p) {
  double total = 0.0;
  for (double v : p.worker_spp) total += v;
  std::string s = "  devices";
  char buf[32];
  for (size_t i = 0; i < p.worker_spp.size(); ++i) {
    std::snprintf(buf, sizeof buf, " %zu: %.0f%%", i, total > 0 ? 100.0 * p.worker_spp[i] / total : 0.0);
    s += buf;
  }
  return s;
}

}  // namespace

ProgressBar::ProgressBar(bool enabled, double pixels)
    : enabled_(enabled), terminal_(isatty(STDERR_FILENO)), pixels_(pixels) {}

void ProgressBar::update(const RenderProgress& p) {
  if (!enabled_) return;
  if (!terminal_) {
    if (p.seconds < next_line_) return;
    next_line_ = p.seconds + 10.0;
  }
  double spp = p.spp_done + p.spp_partial;
  double frac = p.spp_target ? spp / p.spp_target : std::min(1.0, p.seconds / p.time_limit);
  double rate = p.seconds > 0 ? spp * pixels_ / p.seconds : 0.0;
  double eta = frac > 0 ? p.seconds * (1.0 - frac) / frac : 0.0;
  int width = 30, filled = int(frac * width + 0.5);
  std::string bar = std::string(filled, '#') + std::string(width - filled, '-');
  std::string shares = shares_ ? format_device_shares(p) : "";
  std::string target = p.spp_target ? "/" + std::to_string(p.spp_target) : "";
  std::fprintf(
      stderr,
      terminal_ ? "\r[%s] %u%s spp  %.2f Msamples/s  ETA %s%s   " : "[%s] %u%s spp  %.2f Msamples/s  ETA %s%s\n",
      bar.c_str(), p.spp_done, target.c_str(), rate * 1e-6, format_duration(eta).c_str(), shares.c_str());
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressBar::finish() {
  if (drawn_ && terminal_) std::fprintf(stderr, "\n");
}

}  // namespace candela
