// Environment maps on the host: equirectangular images read through OpenImageIO, the
// built-in sky that lights scenes without any light, and their mean radiance. The sampling
// distribution is the compile step's (compile/environment_distribution.hpp).
#pragma once

#include <string>
#include <vector>

#include "scene/scene.hpp"

namespace candela {

// An equirectangular image (.hdr, .exr, .png, .jpg, anything OpenImageIO reads) as linear
// float RGBA texels with alpha 1. One channel is grey; 8- and 16-bit integer images are
// decoded from sRGB unless the file says it is linear; negative and non-finite values
// become 0. Throws Error when the file is missing, unreadable, empty or over 1 GiB as float RGBA.
TextureDesc load_environment_image(const std::string& path);

// The map of `path` with its strength and rotation (degrees); Error as above, and for a
// negative or non-finite strength or rotation
EnvironmentDesc load_environment(const std::string& path, float strength, float rotation);

// The built-in sky, 64 x 32 texels, each the radiance at its centre's height y = cos(theta):
//   sky (y >= 0):    (1, 1, 1) + y (0.1, 0.25, 0.6)  (1 at the horizon, bluish-white zenith)
//   ground (y < 0):  g + (1 - g) exp(y / 0.1), g = (0.4, 0.35, 0.3)  (darker, warm)
EnvironmentDesc builtin_sky();

// The note printed when a scene without light gets the built-in sky
extern const char* const kBuiltinSkyNote;

// Mean luminance of the radiance over the sphere (texels weighted by solid angle)
double environment_mean_luminance(const TextureDesc& map);

}  // namespace candela
