// The compiled scene as the render layer takes it: the device records of every scene buffer
// (CD_SCENE_BUFFERS) and what was measured building them; compile_scene (scene_compiler.hpp)
// makes it from the scene description.
#pragma once

#include <string>
#include <vector>

#include "base/device_types.hpp"
#include "base/scene_features.hpp"

namespace candela {

// A density grid as the device holds it (--stats)
struct GridMemory {
  std::string source;         // "dense" (an inline grid) or the NanoVDB/OpenVDB file and grid
  size_t grid_bytes = 0;      // the NanoVDB buffer, or the dense values
  size_t majorant_bytes = 0;  // its majorant cells
};

struct CompiledScene {
  dev::SceneBuffers buffers;
  std::vector<GridMemory> grids;  // one per grid medium, each grid stored once
  SceneFeatures features;
  int environment_light = NO_LIGHT;  // index into buffers.lights
  size_t triangles = 0, vertices = 0;
  int bvh_depth = 0;
  double bvh_build_seconds = 0.0;
  double bvh_sah_cost = 0.0;     // sah_cost of the BVH (bvh_builder.hpp)
  double compile_seconds = 0.0;  // everything, the BVH included
  size_t device_bytes = 0;       // buffers.bytes() as compiled (kept by release_host_arrays)

  // Frees the host copies of the scene buffers, `lights` aside (Renderer::lights), once
  // every device has its own: they are most of the host memory a large mesh takes
  void release_host_arrays();
};

}  // namespace candela
