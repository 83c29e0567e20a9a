#include "light_table.hpp"

#include <cmath>

namespace candela {
namespace {

constexpr double kPi = 3.14159265358979323846;

double luminance(const float* c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

}  // namespace

LightTable build_light_table(const std::vector<dev::Triangle>& triangles,
                             const std::vector<dev::Material>& materials,
                             const glm::vec3& background, const Bounds& bounds) {
  LightTable table;
  std::vector<double> power;
  for (size_t i = 0; i < triangles.size(); ++i) {
    const dev::Triangle& t = triangles[i];
    const dev::Material& m = materials[t.material];
    double lum = luminance(m.emission);
    if (!(lum > 0.0)) continue;
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
  double total = 0.0;
  for (double p : power) total += p;
  double acc = 0.0;
  for (double p : power) {
    acc += p;
    table.cdf.push_back(float(acc / total));
  }
  if (!table.cdf.empty()) table.cdf.back() = 1.0f;
  return table;
}

}  // namespace candela
