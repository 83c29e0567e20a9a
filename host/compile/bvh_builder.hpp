// Binned-SAH BVH over the scene's primitives, collapsed into a 4-wide BVH for
// bvh_traverse.cl. The node and leaf layout (BvhNode, BvhTriangle) is private to this
// file and bvh_traverse.cl: the rest of candela refers to triangles by their stable
// primitive index.
#pragma once

#include <glm/glm.hpp>
#include <vector>

#include "base/device_types.hpp"

namespace candela {

struct Bvh {
  UninitVector<dev::BvhNode> nodes;     // 4-wide, root at 0
  UninitVector<dev::BvhTriangle> tris;  // leaf triangles in BVH order, with their prim index
  int depth = 0;                        // of the binary SAH tree before collapsing (the 4-wide tree is half as deep)
};

// Depth limit of the binary SAH tree; it bounds the kernel's traversal stack
// (BVH_STACK_SIZE entries, 3 per 4-wide node on a path).
constexpr int kMaxBvhDepth = 60;

// `positions`: xyz per vertex; `prims`: vertex indices per primitive (stable order);
// `alpha_tested`: by Prim::material, whether hits on its triangles call the kernel's alpha
// test (BVH_TRI_ALPHA_TEST); empty for none. `threads`: 0 for bvh_build_threads(); the
// tree is the same for any thread count (the workers build disjoint subtrees). `poses` > 1
// (motion blur): `positions` holds that many poses a vertex (vertex v's pose s at v poses + s);
// a triangle's box bounds all of them and its leaf copy is pose 0.
Bvh build_bvh(const std::vector<float>& positions, const std::vector<dev::Prim>& prims,
              const std::vector<bool>& alpha_tested = {}, int threads = 0, int poses = 1);

// Threads build_bvh uses by default: CANDELA_BVH_THREADS when set (> 0), else every core
int bvh_build_threads();

// Surface-area-heuristic cost of the 4-wide tree, relative to one triangle test: 1 (the
// root) + the sum over child slots of (slot box area / root box area) x (1 for an inner
// node, the triangle count for a leaf). Lower is better; equal trees give equal costs.
double sah_cost(const Bvh& bvh);

}  // namespace candela
