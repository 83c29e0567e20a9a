// The sampling distribution of an environment map, built by the compile step: the CDFs
// that cl/lights/environment.cl inverts to sample directions in proportion to radiance.
#pragma once

#include <vector>

#include "scene/scene.hpp"

namespace candela {

// Sampling CDFs of a map and their guide tables, laid out as cl/lights/environment.cl reads
// them: texel weights luminance x sin(theta at the row centre); every texel of positive
// luminance keeps a float CDF step > 0, so its pdf is > 0.
std::vector<float> environment_distribution(const TextureDesc& map);

// What the strategy choice (cl/integrator/integrator_path.cl) needs of a map, L its texel
// luminance: its effective solid angle (integral L)^2 / integral L^2 over the sphere (4 pi
// for a constant, the solid angle of the lit part for a map lit uniformly over part of the
// sphere), the direction its L^2 is centred on (turned by `rotation` radians about +Y as
// cl/lights/environment.cl maps it; zero where no direction dominates) and integral L.
struct EnvironmentExtent {
  double solid_angle = 0.0;
  double direction[3] = {0.0, 0.0, 0.0};
  double integral = 0.0;
};
EnvironmentExtent environment_extent(const TextureDesc& map, double rotation);

}  // namespace candela
