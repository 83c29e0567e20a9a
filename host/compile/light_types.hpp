// What the host knows of each light type of CD_LIGHTS (cl/shared/device_types.h): its power,
// for light selection, and its bounds in the light tree (where it lies and which way it
// emits), or that it is no member of the tree. Each type has one function of each in
// light_types.cpp, light_power_NAME and light_bounds_NAME; the dispatch is generated from
// the list.
#pragma once

#include <glm/glm.hpp>
#include <limits>

#include "base/device_types.hpp"

namespace candela {

// Where a set of lights lies and which way it emits (Conty Estevez & Kulla 2018):
// positions in [lo, hi], emission axes within theta_o of `axis`, each light emitting within
// theta_e beyond its own axis, with their summed peak radiant intensity (luminance)
struct LightBounds {
  glm::vec3 lo{std::numeric_limits<float>::max()}, hi{-std::numeric_limits<float>::max()};
  double intensity = 0.0;
  glm::dvec3 axis{0.0, 0.0, 1.0};
  double theta_o = 0.0, theta_e = 0.0;
  bool empty() const { return !(intensity > 0.0) && lo.x > hi.x; }
  glm::vec3 centroid() const { return 0.5f * (lo + hi); }
};

// Emitted power of a light (luminance-weighted, for light selection). `emission_scale`
// is the mean luminance of a triangle light's emissive texture (1 without one), or an
// environment map's mean radiance luminance (strength included);
// `scene_radius` bounds the scene for environment lights.
double light_power(const dev::Light& light, const dev::SceneBuffers& buffers, double emission_scale,
                   double scene_radius);

// The light's bounds in the light tree, its intensity at least 1e-30 (a light the alias
// table can pick, the tree can too), `power` its light_power; false: the light is no member
// of the tree (a light at infinity)
bool light_bounds(const dev::Light& light, const dev::SceneBuffers& buffers, double power, LightBounds* bounds);

}  // namespace candela
