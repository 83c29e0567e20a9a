// The sampling distribution of an environment map (environment_distribution.hpp).
#include "compile/environment_distribution.hpp"

#include <algorithm>
#include <cmath>

namespace candela {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Unnormalized CDF of n non-negative weights, appended as n + 1 floats from 0. The sum is
// kept in double; a positive weight gets a step of at least one float ulp, a zero weight
// none, so the device's steps are > 0 exactly where the weights are.
void append_cdf(const double* weights, int n, std::vector<float>* out) {
  double sum = 0.0;
  float prev = 0.0f;
  out->push_back(prev);
  for (int i = 0; i < n; ++i) {
    sum += weights[i];
    float c = prev;
    if (weights[i] > 0.0) c = std::max(float(sum), std::nextafter(prev, INFINITY));
    out->push_back(c);
    prev = c;
  }
}

// Guide table of the CDF of n cells at cdf (n + 1 floats), appended as
// environment_guide_cells(n) floats: cell k holds, as an integer-valued float, the largest
// i < n with cdf[i] <= k / cells x cdf[n], where the kernel starts its search for a sample
// u in [k / cells, (k + 1) / cells). Any start in [0, n) gives the same answer (the kernel
// corrects it both ways); this one leaves about n / cells steps to take.
void append_guide(const float* cdf, int n, std::vector<float>* out) {
  int cells = dev::environment_guide_cells(n);
  double total = cdf[n];
  for (int k = 0; k < cells; ++k) {
    float t = float(double(k) / cells * total);
    int i = int(std::upper_bound(cdf, cdf + n, t) - cdf) - 1;  // cdf[0] = 0 <= t
    out->push_back(float(std::clamp(i, 0, n - 1)));
  }
}

double texel_luminance(const TextureDesc& map, size_t i) {
  const float* t = &map.rgbaf[4 * i];
  return dev::luminance_rgb(t[0], t[1], t[2]);
}

}  // namespace

std::vector<float> environment_distribution(const TextureDesc& map) {
  int w = map.width, h = map.height;
  std::vector<double> row_weight(static_cast<size_t>(h)), weights(static_cast<size_t>(w));
  std::vector<float> out;
  out.reserve(size_t(h) + 1 + size_t(h) * (size_t(w) + 1) + size_t(dev::environment_guide_cells(h)) +
              size_t(h) * size_t(dev::environment_guide_cells(w)));
  out.resize(size_t(h) + 1);  // the marginal CDF goes here once the rows are known
  for (int r = 0; r < h; ++r) {
    double sin_theta = std::sin(kPi * (r + 0.5) / h);
    double sum = 0.0;
    for (int c = 0; c < w; ++c) {
      weights[size_t(c)] = texel_luminance(map, size_t(r) * w + c) * sin_theta;
      sum += weights[size_t(c)];
    }
    row_weight[size_t(r)] = sum;
    // A black row is never sampled; a uniform CDF keeps its steps well defined
    if (!(sum > 0.0)) std::fill(weights.begin(), weights.end(), 1.0);
    append_cdf(weights.data(), w, &out);
  }
  std::vector<float> marginal;
  append_cdf(row_weight.data(), h, &marginal);
  std::copy(marginal.begin(), marginal.end(), out.begin());
  std::vector<float> guides;
  append_guide(out.data(), h, &guides);
  for (int r = 0; r < h; ++r) append_guide(out.data() + (size_t(h) + 1) + size_t(r) * (size_t(w) + 1), w, &guides);
  out.insert(out.end(), guides.begin(), guides.end());
  return out;
}

EnvironmentExtent environment_extent(const TextureDesc& map, double rotation) {
  int w = map.width, h = map.height;
  double sum = 0.0, sum2 = 0.0, centre[3] = {0.0, 0.0, 0.0};
  for (int r = 0; r < h; ++r) {
    double theta = kPi * (r + 0.5) / h;
    double solid_angle = 2.0 * kPi / w * (std::cos(kPi * r / h) - std::cos(kPi * (r + 1) / h));
    for (int c = 0; c < w; ++c) {
      double l = std::max(texel_luminance(map, size_t(r) * w + c), 0.0);
      double phi = 2.0 * kPi * (c + 0.5) / w - rotation;
      double d[3] = {-std::sin(theta) * std::sin(phi), std::cos(theta), std::sin(theta) * std::cos(phi)};
      sum += l * solid_angle;
      sum2 += l * l * solid_angle;
      for (int k = 0; k < 3; ++k) centre[k] += d[k] * l * l * solid_angle;
    }
  }
  EnvironmentExtent e;
  e.integral = sum;
  e.solid_angle = sum2 > 0.0 ? std::min(sum * sum / sum2, 4.0 * kPi) : 4.0 * kPi;
  double length = std::sqrt(centre[0] * centre[0] + centre[1] * centre[1] + centre[2] * centre[2]);
  if (sum2 > 0.0 && length > 1e-3 * sum2)
    for (int k = 0; k < 3; ++k) e.direction[k] = centre[k] / length;
  return e;
}

}  // namespace candela
