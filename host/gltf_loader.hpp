// glTF 2.0 (.gltf / .glb) scene loading through tinygltf.
#pragma once

#include <string>

#include "scene.hpp"

namespace candela {

// Loads the default scene (or the first) with node transforms applied. Throws Error
// on a missing or malformed file; unsupported features land in Scene::warnings.
Scene load_gltf(const std::string& path);

}  // namespace candela
