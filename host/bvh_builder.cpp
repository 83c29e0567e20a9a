#include "bvh_builder.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "scene.hpp"

namespace candela {
namespace {

constexpr int kBins = 16;
constexpr int kMaxLeafSize = 8;
constexpr float kTraversalCost = 1.0f;  // relative to one triangle test
constexpr float kEmptyLo = 1e30f, kEmptyHi = -1e30f;  // an unused child slot's box

// Each 4-wide node on a path down pushes at most 3 entries, and the nodes sit two
// binary levels apart, at binary depths 1, 3, ..., below kMaxBvhDepth
static_assert(3 * (kMaxBvhDepth / 2) <= BVH_STACK_SIZE, "traversal stack too small for the depth limit");

float surface_area(const Bounds& b) {
  if (b.empty()) return 0.0f;
  glm::vec3 d = b.hi - b.lo;
  return 2.0f * (d.x * d.y + d.y * d.z + d.z * d.x);
}

// A primitive during the build: its box and stable index, partitioned in place so that
// binning reads memory in order
struct Ref {
  glm::vec3 lo;
  uint32_t prim;
  glm::vec3 hi;
  glm::vec3 centroid() const { return 0.5f * (lo + hi); }
};

// A range of refs with its bounds and its centroids' bounds; leaf once the SAH says so
struct Range {
  uint32_t begin = 0, end = 0;
  int depth = 1;  // of the binary SAH tree
  Bounds box, cbox;
  bool leaf = false;
};

class Builder {
 public:
  Builder(const std::vector<float>& positions, const std::vector<dev::Prim>& prims,
          const std::vector<bool>& alpha_tested)
      : positions_(positions), prims_(prims), alpha_tested_(alpha_tested) {
    refs_.resize(prims.size());
    for (size_t i = 0; i < prims.size(); ++i) {
      Bounds b;
      for (uint32_t v : prims[i].v) b.grow(vertex(v));
      refs_[i].lo = b.lo;
      refs_[i].hi = b.hi;
      refs_[i].prim = uint32_t(i);
    }
  }

  // The binary binned-SAH tree, collapsed as it is built: a 4-wide node's children are
  // its binary node's grandchildren (or a child that is a leaf)
  Bvh build() {
    Range root;
    root.end = uint32_t(refs_.size());
    for (const Ref& r : refs_) {
      root.box.grow(Bounds{r.lo, r.hi});
      root.cbox.grow(r.centroid());
    }
    bvh_.tris.resize(refs_.size());
    bvh_.nodes.reserve(refs_.size() / 4 + 1);
    bvh_.depth = 1;
    // The root is always a 4-wide node, with one leaf child when the root range is a leaf
    Range halves[2];
    if (root.end == 0) {
      bvh_.nodes.push_back(empty_node());
    } else if (!split(root, &halves[0], &halves[1])) {
      root.leaf = true;
      bvh_.nodes.push_back(empty_node());
      set_child(0, 0, root, leaf_ref(root));
    } else {
      root.leaf = false;
      inner_node(root, halves);
    }
    bvh_.nodes.shrink_to_fit();
    return std::move(bvh_);
  }

 private:
  glm::vec3 vertex(uint32_t v) const {
    return glm::vec3(positions_[3 * size_t(v)], positions_[3 * size_t(v) + 1], positions_[3 * size_t(v) + 2]);
  }

  static dev::BvhNode empty_node() {
    dev::BvhNode n{};
    for (int i = 0; i < 4; ++i) {
      n.lo_x[i] = n.lo_y[i] = n.lo_z[i] = kEmptyLo;
      n.hi_x[i] = n.hi_y[i] = n.hi_z[i] = kEmptyHi;
      n.child[i] = 0;  // the root: never anyone's child, never read
    }
    return n;
  }

  void set_child(uint32_t node, int slot, const Range& r, int ref) {
    dev::BvhNode& n = bvh_.nodes[node];
    n.lo_x[slot] = r.box.lo.x;
    n.lo_y[slot] = r.box.lo.y;
    n.lo_z[slot] = r.box.lo.z;
    n.hi_x[slot] = r.box.hi.x;
    n.hi_y[slot] = r.box.hi.y;
    n.hi_z[slot] = r.box.hi.z;
    n.child[slot] = ref;
  }

  // A leaf's triangles are final once it is made: write them, the last one flagged
  int leaf_ref(const Range& r) {
    bvh_.depth = std::max(bvh_.depth, r.depth);
    for (uint32_t i = r.begin; i < r.end; ++i) {
      uint32_t prim = refs_[i].prim;
      const dev::Prim& p = prims_[prim];
      dev::BvhTriangle& d = bvh_.tris[i];
      d = dev::BvhTriangle{};
      glm::vec3 v0 = vertex(p.v[0]), v1 = vertex(p.v[1]), v2 = vertex(p.v[2]);
      for (int a = 0; a < 3; ++a) {
        d.v0[a] = v0[a];
        d.v1[a] = v1[a];
        d.v2[a] = v2[a];
      }
      d.prim = prim;
      if (p.material < alpha_tested_.size() && alpha_tested_[p.material]) d.flags |= BVH_TRI_ALPHA_TEST;
      if (i + 1 == r.end) d.flags |= BVH_TRI_LAST;
    }
    return ~int(r.begin);
  }

  // A 4-wide node for range r, already split into `halves`; returns its index
  uint32_t inner_node(const Range& r, Range halves[2]) {
    bvh_.depth = std::max(bvh_.depth, r.depth);
    std::array<Range, 4> kids;
    int n = 0;
    for (int h = 0; h < 2; ++h) {
      Range a, b;
      if (split(halves[h], &a, &b)) {
        kids[n++] = a;
        kids[n++] = b;
      } else {
        halves[h].leaf = true;
        kids[n++] = halves[h];
      }
    }
    uint32_t node = uint32_t(bvh_.nodes.size());
    bvh_.nodes.push_back(empty_node());
    for (int i = 0; i < n; ++i) {
      int ref;
      Range sub[2];
      if (kids[i].leaf || !split(kids[i], &sub[0], &sub[1])) {
        ref = leaf_ref(kids[i]);
      } else {
        ref = int(inner_node(kids[i], sub));
      }
      set_child(node, i, kids[i], ref);  // bvh_.nodes may have grown: index, not a reference
    }
    return node;
  }

  // Binned SAH split of r into *left and *right (bounds included); false: r is a leaf
  bool split(const Range& r, Range* left, Range* right) {
    uint32_t count = r.end - r.begin;
    if (count <= 1 || r.depth >= kMaxBvhDepth) return false;
    // One pass bins the centroids along all three axes; small ranges get fewer bins (the
    // sweep over the bins costs as much as binning a few dozen triangles)
    int nbins = int(std::clamp<uint32_t>(count, 4, kBins));
    glm::vec3 lo = r.cbox.lo, extent = r.cbox.hi - r.cbox.lo;
    glm::vec3 scale;
    bool usable[3];
    for (int a = 0; a < 3; ++a) {
      scale[a] = float(nbins) / extent[a];
      // A flat or denormal extent cannot be binned
      usable[a] = extent[a] > 0.0f && std::isfinite(scale[a]);
      if (!usable[a]) scale[a] = 0.0f;
    }
    struct Bin {
      Bounds box;
      uint32_t count = 0;
    };
    std::array<std::array<Bin, kBins>, 3> bins;
    for (uint32_t i = r.begin; i < r.end; ++i) {
      const Ref& ref = refs_[i];
      glm::vec3 c = ref.centroid();
      for (int a = 0; a < 3; ++a) {
        Bin& bin = bins[a][bin_index(c[a], lo[a], scale[a], nbins)];
        bin.box.lo = glm::min(bin.box.lo, ref.lo);
        bin.box.hi = glm::max(bin.box.hi, ref.hi);
        bin.count++;
      }
    }
    int best_axis = -1, best_plane = 0;
    float best_cost = 1e30f;
    for (int a = 0; a < 3; ++a) {
      if (!usable[a]) continue;
      // Sweep: areas and counts left of each plane, then right
      std::array<float, kBins - 1> left_area, right_area;
      std::array<uint32_t, kBins - 1> left_count, right_count;
      Bounds acc;
      uint32_t c = 0;
      for (int i = 0; i < nbins - 1; ++i) {
        acc.grow(bins[a][i].box);
        c += bins[a][i].count;
        left_area[i] = surface_area(acc);
        left_count[i] = c;
      }
      acc = Bounds();
      c = 0;
      for (int i = nbins - 1; i > 0; --i) {
        acc.grow(bins[a][i].box);
        c += bins[a][i].count;
        right_area[i - 1] = surface_area(acc);
        right_count[i - 1] = c;
      }
      for (int i = 0; i < nbins - 1; ++i) {
        if (left_count[i] == 0 || right_count[i] == 0) continue;
        float cost = left_area[i] * left_count[i] + right_area[i] * right_count[i];
        if (cost < best_cost) {
          best_axis = a;
          best_plane = i;
          best_cost = cost;
        }
      }
    }
    float leaf_cost = float(count);
    float split_cost = kTraversalCost + best_cost / std::max(surface_area(r.box), 1e-30f);
    *left = Range();
    *right = Range();
    left->depth = right->depth = r.depth + 1;
    left->begin = r.begin;
    right->end = r.end;
    if (best_axis >= 0 && (split_cost < leaf_cost || count > kMaxLeafSize)) {
      // Partition by the same bin index as above, so that the bins' bounds are exact; the
      // sides' centroid bounds on the way
      int a = best_axis;
      float la = lo[a], sa = scale[a];
      uint32_t i = r.begin, j = r.end;
      while (true) {
        for (; i < j; ++i) {
          glm::vec3 c = refs_[i].centroid();
          if (bin_index(c[a], la, sa, nbins) > best_plane) break;
          left->cbox.grow(c);
        }
        for (; i < j; --j) {
          glm::vec3 c = refs_[j - 1].centroid();
          if (bin_index(c[a], la, sa, nbins) <= best_plane) break;
          right->cbox.grow(c);
        }
        if (i >= j) break;
        std::swap(refs_[i], refs_[j - 1]);
      }
      left->end = right->begin = i;
      for (int k = 0; k < nbins; ++k) (k <= best_plane ? left : right)->box.grow(bins[a][k].box);
      return true;
    }
    if (count <= kMaxLeafSize) return false;
    // All centroids coincide (or no useful plane): split the range in half
    left->end = right->begin = r.begin + count / 2;
    for (Range* side : {left, right})
      for (uint32_t i = side->begin; i < side->end; ++i) {
        side->box.grow(Bounds{refs_[i].lo, refs_[i].hi});
        side->cbox.grow(refs_[i].centroid());
      }
    return true;
  }

  static int bin_index(float c, float lo, float scale, int nbins) {
    return std::min(nbins - 1, std::max(0, int((c - lo) * scale)));
  }

  const std::vector<float>& positions_;
  const std::vector<dev::Prim>& prims_;
  const std::vector<bool>& alpha_tested_;
  std::vector<Ref> refs_;  // refs_[i]: primitive stored at leaf position i once built
  Bvh bvh_;
};

}  // namespace

Bvh build_bvh(const std::vector<float>& positions, const std::vector<dev::Prim>& prims,
              const std::vector<bool>& alpha_tested) {
  return Builder(positions, prims, alpha_tested).build();
}

}  // namespace candela
