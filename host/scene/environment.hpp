// Environment maps on the host: equirectangular images read through OpenImageIO, the
// built-in studio that lights scenes without light of their own, and their mean radiance.
// The sampling distribution is the compile step's (compile/environment_distribution.hpp).
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

// The built-in environment that lights scenes without light of their own (the default light,
// scene/default_light.hpp): a neutral grey studio, 512 x 256 texels looked up bilinearly.
// Radiance 0.55 at the horizon to 0.85 overhead, a floor of 0.18 below a soft horizon
// (blended from 12 degrees below to 5 above), and three soft lights: a key (peak 4.6, about 10 degrees wide) in front,
// left and above, a fill (2, right) and a rim light (3, behind); mean radiance about 0.5.
EnvironmentDesc builtin_environment();

// Mean luminance of the radiance over the sphere (texels weighted by solid angle)
double environment_mean_luminance(const TextureDesc& map);

}  // namespace candela
