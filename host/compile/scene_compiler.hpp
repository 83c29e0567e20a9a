// The compile step: turns the host scene description (scene.hpp) into the device
// records of every scene buffer (CD_SCENE_BUFFERS), built once and shared by every
// device that renders the scene.
#pragma once

#include <vector>

#include "scene/scene.hpp"

namespace candela {

// A density grid as the device holds it (--stats)
struct GridMemory {
  std::string source;  // "dense" (an inline grid) or the NanoVDB/OpenVDB file and grid
  size_t grid_bytes = 0;  // the NanoVDB buffer, or the dense values
  size_t majorant_bytes = 0;  // its majorant cells
};

struct CompiledScene {
  dev::SceneBuffers buffers;
  std::vector<GridMemory> grids;  // one per grid medium, each grid stored once
  SceneFeatures features;
  CameraDesc camera;  // resolved: the scene's, or one framing it
  int environment_light = NO_LIGHT;  // index into buffers.lights
  size_t triangles = 0, vertices = 0;
  int bvh_depth = 0;
  double bvh_build_seconds = 0.0;
  double bvh_sah_cost = 0.0;  // sah_cost of the BVH (bvh_builder.hpp)
  double compile_seconds = 0.0;  // everything, the BVH included
  size_t device_bytes = 0;  // buffers.bytes() as compiled (kept by release_host_arrays)

  // Frees the host copies of the scene buffers, `lights` aside (Renderer::lights), once
  // every device has its own: they are most of the host memory a large mesh takes
  void release_host_arrays();
};

CompiledScene compile_scene(const Scene& scene);
// With kernel features that include the scene's (e.g. SceneFeatures::all(), the generic
// kernel of --generic): the optional vertex arrays of every feature on are filled, with
// the defaults where a mesh has none. Throws Error when `features` lack one the scene needs.
CompiledScene compile_scene(const Scene& scene, const SceneFeatures& features);

// Alias table (Walker 1977, Vose 1991) for selecting index i with probability ~ weights[i]
// (all > 0) from a uniform 32-bit integer (sample_discrete_alias in sampling.cl); the exact
// probabilities it realizes go to *pmf. Each index gets at least one of the 2^32 integers.
std::vector<dev::AliasBin> alias_table(const std::vector<double>& weights, std::vector<double>* pmf);

// Emitted power of a light (luminance-weighted, for light selection). `emission_scale`
// is the mean luminance of a triangle light's emissive texture (1 without one), or an
// environment map's mean radiance luminance (strength included);
// `scene_radius` bounds the scene for environment lights.
double light_power(const dev::Light& light, const dev::SceneBuffers& buffers,
                   double emission_scale, double scene_radius);

}  // namespace candela
