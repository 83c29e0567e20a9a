// The light-selection table: every light with a selection probability proportional to
// its power, as a CDF the kernel searches (lights.cl).
#pragma once

#include <vector>

#include "scene.hpp"

namespace candela {

struct LightTable {
  std::vector<dev::Light> lights;
  std::vector<float> cdf;  // cdf[i] = P(light <= i); cdf.back() == 1
};

// `triangles` in BVH order (Light::index refers to them)
LightTable build_light_table(const std::vector<dev::Triangle>& triangles,
                             const std::vector<dev::Material>& materials,
                             const glm::vec3& background, const Bounds& bounds);

}  // namespace candela
