// The film: per-pixel running mean and squared deviations (Welford), and image output.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <map>
#include <string>
#include <vector>

#include "render/tonemap.hpp"

namespace candela {

struct Film {
  int width = 0, height = 0;
  std::vector<float> mean;  // 4 per pixel: rgb mean, w = samples kept
  std::vector<float> m2;    // 4 per pixel: rgb sum of squared deviations, w = samples dropped

  Film() = default;
  Film(int w, int h) : width(w), height(h), mean(size_t(w) * h * 4, 0.0f), m2(size_t(w) * h * 4, 0.0f) {}
  size_t pixels() const { return size_t(width) * height; }
  glm::vec3 pixel(size_t i) const { return {mean[4 * i], mean[4 * i + 1], mean[4 * i + 2]}; }
  float samples(size_t i) const { return mean[4 * i + 3]; }
  // Variance of the pixel's mean estimate (sample variance / n)
  glm::vec3 variance_of_mean(size_t i) const;
  uint64_t dropped_samples() const;
};

// Combines films of disjoint sample ranges of the same image, weighted by sample count
// (Chan, Golub and LeVeque 1979, parallel variance update).
Film merge_films(const Film& a, const Film& b);

// Throws Error unless the path ends in .exr, .png, .jpg or .jpeg (case-insensitive) and its
// folder exists and can be written (check_writable_path)
void check_output_path(const std::string& path);

// Writes width x height RGB pixels (3 floats each) to path: float channels (.exr) or 8-bit
// ones (.png, .jpg, the values already encoded), with each metadata entry as attribute candela:KEY
// and Software = candela VERSION, atomically (write_file_atomically: a failure leaves an
// existing file as it was); throws Error naming the path when it cannot
void write_rgb_pixels(const std::string& path, int width, int height, const std::vector<float>& rgb,
                      bool float_channels, const std::map<std::string, std::string>& metadata);

// How radiance becomes an 8-bit display value: scaled by 2^exposure, tone-mapped, sRGB-encoded
struct DisplayTransform {
  float exposure = 0.0f;  // stops
  Tonemap tonemap = Tonemap::Neutral;
};

// Writes OUT.exr (linear float RGB + metadata, no display transform) or OUT.png / OUT.jpg
// (8-bit sRGB through `display`). Other extensions throw Error.
void write_image(const std::string& path, const Film& film, const std::map<std::string, std::string>& metadata,
                 const DisplayTransform& display = {});

}  // namespace candela
