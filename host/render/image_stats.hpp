// Measured error bars and image comparison: the variance image of a render (the
// variance of each pixel's mean, from the film's Welford M2), reading linear EXR images
// back, error metrics against a reference, and the per-pixel z-test between two
// independent renders (`candela compare`).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "render/film.hpp"

namespace candela {

// Writes the per-pixel variance of the mean, M2 / (n (n - 1)) for each of R, G, B, as a
// linear float EXR. Pixels with fewer than two samples have no estimate: they are written
// as +infinity. `metadata` is written as candela:KEY attributes, plus
// candela:image = "variance_of_mean".
void write_variance_image(const std::string& path, const Film& film,
                          const std::map<std::string, std::string>& metadata);

// A linear RGB float image read from a file (any format OpenImageIO reads): channels R, G, B
// by name, else the first three (a grey image repeated into R, G and B); the others kept apart.
// A denoised render's EXR gives its unbiased estimate, noisy.R/G/B, and leaves R, G, B out.
struct RgbImage {
  int width = 0, height = 0;
  std::vector<float> rgb;                       // 3 per pixel, row-major from the top
  std::map<std::string, std::string> metadata;  // candela:KEY attributes, without "candela:"
  std::vector<std::string> extra_names;         // the channels besides R, G and B (A, albedo.R, ...)
  std::vector<float> extra;                     // extra_names.size() per pixel
  size_t pixels() const { return size_t(width) * height; }
};

// Throws Error with `what` naming the file's role when it is missing or unreadable
RgbImage read_rgb_image(const std::string& path, const std::string& what = "image");

// Error of `image` against `reference` over all pixels and channels. relMSE is the mean of
// (x - r)^2 / (r^2 + epsilon). Throws Error when the sizes differ.
struct ErrorMetrics {
  double rel_mse = 0.0, mse = 0.0, mae = 0.0;
  size_t values = 0;  // pixel-channels compared
};
constexpr double kRelMseEpsilon = 0.01;
ErrorMetrics image_error(const RgbImage& image, const RgbImage& reference, double epsilon = kRelMseEpsilon);

// Per-pixel z-test between two independent renders a and b of the same scene, each with
// its variance image: z = (a - b) / sqrt(var_a + var_b) per pixel-channel.
struct ZTest {
  size_t values = 0;                            // pixel-channels with var_a + var_b > 0 (and finite)
  size_t zero_variance = 0;                     // pixel-channels with no variance on either side
  size_t zero_variance_mismatch = 0;            // of those, how many differ beyond float rounding
  size_t undefined = 0;                         // pixel-channels with an infinite variance (fewer than 2 samples)
  double mean_z = 0.0;                          // a bias of one image against the other shows as a mean away from 0
  double mean_z2 = 0.0;                         // chi^2 / values; about 1 when consistent
  double frac_over_3 = 0.0, frac_over_4 = 0.0;  // fraction of |z| > 3 and > 4
  size_t count_over_4 = 0;
  double max_abs_z = 0.0;
  // The verdict (ZTestRule documents it) and, when inconsistent, why
  bool consistent = false;
  std::vector<std::string> reasons;
};

// The verdict rule of `candela compare` (README, "Speed against accuracy"): consistent when
//  1. the mean of z^2 is at most 1 + z2_slack + 4 sqrt(2 / values)  (chi^2: z^2 averages 1;
//     the slack allows the heavy tails of path-traced samples, whose variance estimates
//     at a few dozen samples run low in some pixels),
//  2. |mean z| <= 4 / sqrt(values / 3)  (no global bias; the three channels of a pixel are
//     correlated, so about values / 3 independent terms),
//  3. the count of |z| > 4 is at most expected + 4 sqrt(expected) + 3, where expected is
//     tail_allowance x values x P(|z| > 4 | normal) (the allowance again for heavy tails),
//  4. every zero-variance pixel-channel agrees to float rounding (a variance below
//     (1e-6 x the value)^2 counts as zero: it is rounding noise, not Monte Carlo noise).
struct ZTestRule {
  double z2_slack = 0.25;
  double tail_allowance = 10.0;
};
ZTest z_test(const RgbImage& a, const RgbImage& var_a, const RgbImage& b, const RgbImage& var_b,
             const ZTestRule& rule = {});

// Determinism check of two renders with the same seed: largest absolute and relative
// difference, and the fraction of pixel-channels that are bit-identical
struct SameSeedDiff {
  double max_abs = 0.0;
  double max_rel = 0.0;  // |a - b| / max(|a|, |b|)
  double identical_fraction = 0.0;
};
SameSeedDiff same_seed_diff(const RgbImage& a, const RgbImage& b);

}  // namespace candela
