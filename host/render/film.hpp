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
  // With AOVs (cl/integrator/aov.cl), 8 per pixel, else empty: the means over the pixel's
  // samples (kept and dropped) of albedo rgb, alpha, normal xyz and depth
  std::vector<float> aov;
  // With --denoise, 3 per pixel, else empty: the denoised RGB, which image outputs show
  // (EXR ones keep the mean as noisy.R/G/B); merges and statistics use the mean
  std::vector<float> denoised;

  Film() = default;
  Film(int w, int h) : width(w), height(h), mean(size_t(w) * h * 4, 0.0f), m2(size_t(w) * h * 4, 0.0f) {}
  size_t pixels() const { return size_t(width) * height; }
  glm::vec3 pixel(size_t i) const { return {mean[4 * i], mean[4 * i + 1], mean[4 * i + 2]}; }
  float samples(size_t i) const { return mean[4 * i + 3]; }
  float samples_taken(size_t i) const { return mean[4 * i + 3] + m2[4 * i + 3]; }  // kept + dropped
  // Variance of the pixel's mean estimate (sample variance / n)
  glm::vec3 variance_of_mean(size_t i) const;
  uint64_t dropped_samples() const;
};

// Combines films of disjoint sample ranges of the same image, weighted by sample count
// (Chan, Golub and LeVeque 1979, parallel variance update); AOVs, where both have them, by
// samples taken.
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

// What an image output holds beyond the film's RGB (render/aov.hpp)
struct ImageLayers {
  uint32_t aovs = 0;         // EXR: these AOVs as channels (Aov bits)
  bool transparent = false;  // the film's RGB is premultiplied by its alpha: PNG RGBA with straight
                             // alpha, EXR with A
  uint32_t single = 0;       // PNG/JPEG: this one AOV instead of the image
};

// Writes OUT.exr (linear float RGB + metadata, no display transform) or OUT.png / OUT.jpg
// (8-bit sRGB through `display`). Other extensions throw Error.
void write_image(const std::string& path, const Film& film, const std::map<std::string, std::string>& metadata,
                 const DisplayTransform& display = {}, const ImageLayers& layers = {});

// Writes width x height pixels of the named channels (channels.size() floats each), float
// (.exr) or 8-bit (the values already encoded), as write_rgb_pixels does
void write_pixels(const std::string& path, int width, int height, const std::vector<std::string>& channels,
                  const std::vector<float>& values, bool float_channels,
                  const std::map<std::string, std::string>& metadata);

// sRGB encoding (IEC 61966-2-1) of a display-linear value, clamped to [0, 1]
float linear_to_srgb(float c);

}  // namespace candela
