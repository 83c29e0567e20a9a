// The light tree (Conty Estevez & Kulla 2018, Importance Sampling of Many Lights with
// Adaptive Tree Splitting) over a scene's finite lights: the LightTreeNode records the
// kernel descends to pick a light by its estimated contribution at the shading point, and
// each light's trail to its leaf (cl/shared/device_types.h, cl/lights/light_tree.cl).
#pragma once

#include <vector>

#include "base/device_types.hpp"

namespace candela {

struct LightTree {
  std::vector<dev::LightTreeNode> nodes;    // depth first, root at 0; empty: no tree
  std::vector<dev::LightTreeTrail> trails;  // one per light; depth LIGHT_TREE_NONE outside the tree
  int depth = 0;                            // of the deepest leaf
};

// The tree over the lights of `buffers.lights` that have bounds (light_bounds,
// light_types.hpp: the finite ones, triangles, points and spots); `power` is each
// light's light_power, `pmf` the probability the alias table picks it (the root's share is
// the sum over the tree's lights, exactly 1 when the tree holds every light: holds_all). Nodes are split where Conty &
// Kulla's surface area orientation heuristic is lowest over 12 buckets of the centroids on each axis. No tree (empty
// nodes) without finite lights.
LightTree build_light_tree(const dev::SceneBuffers& buffers, const std::vector<double>& power,
                           const std::vector<double>& pmf);

// Light selection by power alone: the tree left out (the kernel then picks every light
// through the alias table)
void drop_light_tree(dev::SceneBuffers* buffers);

}  // namespace candela
