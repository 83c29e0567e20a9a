// The compile step: turns the host scene description (scene.hpp) into the device
// records of every scene buffer (CD_SCENE_BUFFERS), built once and shared by every
// device that renders the scene.
#pragma once

#include <functional>
#include <vector>

#include "compile/compiled_scene.hpp"
#include "compile/light_types.hpp"  // light_power
#include "scene/scene.hpp"

namespace candela {

// Called by compile_scene once the kernel features are final (after the lights and their
// light tree, before the BVH), with the scene compiled so far: the kernel can be built
// while the rest compiles
using FeaturesKnown = std::function<void(const CompiledScene&)>;

CompiledScene compile_scene(const Scene& scene, const FeaturesKnown& features_known = {});
// With kernel features that include the scene's (e.g. SceneFeatures::all(), the generic
// kernel of --generic): the optional vertex arrays of every feature on are filled, with
// the defaults where a mesh has none. Throws Error when `features` lack one the scene needs.
CompiledScene compile_scene(const Scene& scene, const SceneFeatures& features,
                            const FeaturesKnown& features_known = {});

// The device record of a punctual light: its type (LIGHT_POINT, LIGHT_SPOT or
// LIGHT_DIRECTIONAL) and parameters (PointLight, SpotLight, DirectionalLight)
dev::Light punctual_light(const PunctualLightDesc& p);

// Alias table (Walker 1977, Vose 1991) for selecting index i with probability ~ weights[i]
// (all > 0) from a uniform 32-bit integer (sample_discrete_alias in sampling.cl); the exact
// probabilities it realizes go to *pmf. Each index gets at least one of the 2^32 integers.
std::vector<dev::AliasBin> alias_table(const std::vector<double>& weights, std::vector<double>* pmf);

}  // namespace candela
