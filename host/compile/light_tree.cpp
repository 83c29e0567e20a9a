#include "compile/light_tree.hpp"

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <limits>
#include <numeric>

#include "base/error.hpp"
#include "compile/light_types.hpp"

namespace candela {
namespace {

constexpr double kPi = 3.14159265358979323846;

double angle_between(const glm::dvec3& a, const glm::dvec3& b) {
  return std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
}

// The smallest cone (Conty & Kulla's union of two bounding cones) holding both
LightBounds unite(LightBounds a, const LightBounds& b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  LightBounds u;
  u.lo = glm::min(a.lo, b.lo);
  u.hi = glm::max(a.hi, b.hi);
  u.intensity = a.intensity + b.intensity;
  u.theta_e = std::max(a.theta_e, b.theta_e);
  const LightBounds* wide = a.theta_o >= b.theta_o ? &a : &b;
  const LightBounds* narrow = wide == &a ? &b : &a;
  double theta_d = angle_between(wide->axis, narrow->axis);
  if (std::min(theta_d + narrow->theta_o, kPi) <= wide->theta_o) {
    u.axis = wide->axis;
    u.theta_o = wide->theta_o;
    return u;
  }
  double theta_o = 0.5 * (wide->theta_o + theta_d + narrow->theta_o);
  if (theta_o >= kPi) {
    u.axis = wide->axis;
    u.theta_o = kPi;
    return u;
  }
  // Turn the wide cone's axis toward the narrow one's by theta_o - wide.theta_o
  glm::dvec3 t = narrow->axis - glm::dot(narrow->axis, wide->axis) * wide->axis;
  double tl = glm::length(t);
  if (!(tl > 1e-12)) {  // opposite axes: any perpendicular
    t = std::abs(wide->axis.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    t -= glm::dot(t, wide->axis) * wide->axis;
    tl = glm::length(t);
  }
  double rot = theta_o - wide->theta_o;
  u.axis = glm::normalize(std::cos(rot) * wide->axis + std::sin(rot) * (t / tl));
  u.theta_o = theta_o;
  return u;
}

// Conty & Kulla's orientation measure: the solid angle the cone's emission reaches,
// weighted by the cosine to the nearest emission axis
double orientation_measure(const LightBounds& b) {
  double to = b.theta_o, tw = std::min(b.theta_o + b.theta_e, kPi);
  return 2.0 * kPi * (1.0 - std::cos(to)) +
         0.5 * kPi * (2.0 * tw * std::sin(to) - std::cos(to - 2.0 * tw) - 2.0 * to * std::sin(to) + std::cos(to));
}

double surface_area(const LightBounds& b) {
  glm::dvec3 d = glm::dvec3(b.hi) - glm::dvec3(b.lo);
  return 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
}

float cos_down(double theta) {  // float cosine no larger than the exact one: a cone never shrinks
  return std::nextafter(float(std::cos(theta)), -2.0f);
}

glm::dvec3 triangle_vertex(const dev::SceneBuffers& b, const dev::Light& l, int k) {
  size_t v = 3 * size_t(b.prims[l.index].v[k]);
  return {b.positions[v], b.positions[v + 1], b.positions[v + 2]};
}

// Twice the area of the convex hull of points in the plane (Andrew's monotone chain)
double hull_area(std::vector<glm::dvec2> p) {
  std::sort(p.begin(), p.end(),
            [](const glm::dvec2& a, const glm::dvec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  auto cross = [](const glm::dvec2& o, const glm::dvec2& a, const glm::dvec2& b) {
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
  };
  std::vector<glm::dvec2> h(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {  // lower hull
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0.0) --k;
    h[k++] = p[i];
  }
  for (size_t i = p.size() - 1, t = k + 1; i-- > 0;) {  // upper hull
    while (k >= t && cross(h[k - 2], h[k - 1], p[i]) <= 0.0) --k;
    h[k++] = p[i];
  }
  double area = 0.0;
  for (size_t i = 0; i + 1 < k; ++i) area += h[i].x * h[i + 1].y - h[i + 1].x * h[i].y;
  return std::abs(area);
}

// Fraction of the convex hull of their vertices (in their plane) that the triangles cover
// at least, for a cluster to be one emitter: a quad's two triangles or a disc's fan cover it
// all; two square lamps one lamp's width apart cover half
constexpr double kClusterCover = 0.75;

// A node of the binary tree the builder splits, before it is made four wide
constexpr uint32_t kCluster = 2u;  // interior node inside a planar emitter
struct BinaryNode {
  LightBounds bounds;
  uint32_t next = 0;                    // interior: the second child (the first follows the node); leaf: its light
  uint32_t kind = LIGHT_TREE_INTERIOR;  // LIGHT_TREE_INTERIOR, LIGHT_TREE_LEAF or kCluster
};

// Makes the binary tree four wide: a node's children are its binary children, each replaced
// by its own two (and so on, level by level, while the four slots last) when it is of the
// node's kind, interior or cluster: a cluster is never opened by an interior node and
// weighed lane by lane, and a leaf stays a leaf. Writes each light's trail.
struct Widener {
  const std::vector<BinaryNode>& binary;
  LightTree* tree;

  uint32_t widen(uint32_t b, const dev::LightTreeTrail& trail) {
    uint32_t index = uint32_t(tree->nodes.size());
    tree->nodes.emplace_back();
    tree->depth = std::max(tree->depth, int(trail.depth) + 1);
    uint32_t kind = binary[b].kind;
    // Open children of the node's kind level by level while the slots last
    std::vector<uint32_t> children{b + 1, binary[b].next};
    for (bool opened = true; opened && children.size() < LIGHT_TREE_WIDTH;) {
      opened = false;
      for (size_t i = 0; i < children.size() && children.size() < LIGHT_TREE_WIDTH;) {
        uint32_t c = children[i];
        if (binary[c].kind != kind) {
          ++i;
          continue;
        }
        children[i] = c + 1;
        children.insert(children.begin() + long(i) + 1, binary[c].next);
        opened = true;
        i += 2;
      }
    }
    tree->nodes[index].cluster = kind == kCluster ? 1u : 0u;
    for (uint32_t slot = 0; slot < children.size(); ++slot) {
      const BinaryNode& c = binary[children[slot]];
      write(index, slot, c.bounds);
      dev::LightTreeTrail t = trail;
      t.bits[t.depth >> 4] |= slot << (2u * (t.depth & 15u));
      ++t.depth;
      if (c.kind == LIGHT_TREE_LEAF) {
        tree->nodes[index].leaf[slot] = LIGHT_TREE_LEAF;
        tree->nodes[index].child[slot] = c.next;
        tree->trails[c.next] = t;
      } else {
        uint32_t child = widen(children[slot], t);
        tree->nodes[index].leaf[slot] = LIGHT_TREE_INTERIOR;
        tree->nodes[index].child[slot] = child;
      }
    }
    return index;
  }

  void write(uint32_t index, uint32_t slot, const LightBounds& b) {
    dev::LightTreeNode& n = tree->nodes[index];
    // The sphere about the box's centre (as rounded to float) through its farthest corner,
    // its radius rounded up: it holds the box
    glm::vec3 centre = b.centroid();
    double r2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      double far = std::max(double(centre[k]) - double(b.lo[k]), double(b.hi[k]) - double(centre[k]));
      r2 += far * far;
    }
    for (int k = 0; k < 3; ++k) {
      n.centre[k][slot] = centre[k];
      n.axis[k][slot] = float(b.axis[k]);
    }
    n.radius[slot] = r2 > 0.0 ? std::nextafter(float(std::sqrt(r2)), INFINITY) : 0.0f;
    float intensity = float(std::min(b.intensity, double(std::numeric_limits<float>::max())));
    n.intensity[slot] = std::max(intensity, std::numeric_limits<float>::min());
    n.cos_o[slot] = b.theta_o >= kPi ? -1.0f : cos_down(b.theta_o);
    // The sine of the angle whose cosine is stored (that angle, not theta_o, is the cone)
    double c = double(n.cos_o[slot]);
    n.sin_o[slot] = float(std::sqrt(std::max(1.0 - c * c, 0.0)));
    n.cos_e[slot] = cos_down(b.theta_e);
  }
};

struct Builder {
  const dev::SceneBuffers& buffers;
  const std::vector<LightBounds>& bounds;
  std::vector<uint32_t>& order;   // light indices, partitioned in place
  std::vector<BinaryNode> nodes;  // depth first, a node's first child right after it

  // Whether lights order[begin, end) make one planar emitter: triangles in one plane, all
  // single-sided facing one way or all double-sided, that cover at least kClusterCover of
  // their convex hull. Importance barely tells such lights apart from any point the emitter
  // lights, so the tree picks among them by power alone (cluster nodes).
  bool planar_emitter(size_t begin, size_t end) const {
    const dev::Light& first = buffers.lights[order[begin]];
    if (first.type != LIGHT_TRIANGLE) return false;
    const glm::dvec3 n = bounds[order[begin]].axis, p0 = triangle_vertex(buffers, first, 0);
    glm::dvec3 extent = glm::dvec3(bounds[order[begin]].hi) - glm::dvec3(bounds[order[begin]].lo);
    for (size_t i = begin; i < end; ++i) extent = glm::max(extent, glm::dvec3(bounds[order[i]].hi) - p0);
    const double tolerance = 1e-5 * std::max(glm::length(extent), 1e-30);
    // The plane's frame (Duff et al. 2017's orthonormal basis)
    double sign = std::copysign(1.0, n.z), a = -1.0 / (sign + n.z), bxy = n.x * n.y * a;
    glm::dvec3 t(1.0 + sign * n.x * n.x * a, sign * bxy, -sign * n.x), s(bxy, sign + n.y * n.y * a, -n.y);
    std::vector<glm::dvec2> points;
    points.reserve(3 * (end - begin));
    double area = 0.0;
    for (size_t i = begin; i < end; ++i) {
      const dev::Light& l = buffers.lights[order[i]];
      const LightBounds& lb = bounds[order[i]];
      if (l.type != LIGHT_TRIANGLE || lb.theta_o != bounds[order[begin]].theta_o) return false;
      double facing = glm::dot(lb.axis, n);
      if ((lb.theta_o == 0.0 ? facing : std::abs(facing)) < 1.0 - 1e-9) return false;
      for (int k = 0; k < 3; ++k) {
        glm::dvec3 d = triangle_vertex(buffers, l, k) - p0;
        if (std::abs(glm::dot(d, n)) > tolerance) return false;
        points.emplace_back(glm::dot(d, t), glm::dot(d, s));
      }
      area += 2.0 * double(l.params.triangle.area);
    }
    return area >= kClusterCover * hull_area(std::move(points));
  }

  // Builds the binary subtree over order[begin, end) at `depth`; returns its bounds.
  // `cluster`: the lights are part of one planar emitter (planar_emitter).
  LightBounds build(size_t begin, size_t end, uint32_t depth, bool cluster = false) {
    size_t index = nodes.size();
    nodes.emplace_back();
    if (end - begin == 1) {
      nodes[index] = BinaryNode{bounds[order[begin]], order[begin], LIGHT_TREE_LEAF};
      return bounds[order[begin]];
    }
    if (depth + 1 >= LIGHT_TREE_MAX_DEPTH) throw Error("light tree deeper than LIGHT_TREE_MAX_DEPTH");
    cluster = cluster || planar_emitter(begin, end);
    size_t mid = split(begin, end, depth);
    LightBounds a = build(begin, mid, depth + 1, cluster);
    uint32_t second = uint32_t(nodes.size());
    LightBounds b = build(mid, end, depth + 1, cluster);
    nodes[index] = BinaryNode{unite(a, b), second, cluster ? kCluster : LIGHT_TREE_INTERIOR};
    return nodes[index].bounds;
  }

  // Where to split order[begin, end): the lowest-cost bucket boundary, or the median along
  // the widest centroid axis when no cost separates them (or the tree grows deep)
  size_t split(size_t begin, size_t end, uint32_t depth) {
    glm::vec3 clo(std::numeric_limits<float>::max()), chi(-std::numeric_limits<float>::max());
    LightBounds all;
    for (size_t i = begin; i < end; ++i) {
      glm::vec3 c = bounds[order[i]].centroid();
      clo = glm::min(clo, c);
      chi = glm::max(chi, c);
      all = unite(all, bounds[order[i]]);
    }
    glm::vec3 ext = chi - clo;
    int widest = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    constexpr int kBuckets = 12;
    double best = std::numeric_limits<double>::infinity();
    int best_axis = -1, best_bucket = -1;
    glm::dvec3 box = glm::dvec3(all.hi) - glm::dvec3(all.lo);
    double box_max = std::max(box.x, std::max(box.y, box.z));
    if (depth < 40) {
      for (int axis = 0; axis < 3; ++axis) {
        if (!(ext[axis] > 0.0f)) continue;
        LightBounds bucket[kBuckets];
        for (size_t i = begin; i < end; ++i)
          bucket[bucket_of(order[i], axis, clo, ext)] =
              unite(bucket[bucket_of(order[i], axis, clo, ext)], bounds[order[i]]);
        // Costs of the kBuckets - 1 boundaries: sweep from above, then from below
        double right_cost[kBuckets] = {};
        LightBounds acc;
        for (int k = kBuckets - 1; k > 0; --k) {
          acc = unite(acc, bucket[k]);
          right_cost[k] = acc.empty() ? 0.0 : acc.intensity * surface_area(acc) * orientation_measure(acc);
        }
        double kr = box_max / std::max(box[axis], 1e-30);  // Conty & Kulla's penalty on thin splits
        acc = LightBounds();
        for (int k = 0; k + 1 < kBuckets; ++k) {
          acc = unite(acc, bucket[k]);
          double left = acc.empty() ? 0.0 : acc.intensity * surface_area(acc) * orientation_measure(acc);
          double cost = kr * (left + right_cost[k + 1]);
          if (cost < best) {
            best = cost;
            best_axis = axis;
            best_bucket = k;
          }
        }
      }
    }
    if (best_axis >= 0 && best > 0.0) {
      auto mid = std::partition(order.begin() + long(begin), order.begin() + long(end),
                                [&](uint32_t l) { return bucket_of(l, best_axis, clo, ext) <= best_bucket; });
      size_t m = size_t(mid - order.begin());
      if (m > begin && m < end) return m;
    }
    size_t m = begin + (end - begin) / 2;
    std::nth_element(
        order.begin() + long(begin), order.begin() + long(m), order.begin() + long(end),
        [&](uint32_t x, uint32_t y) { return bounds[x].centroid()[widest] < bounds[y].centroid()[widest]; });
    return m;
  }

  int bucket_of(uint32_t light, int axis, const glm::vec3& clo, const glm::vec3& ext) const {
    float t = (bounds[light].centroid()[axis] - clo[axis]) / ext[axis];
    return std::clamp(int(t * 12.0f), 0, 11);
  }
};

}  // namespace

LightTree build_light_tree(const dev::SceneBuffers& buffers, const std::vector<double>& power,
                           const std::vector<double>& pmf) {
  LightTree tree;
  dev::LightTreeTrail none_trail{};
  none_trail.depth = LIGHT_TREE_NONE;
  tree.trails.assign(buffers.lights.size(), none_trail);
  std::vector<LightBounds> bounds(buffers.lights.size());
  std::vector<uint32_t> order;
  double share = 0.0;
  for (size_t i = 0; i < buffers.lights.size(); ++i) {
    if (!light_bounds(buffers.lights[i], buffers, power[i], &bounds[i])) continue;  // a light at infinity
    order.push_back(uint32_t(i));
    share += pmf[i];
  }
  if (order.empty()) return tree;
  Builder builder{buffers, bounds, order, {}};
  builder.build(0, order.size(), 0u);
  // One light, or one planar emitter: the tree would pick as the alias table does, by power
  if (builder.nodes[0].kind != LIGHT_TREE_INTERIOR) return tree;
  Widener{builder.nodes, &tree}.widen(0, dev::LightTreeTrail{});
  // Every light in the tree: the alias table's draw has nothing left to decide
  tree.nodes[0].holds_all = order.size() == buffers.lights.size() ? 1u : 0u;
  tree.nodes[0].share = tree.nodes[0].holds_all ? 1.0f : float(std::min(share, 1.0));
  // Least weight of a child, as a fraction of the sum of the importances, min_prob (at most
  // about 6, where q nears 0.24): after it a child gets at least
  // q = min_prob / (1 + 4 min_prob); q^depth x share >= 2^-124 (a normal float), with a
  // margin for rounding. A tree too deep for any floor to keep that (q near 1/4: some 60
  // levels) is not used: selection by power instead.
  double q = std::pow(std::ldexp(1.0, -124) / double(tree.nodes[0].share), 1.0 / double(tree.depth));
  if (!(q < 0.24)) {
    LightTree none;
    none.trails.assign(buffers.lights.size(), none_trail);
    return none;
  }
  tree.nodes[0].min_prob = float(1.001 * q / (1.0 - 4.0 * q));
  return tree;
}

void drop_light_tree(dev::SceneBuffers* buffers) {
  buffers->light_tree.clear();
  buffers->light_trails.clear();
}

}  // namespace candela
