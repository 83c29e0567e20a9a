#include "compile/bvh_builder.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <thread>

#include "compile/bvh_sah.hpp"

namespace candela {
namespace {

using namespace bvh_build;

// The top phase hands subtrees of at most max(kMinJobRefs, refs / kJobsPerTree) refs to
// the workers: independent of the thread count, so that the tree (node order included) is
// the same for any thread count
constexpr uint32_t kMinJobRefs = 4096;
constexpr size_t kJobsPerTree = 128;

// Each 4-wide node on a path down pushes at most 3 entries, and the nodes sit two
// binary levels apart, at binary depths 1, 3, ..., below kMaxBvhDepth
static_assert(3 * (kMaxBvhDepth / 2) <= BVH_STACK_SIZE, "traversal stack too small for the depth limit");

// 4-wide nodes of one subtree (the top of the tree, or one worker's job): child
// references inside it are indices into `nodes`, relocated when the subtrees are joined
struct Subtree {
  UninitVector<dev::BvhNode> nodes;
  int depth = 1;
};

// A subtree the top phase leaves to the workers: range r (not a leaf), which becomes the
// child in `slot` of top node `node`
struct Job {
  Range r;
  uint32_t node = 0;
  int slot = 0;
  Subtree out;
  int ref = 0;  // the job's root reference within out
};

class Builder {
 public:
  Builder(const std::vector<float>& positions, const std::vector<dev::Prim>& prims,
          const std::vector<bool>& alpha_tested, int threads, int poses)
      : positions_(positions),
        prims_(prims),
        alpha_tested_(alpha_tested),
        threads_(std::max(1, threads)),
        poses_(size_t(std::max(1, poses))) {
    refs_.resize(prims.size());
    parallel_for(prims.size(), [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) {
        const dev::Prim& p = prims[i];
        v4f a = vertex(p.v[0]), b = vertex(p.v[1]), c = vertex(p.v[2]);
        Ref& r = refs_[i];
        r.lo = vmin(vmin(a, b), c);
        r.hi = vmax(vmax(a, b), c);
        for (size_t s = 1; s < poses_; ++s)
          for (int k = 0; k < 3; ++k) {
            v4f q = vertex(p.v[k], s);
            r.lo = vmin(r.lo, q);
            r.hi = vmax(r.hi, q);
          }
        uint32_t prim = uint32_t(i);
        std::memcpy(reinterpret_cast<char*>(&r.lo) + 12, &prim, 4);
      }
    });
  }

  // The binary binned-SAH tree, collapsed as it is built: a 4-wide node's children are
  // its binary node's grandchildren (or a child that is a leaf). The top of the tree is
  // built first, down to subtrees small enough to share out; the workers build those,
  // and their nodes follow the top's, in the top's depth-first order. The result does
  // not depend on the thread count.
  Bvh build() {
    Range root;
    root.end = uint32_t(refs_.size());
    {
      std::vector<std::array<v4f, 4>> part(size_t(threads_),
                                           {vec(Bounds().lo), vec(Bounds().hi), vec(Bounds().lo), vec(Bounds().hi)});
      parallel_for_indexed(refs_.size(), [&](int t, size_t begin, size_t end) {
        std::array<v4f, 4>& b = part[size_t(t)];
        for (size_t i = begin; i < end; ++i) {
          const Ref& r = refs_[i];
          b[0] = vmin(b[0], r.box_lo());
          b[1] = vmax(b[1], r.hi);
          v4f c = r.centroid2();
          b[2] = vmin(b[2], c);
          b[3] = vmax(b[3], c);
        }
      });
      for (const auto& b : part) {
        root.box.grow(Bounds{glm3(b[0]), glm3(b[1])});
        root.cbox.grow(Bounds{glm3(b[2]), glm3(b[3])});
      }
    }
    bvh_.tris.resize(refs_.size());
    job_refs_ = std::max<uint32_t>(kMinJobRefs, uint32_t(refs_.size() / kJobsPerTree));
    Top top;
    // The root is always a 4-wide node, with one leaf child when the root range is a leaf
    Range halves[2];
    if (root.end == 0) {
      top.sub.nodes.push_back(empty_node());
    } else if (!split(root, &halves[0], &halves[1], true)) {
      root.leaf = true;
      top.sub.nodes.push_back(empty_node());
      set_child(top.sub, 0, 0, root, leaf_ref(top.sub, root));
    } else {
      top_node(top, root, halves);
    }
    std::vector<Job>& jobs = top.jobs;
    run_jobs(jobs);
    decltype(refs_)().swap(refs_);  // the leaves hold the triangles now
    // Join: the jobs' nodes after the top's, in job order, their child references
    // relocated; the threads copy a job each, and free its nodes once copied (host memory:
    // README, Performance)
    std::vector<size_t> offset(jobs.size());
    size_t total = top.sub.nodes.size();
    for (size_t k = 0; k < jobs.size(); ++k) {
      offset[k] = total;
      total += jobs[k].out.nodes.size();
    }
    bvh_.nodes = std::move(top.sub.nodes);
    bvh_.depth = top.sub.depth;
    for (size_t k = 0; k < jobs.size(); ++k) {
      const Job& j = jobs[k];
      bvh_.nodes[j.node].child[j.slot] = j.ref >= 0 ? j.ref + int(offset[k]) : j.ref;
      bvh_.depth = std::max(bvh_.depth, j.out.depth);
    }
    bvh_.nodes.resize(total);  // uninitialized: every job writes its own part
    for_each_taken(jobs.size(), [&](size_t k) {
      relocate(jobs[k].out.nodes, bvh_.nodes.data() + offset[k], int(offset[k]));  // a leaf job has no node
      decltype(jobs[k].out.nodes)().swap(jobs[k].out.nodes);
    });
    return std::move(bvh_);
  }

 private:
  v4f vertex(uint32_t v, size_t pose = 0) const {
    const float* p = &positions_[3 * (size_t(v) * poses_ + pose)];
    return v4f{p[0], p[1], p[2], 0.0f};
  }

  // fn(begin, end) over [0, n) in up to threads_ contiguous chunks of at least `grain`
  template <class Fn>
  void parallel_for(size_t n, Fn fn, size_t grain = 4096) {
    parallel_for_indexed(
        n, [&](int, size_t b, size_t e) { fn(b, e); }, grain);
  }
  template <class Fn>
  void parallel_for_indexed(size_t n, Fn fn, size_t grain = 4096) {
    bvh_build::parallel_for_indexed(threads_, n, fn, grain);
  }

  // fn(k) for k < n on up to threads_ threads, each taking the next k when it is free
  template <class Fn>
  void for_each_taken(size_t n, Fn fn) {
    std::atomic<size_t> next{0};
    auto worker = [&] {
      for (size_t k; (k = next.fetch_add(1)) < n;) fn(k);
    };
    int t = int(std::min<size_t>(size_t(threads_), n));
    std::vector<std::thread> pool;
    for (int i = 1; i < t; ++i) pool.emplace_back(worker);
    worker();
    for (std::thread& th : pool) th.join();
  }

  // The workers take the jobs largest first
  void run_jobs(std::vector<Job>& jobs) {
    std::vector<size_t> order(jobs.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
      return jobs[a].r.end - jobs[a].r.begin > jobs[b].r.end - jobs[b].r.begin;
    });
    for_each_taken(order.size(), [&](size_t k) {
      Job& j = jobs[order[k]];
      // Room for the subtree's nodes (about 0.27 per ref; pages are touched only as nodes are
      // written), so that growing the array does not copy it
      j.out.nodes.reserve((j.r.end - j.r.begin) / 2 + 1);
      Range sub[2];
      if (split(j.r, &sub[0], &sub[1], false)) {
        j.ref = int(inner_node(j.out, j.r, sub));
      } else {
        j.ref = leaf_ref(j.out, j.r);
      }
    });
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

  static void set_child(Subtree& out, uint32_t node, int slot, const Range& r, int ref) {
    dev::BvhNode& n = out.nodes[node];
    n.lo_x[slot] = r.box.lo.x;
    n.lo_y[slot] = r.box.lo.y;
    n.lo_z[slot] = r.box.lo.z;
    n.hi_x[slot] = r.box.hi.x;
    n.hi_y[slot] = r.box.hi.y;
    n.hi_z[slot] = r.box.hi.z;
    n.child[slot] = ref;
  }

  // A leaf's triangles are final once it is made: write them, the last one flagged
  // (ranges are disjoint, so workers write bvh_.tris concurrently)
  int leaf_ref(Subtree& out, const Range& r) {
    out.depth = std::max(out.depth, r.depth);
    for (uint32_t i = r.begin; i < r.end; ++i) {
      uint32_t prim = refs_[i].prim();
      const dev::Prim& p = prims_[prim];
      dev::BvhTriangle& d = bvh_.tris[i];
      d = dev::BvhTriangle{};
      for (int a = 0; a < 3; ++a) {
        d.v0[a] = positions_[3 * size_t(p.v[0]) * poses_ + a];
        d.v1[a] = positions_[3 * size_t(p.v[1]) * poses_ + a];
        d.v2[a] = positions_[3 * size_t(p.v[2]) * poses_ + a];
      }
      d.prim = prim;
      if (p.material < alpha_tested_.size() && alpha_tested_[p.material]) d.flags |= BVH_TRI_ALPHA_TEST;
      if (i + 1 == r.end) d.flags |= BVH_TRI_LAST;
    }
    return ~int(r.begin);
  }

  // A 4-wide node for range r, already split into `halves`; returns its index in out
  uint32_t inner_node(Subtree& out, const Range& r, Range halves[2]) {
    out.depth = std::max(out.depth, r.depth);
    std::array<Range, 4> kids;
    int n = 0;
    for (int h = 0; h < 2; ++h) {
      Range a, b;
      if (split(halves[h], &a, &b, false)) {
        kids[n++] = a;
        kids[n++] = b;
      } else {
        halves[h].leaf = true;
        kids[n++] = halves[h];
      }
    }
    uint32_t node = uint32_t(out.nodes.size());
    out.nodes.push_back(empty_node());
    for (int i = 0; i < n; ++i) {
      int ref = 0;
      Range sub[2];
      if (kids[i].leaf || !split(kids[i], &sub[0], &sub[1], false)) {
        ref = leaf_ref(out, kids[i]);
      } else {
        ref = int(inner_node(out, kids[i], sub));
      }
      set_child(out, node, i, kids[i], ref);  // out.nodes may have grown: index, not a reference
    }
    return node;
  }

  // The top of the tree: like inner_node, but children of at most job_refs_ refs become
  // jobs (child reference patched when the jobs are joined), and the larger children's
  // subtrees are built on threads of their own while threads are free, each into a Top of
  // its own that is appended in child order, so the node order is inner_node's
  struct Top {
    Subtree sub;
    std::vector<Job> jobs;
  };

  // fn(i) for i < n, on new threads while fewer than threads_ are busy, else inline
  template <class Fn>
  void fork(int n, Fn fn) {
    std::vector<std::thread> pool;
    for (int i = 0; i < n; ++i) {
      if (i + 1 < n && busy_.fetch_add(1) < threads_) {
        pool.emplace_back([&fn, this, i] {
          fn(i);
          busy_.fetch_sub(1);
        });
      } else {
        if (i + 1 < n) busy_.fetch_sub(1);
        fn(i);
      }
    }
    for (std::thread& t : pool) t.join();
  }

  uint32_t top_node(Top& out, const Range& r, Range halves[2]) {
    out.sub.depth = std::max(out.sub.depth, r.depth);
    Range split_halves[2][2];
    bool split_ok[2];
    fork(2, [&](int h) { split_ok[h] = split(halves[h], &split_halves[h][0], &split_halves[h][1], true); });
    std::array<Range, 4> kids;
    int n = 0;
    for (int h = 0; h < 2; ++h) {
      if (split_ok[h]) {
        kids[n++] = split_halves[h][0];
        kids[n++] = split_halves[h][1];
      } else {
        halves[h].leaf = true;
        kids[n++] = halves[h];
      }
    }
    uint32_t node = uint32_t(out.sub.nodes.size());
    out.sub.nodes.push_back(empty_node());
    std::array<Top, 4> below;
    std::array<int, 4> ref{};
    std::array<int, 4> big{};
    int nbig = 0;
    for (int i = 0; i < n; ++i) {
      if (kids[i].leaf) {
        ref[i] = leaf_ref(out.sub, kids[i]);
      } else if (kids[i].end - kids[i].begin <= job_refs_) {
        Job j;
        j.r = kids[i];
        j.node = node;
        j.slot = i;
        out.jobs.push_back(std::move(j));
      } else {
        big[nbig++] = i;
      }
    }
    fork(nbig, [&](int k) {
      int i = big[k];
      Range sub[2];
      if (!split(kids[i], &sub[0], &sub[1], true)) {
        ref[i] = leaf_ref(below[i].sub, kids[i]);
      } else {
        ref[i] = int(top_node(below[i], kids[i], sub));
      }
    });
    // Children in slot order: jobs and leaves were recorded above, big subtrees now
    for (int k = 0; k < nbig; ++k) {
      int i = big[k];
      int offset = int(out.sub.nodes.size());
      out.sub.nodes.resize(out.sub.nodes.size() + below[i].sub.nodes.size());
      relocate(below[i].sub.nodes, out.sub.nodes.data() + offset, offset);
      out.sub.depth = std::max(out.sub.depth, below[i].sub.depth);
      if (ref[i] >= 0) ref[i] += offset;
      for (Job& j : below[i].jobs) {
        j.node += uint32_t(offset);
        out.jobs.push_back(std::move(j));
      }
    }
    for (int i = 0; i < n; ++i) set_child(out.sub, node, i, kids[i], ref[i]);
    return node;
  }

  // Copies `from` to `to`, inner-child references (into `from`) moved by offset
  static void relocate(const UninitVector<dev::BvhNode>& from, dev::BvhNode* to, int offset) {
    for (dev::BvhNode n : from) {
      for (int i = 0; i < 4; ++i)
        if (n.child[i] >= 0 && n.lo_x[i] <= n.hi_x[i]) n.child[i] += offset;
      *to++ = n;
    }
  }

  // Binned SAH split of r into *left and *right (bvh_sah.cpp); false: r is a leaf
  bool split(const Range& r, Range* left, Range* right, bool parallel) {
    return sah_split(refs_, threads_, busy_, r, left, right, parallel);
  }

  const std::vector<float>& positions_;
  const std::vector<dev::Prim>& prims_;
  const std::vector<bool>& alpha_tested_;
  const int threads_;
  const size_t poses_;
  uint32_t job_refs_ = kMinJobRefs;
  std::atomic<int> busy_{1};  // threads at work in the top phase (the caller's included)
  UninitVector<Ref> refs_;    // refs_[i]: primitive stored at leaf position i once built
  Bvh bvh_;
};

}  // namespace

int bvh_build_threads() {
  if (const char* env = std::getenv("CANDELA_BVH_THREADS")) {
    int n = std::atoi(env);
    if (n > 0) return n;
  }
  return std::max(1u, std::thread::hardware_concurrency());
}

double sah_cost(const Bvh& bvh) {
  if (bvh.nodes.empty()) return 0.0;
  // The root's box: the union of its children's
  auto area = [](const dev::BvhNode& n, int i) {
    double dx = double(n.hi_x[i]) - n.lo_x[i], dy = double(n.hi_y[i]) - n.lo_y[i], dz = double(n.hi_z[i]) - n.lo_z[i];
    return 2.0 * (dx * dy + dy * dz + dz * dx);
  };
  const dev::BvhNode& root = bvh.nodes[0];
  glm::dvec3 lo(1e300), hi(-1e300);
  for (int i = 0; i < 4; ++i) {
    if (root.lo_x[i] > root.hi_x[i]) continue;
    lo = glm::min(lo, glm::dvec3(root.lo_x[i], root.lo_y[i], root.lo_z[i]));
    hi = glm::max(hi, glm::dvec3(root.hi_x[i], root.hi_y[i], root.hi_z[i]));
  }
  if (lo.x > hi.x) return 0.0;
  glm::dvec3 d = hi - lo;
  double root_area = 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
  if (!(root_area > 0.0)) return 0.0;
  // Every node is some node's child (the root aside): cost = sum over child slots of
  // area / root area x (traversal cost for an inner child, triangle count for a leaf)
  double cost = kTraversalCost;
  for (const dev::BvhNode& n : bvh.nodes)
    for (int i = 0; i < 4; ++i) {
      if (n.lo_x[i] > n.hi_x[i]) continue;
      double weight;
      if (n.child[i] >= 0) {
        weight = kTraversalCost;
      } else {
        size_t t = size_t(~n.child[i]), count = 1;
        while (t < bvh.tris.size() && !(bvh.tris[t].flags & BVH_TRI_LAST)) ++t, ++count;
        weight = double(count);
      }
      cost += area(n, i) / root_area * weight;
    }
  return cost;
}

Bvh build_bvh(const std::vector<float>& positions, const std::vector<dev::Prim>& prims,
              const std::vector<bool>& alpha_tested, int threads, int poses) {
  return Builder(positions, prims, alpha_tested, threads > 0 ? threads : bvh_build_threads(), poses).build();
}

}  // namespace candela
