// Binned-SAH BVH over triangles, flattened for bvh_traverse.cl.
#pragma once

#include <vector>

#include "scene.hpp"

namespace candela {

struct Bvh {
  std::vector<dev::BvhNode> nodes;  // root at 0
  std::vector<uint32_t> order;  // order[i]: scene triangle stored at position i
  int depth = 0;
};

// The kernel's traversal stack holds BVH_STACK_SIZE (64) entries; the builder keeps
// the tree shallower than that.
constexpr int kMaxBvhDepth = 60;

Bvh build_bvh(const std::vector<SceneTriangle>& triangles);

// Device triangles in BVH order
std::vector<dev::Triangle> bvh_ordered_triangles(const std::vector<SceneTriangle>& triangles,
                                                 const Bvh& bvh);

}  // namespace candela
