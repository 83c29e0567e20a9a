#include "light_table.hpp"

#include <algorithm>
#include <cmath>

#include "error.hpp"

namespace candela {
namespace {

constexpr double kPi = 3.14159265358979323846;

double luminance(const float* c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

}  // namespace

std::vector<uint32_t> selection_thresholds(const std::vector<double>& weights,
                                           std::vector<double>* pmf) {
  const uint64_t range = uint64_t(1) << 32;
  size_t n = weights.size();
  pmf->assign(n, 0.0);
  if (n == 0) return {};
  if (n > (uint64_t(1) << 31)) throw Error("too many lights for the light table");
  double total = 0.0;
  for (double w : weights) total += w;
  std::vector<uint32_t> thresholds;
  uint64_t prev = 0;
  double cum = 0.0;
  for (size_t i = 0; i + 1 < n; ++i) {
    cum += weights[i];
    uint64_t t = uint64_t(std::llround(cum / total * double(range)));
    // At least one integer per light, and room for every light after this one
    t = std::max(t, prev + 1);
    t = std::min(t, range - (n - 1 - i));
    thresholds.push_back(uint32_t(t));
    (*pmf)[i] = double(t - prev) / double(range);
    prev = t;
  }
  (*pmf)[n - 1] = double(range - prev) / double(range);
  return thresholds;
}

LightTable build_light_table(const std::vector<dev::Triangle>& triangles,
                             const std::vector<dev::Material>& materials,
                             const std::vector<double>& texture_means,
                             const glm::vec3& background, const Bounds& bounds) {
  LightTable table;
  std::vector<double> power;
  for (size_t i = 0; i < triangles.size(); ++i) {
    const dev::Triangle& t = triangles[i];
    const dev::Material& m = materials[t.material];
    double lum = luminance(m.emission);
    if (m.emission_texture != NO_TEXTURE) lum *= texture_means.at(size_t(m.emission_texture));
    if (!(lum > 0.0)) continue;  // includes emissive textures that are black throughout
    glm::vec3 v0(t.v0[0], t.v0[1], t.v0[2]), v1(t.v1[0], t.v1[1], t.v1[2]),
        v2(t.v2[0], t.v2[1], t.v2[2]);
    double area = 0.5 * glm::length(glm::cross(v1 - v0, v2 - v0));
    if (!(area > 0.0)) continue;
    dev::Light l{};
    l.type = LIGHT_TRIANGLE;
    l.index = uint32_t(i);
    l.area = float(area);
    for (int c = 0; c < 3; ++c) l.radiance[c] = m.emission[c];
    table.lights.push_back(l);
    // Diffuse emitter: power = pi * L * A per emitting side
    power.push_back(kPi * lum * area * (m.double_sided ? 2.0 : 1.0));
  }
  float bg[3] = {background.x, background.y, background.z};
  if (luminance(bg) > 0.0) {
    dev::Light l{};
    l.type = LIGHT_BACKGROUND;
    for (int c = 0; c < 3; ++c) l.radiance[c] = bg[c];
    table.lights.push_back(l);
    // Power of a constant environment through the scene's bounding sphere
    double r = std::max(double(bounds.radius()), 1e-6);
    power.push_back(4.0 * kPi * kPi * r * r * luminance(bg));
  }
  std::vector<double> pmf;
  table.thresholds = selection_thresholds(power, &pmf);
  for (size_t i = 0; i < table.lights.size(); ++i) table.lights[i].pmf = float(pmf[i]);
  return table;
}

}  // namespace candela
