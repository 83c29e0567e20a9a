// The light-selection table: every light with a selection probability proportional to
// its power, as 32-bit integer thresholds the kernel searches (lights.cl). Each light
// gets at least one of the 2^32 integers, and Light::pmf is its exact share.
#pragma once

#include <vector>

#include "scene.hpp"

namespace candela {

struct LightTable {
  std::vector<dev::Light> lights;
  std::vector<uint32_t> thresholds;  // n - 1 increasing values; the last (2^32) is implicit
};

// Thresholds for selecting index i with probability ~ weights[i] (all > 0); the exact
// probabilities realized are written to *pmf
std::vector<uint32_t> selection_thresholds(const std::vector<double>& weights,
                                           std::vector<double>* pmf);

// `triangles` in BVH order (Light::index refers to them); an emissive texture scales
// a light's power by its mean luminance (texture_means from Scene::emission_texture_means)
LightTable build_light_table(const std::vector<dev::Triangle>& triangles,
                             const std::vector<dev::Material>& materials,
                             const std::vector<double>& texture_means,
                             const glm::vec3& background, const Bounds& bounds);

}  // namespace candela
