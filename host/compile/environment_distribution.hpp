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

}  // namespace candela
