// The sampling distribution of an environment map, built by the compile step: the CDFs
// that cl/lights/environment.cl inverts to sample directions in proportion to radiance.
#pragma once

#include <vector>

#include "scene/scene.hpp"

namespace candela {

// Sampling CDFs of a map, laid out as cl/lights/environment.cl reads them: texel weights
// luminance x sin(theta at the row centre); every texel of positive luminance keeps a
// float CDF step > 0, so its pdf is > 0.
std::vector<float> environment_distribution(const TextureDesc& map);

// The map's effective solid angle (integral L)^2 / integral L^2 over the sphere, L its
// luminance: 4 pi for a constant, the solid angle of the lit part for a map lit uniformly
// over part of the sphere. The strategy choice reads it (cl/integrator/integrator_path.cl).
double environment_solid_angle(const TextureDesc& map);

}  // namespace candela
