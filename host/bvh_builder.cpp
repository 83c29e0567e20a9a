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

float surface_area(const Bounds& b) {
  if (b.empty()) return 0.0f;
  glm::vec3 d = b.hi - b.lo;
  return 2.0f * (d.x * d.y + d.y * d.z + d.z * d.x);
}

class Builder {
 public:
  Builder(const std::vector<float>& positions, const std::vector<dev::Prim>& prims)
      : positions_(positions), prims_(prims) {
    size_t n = prims.size();
    boxes_.resize(n);
    centroids_.resize(n);
    for (size_t i = 0; i < n; ++i) {
      for (uint32_t v : prims[i].v) boxes_[i].grow(vertex(v));
      centroids_[i] = boxes_[i].center();
    }
    order_.resize(n);
    for (size_t i = 0; i < n; ++i) order_[i] = uint32_t(i);
  }

  Bvh build() {
    bvh_.nodes.reserve(2 * order_.size());
    bvh_.nodes.emplace_back();
    build_node(0, 0, uint32_t(order_.size()), 1);
    leaf_triangles();
    return std::move(bvh_);
  }

 private:
  struct Split {
    int axis = -1;
    float position = 0.0f;
    float cost = 1e30f;
  };

  glm::vec3 vertex(uint32_t v) const {
    return glm::vec3(positions_[3 * size_t(v)], positions_[3 * size_t(v) + 1], positions_[3 * size_t(v) + 2]);
  }

  // Leaf triangles in BVH order, each with its primitive index
  void leaf_triangles() {
    bvh_.tris.resize(order_.size());
    for (size_t i = 0; i < order_.size(); ++i) {
      const dev::Prim& p = prims_[order_[i]];
      dev::BvhTriangle& d = bvh_.tris[i];
      d = dev::BvhTriangle{};
      glm::vec3 v0 = vertex(p.v[0]), v1 = vertex(p.v[1]), v2 = vertex(p.v[2]);
      for (int a = 0; a < 3; ++a) {
        d.v0[a] = v0[a];
        d.v1[a] = v1[a];
        d.v2[a] = v2[a];
      }
      d.prim = order_[i];
    }
  }

  Bounds range_bounds(uint32_t begin, uint32_t end, bool centroids) const {
    Bounds b;
    for (uint32_t i = begin; i < end; ++i) {
      uint32_t t = order_[i];
      if (centroids)
        b.grow(centroids_[t]);
      else
        b.grow(boxes_[t]);
    }
    return b;
  }

  // Best SAH split of [begin, end) over kBins centroid bins per axis
  Split find_split(uint32_t begin, uint32_t end, const Bounds& cbounds) const {
    Split best;
    for (int axis = 0; axis < 3; ++axis) {
      float lo = cbounds.lo[axis], hi = cbounds.hi[axis];
      if (!(hi > lo)) continue;
      float scale = kBins / (hi - lo);
      if (!std::isfinite(scale)) continue;  // a denormal extent cannot be binned: as if flat
      std::array<Bounds, kBins> bins;
      std::array<uint32_t, kBins> counts{};
      for (uint32_t i = begin; i < end; ++i) {
        uint32_t t = order_[i];
        int b = std::min(kBins - 1, int((centroids_[t][axis] - lo) * scale));
        bins[b].grow(boxes_[t]);
        counts[b]++;
      }
      // Sweep: areas and counts left of each plane, then right
      std::array<float, kBins - 1> left_area, right_area;
      std::array<uint32_t, kBins - 1> left_count, right_count;
      Bounds acc;
      uint32_t c = 0;
      for (int i = 0; i < kBins - 1; ++i) {
        acc.grow(bins[i]);
        c += counts[i];
        left_area[i] = surface_area(acc);
        left_count[i] = c;
      }
      acc = Bounds();
      c = 0;
      for (int i = kBins - 1; i > 0; --i) {
        acc.grow(bins[i]);
        c += counts[i];
        right_area[i - 1] = surface_area(acc);
        right_count[i - 1] = c;
      }
      for (int i = 0; i < kBins - 1; ++i) {
        if (left_count[i] == 0 || right_count[i] == 0) continue;
        float cost = left_area[i] * left_count[i] + right_area[i] * right_count[i];
        if (cost < best.cost) {
          best.axis = axis;
          best.position = lo + (i + 1) / scale;
          best.cost = cost;
        }
      }
    }
    return best;
  }

  void make_leaf(uint32_t node, uint32_t begin, uint32_t end) {
    bvh_.nodes[node].left = int(begin);
    bvh_.nodes[node].right = -int(end - begin);
  }

  void build_node(uint32_t node, uint32_t begin, uint32_t end, int depth) {
    Bounds box = range_bounds(begin, end, false);
    for (int a = 0; a < 3; ++a) {
      bvh_.nodes[node].bmin[a] = box.lo[a];
      bvh_.nodes[node].bmax[a] = box.hi[a];
    }
    bvh_.depth = std::max(bvh_.depth, depth);
    uint32_t count = end - begin;
    if (count <= 1 || depth >= kMaxBvhDepth) return make_leaf(node, begin, end);

    Bounds cbounds = range_bounds(begin, end, true);
    Split split = find_split(begin, end, cbounds);
    float leaf_cost = float(count);
    float split_cost = kTraversalCost + split.cost / std::max(surface_area(box), 1e-30f);
    uint32_t mid;
    if (split.axis >= 0 && (split_cost < leaf_cost || count > kMaxLeafSize)) {
      auto it = std::partition(order_.begin() + begin, order_.begin() + end,
                               [&](uint32_t t) { return centroids_[t][split.axis] < split.position; });
      mid = uint32_t(it - order_.begin());
    } else if (count > kMaxLeafSize) {
      // All centroids coincide (or no useful plane): split the range in half
      mid = begin + count / 2;
    } else {
      return make_leaf(node, begin, end);
    }
    if (mid == begin || mid == end) mid = begin + count / 2;

    uint32_t left = uint32_t(bvh_.nodes.size());
    bvh_.nodes.emplace_back();
    bvh_.nodes.emplace_back();
    bvh_.nodes[node].left = int(left);
    bvh_.nodes[node].right = int(left + 1);
    build_node(left, begin, mid, depth + 1);
    build_node(left + 1, mid, end, depth + 1);
  }

  const std::vector<float>& positions_;
  const std::vector<dev::Prim>& prims_;
  std::vector<uint32_t> order_;  // order_[i]: primitive stored at leaf position i
  std::vector<Bounds> boxes_;
  std::vector<glm::vec3> centroids_;
  Bvh bvh_;
};

}  // namespace

Bvh build_bvh(const std::vector<float>& positions, const std::vector<dev::Prim>& prims,
              const std::vector<bool>& alpha_tested) {
  Bvh bvh = Builder(positions, prims).build();
  for (dev::BvhTriangle& t : bvh.tris) {
    uint32_t material = prims[t.prim].material;
    if (material < alpha_tested.size() && alpha_tested[material]) t.flags |= BVH_TRI_ALPHA_TEST;
  }
  return bvh;
}

}  // namespace candela
