#include "compile/bvh_builder.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <thread>

#include "scene/scene.hpp"

namespace candela {
namespace {

// The builder's hot functions compiled twice, for AVX2 and for the baseline ISA candela
// is built for (SSE2 on x86-64); the loader picks one for the CPU. No FMA: each operation
// rounds as in the baseline code, so both give the same tree.
#if defined(__x86_64__) && defined(__GNUC__)
#define CD_BUILD_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define CD_BUILD_CLONES
#endif

constexpr int kBins = 16;
constexpr int kMaxLeafSize = 8;
constexpr float kTraversalCost = 1.0f;                // relative to one triangle test
constexpr float kEmptyLo = 1e30f, kEmptyHi = -1e30f;  // an unused child slot's box
// Ranges of at least this many refs bin on every thread during the serial top phase
constexpr uint32_t kParallelBinning = 32768;
// Ranges of at least this many refs are binned into two sets of bins (Builder::bin)
constexpr uint32_t kTwoBinSets = 256;
// Ranges of at least kSampledBinning refs choose their split plane from the bins of every
// kSampleStride-th ref (8192 refs or more): half the binning work at the top levels, where
// it streams the array from memory, for trees of the same SAH cost within 0.01 % on the
// 1 M and 10 M meshes measured (every fourth ref gave 1.4 % more on the 10 M one). The sides' boxes then come from the
// partition, which reads every ref.
constexpr uint32_t kSampledBinning = 16384;
constexpr uint32_t kSampleStride = 2;
// The top phase hands subtrees of at most max(kMinJobRefs, refs / kJobsPerTree) refs to
// the workers: independent of the thread count, so that the tree (node order included) is
constexpr uint32_t kMinJobRefs = 4096;
constexpr size_t kJobsPerTree = 128;

// Each 4-wide node on a path down pushes at most 3 entries, and the nodes sit two
// binary levels apart, at binary depths 1, 3, ..., below kMaxBvhDepth
static_assert(3 * (kMaxBvhDepth / 2) <= BVH_STACK_SIZE, "traversal stack too small for the depth limit");

// Four floats in one SSE/NEON register (GCC and Clang vector extensions); lane 3 unused
typedef float v4f __attribute__((vector_size(16)));
typedef int32_t v4i __attribute__((vector_size(16)));

inline v4f vmin(v4f a, v4f b) { return a < b ? a : b; }
inline v4f vmax(v4f a, v4f b) { return a > b ? a : b; }
inline v4f vec(const glm::vec3& p) { return v4f{p.x, p.y, p.z, 0.0f}; }
inline glm::vec3 glm3(v4f v) { return glm::vec3(v[0], v[1], v[2]); }

float surface_area(const Bounds& b) {
  if (b.empty()) return 0.0f;
  glm::vec3 d = b.hi - b.lo;
  return 2.0f * (d.x * d.y + d.y * d.z + d.z * d.x);
}

float surface_area(v4f lo, v4f hi) {
  if (lo[0] > hi[0]) return 0.0f;
  v4f d = hi - lo;
  return 2.0f * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]);
}

// A primitive during the build, 32 bytes: its box, with the stable primitive index in the
// low box's lane 3 (masked off before any arithmetic: as a float it is a denormal) and 0
// in the high box's. Partitioned in place, so that binning reads memory in order.
struct Ref {
  v4f lo, hi;
  uint32_t prim() const {
    uint32_t p;
    std::memcpy(&p, reinterpret_cast<const char*>(&lo) + 12, 4);
    return p;
  }
  v4f box_lo() const { return v4f((v4i)lo & v4i{-1, -1, -1, 0}); }
  // Twice the centroid, in lane 3 zero
  v4f centroid2() const { return box_lo() + hi; }
};

// A range of refs with its bounds and its centroids' bounds (twice the centroids, as
// Ref::centroid2); leaf once the SAH says so
struct Range {
  uint32_t begin = 0, end = 0;
  int depth = 1;  // of the binary SAH tree
  Bounds box, cbox;
  bool leaf = false;
};

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

struct Bins {
  v4f lo[3][kBins], hi[3][kBins];
  uint32_t count[3][kBins];
  void clear(int nbins) {
    for (int a = 0; a < 3; ++a)
      for (int i = 0; i < nbins; ++i) {
        lo[a][i] = v4f{kEmptyLo, kEmptyLo, kEmptyLo, 0.0f};
        hi[a][i] = v4f{kEmptyHi, kEmptyHi, kEmptyHi, 0.0f};
      }
    // Every count, four at a time: twelve vector stores (GCC turns a loop of variable
    // length, or a memset of them all, into a `rep stos`, which takes longer to start)
    static_assert(kBins % 4 == 0, "counts are cleared four at a time");
    const v4i zero{};
    for (int a = 0; a < 3; ++a)
      for (int i = 0; i < kBins; i += 4) std::memcpy(&count[a][i], &zero, sizeof zero);
  }
  void merge(const Bins& o, int nbins) {
    for (int a = 0; a < 3; ++a)
      for (int i = 0; i < nbins; ++i) {
        lo[a][i] = vmin(lo[a][i], o.lo[a][i]);
        hi[a][i] = vmax(hi[a][i], o.hi[a][i]);
        count[a][i] += o.count[a][i];
      }
  }
};

// The bin of each axis for a ref's doubled centroid c2 (binning and partition share it,
// so that the bins' bounds are exactly the sides' bounds)
struct Binner {
  v4f lo2, scale2;
  v4i top;
  v4i index(v4f c2) const {
    v4i i = __builtin_convertvector((c2 - lo2) * scale2, v4i);
    i = i < top ? i : top;
    return i > 0 ? i : v4i{0, 0, 0, 0};
  }
};

class Builder {
 public:
  Builder(const std::vector<float>& positions, const std::vector<dev::Prim>& prims,
          const std::vector<bool>& alpha_tested, int threads)
      : positions_(positions), prims_(prims), alpha_tested_(alpha_tested), threads_(std::max(1, threads)) {
    refs_.resize(prims.size());
    parallel_for(prims.size(), [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) {
        const dev::Prim& p = prims[i];
        v4f a = vertex(p.v[0]), b = vertex(p.v[1]), c = vertex(p.v[2]);
        Ref& r = refs_[i];
        r.lo = vmin(vmin(a, b), c);
        r.hi = vmax(vmax(a, b), c);
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
  v4f vertex(uint32_t v) const {
    const float* p = &positions_[3 * size_t(v)];
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
    int t = int(std::min<size_t>(size_t(threads_), std::max<size_t>(1, n / grain)));
    if (t <= 1) {
      fn(0, 0, n);
      return;
    }
    std::vector<std::thread> pool;
    for (int i = 1; i < t; ++i)
      pool.emplace_back([&, i] { fn(i, n * size_t(i) / size_t(t), n * size_t(i + 1) / size_t(t)); });
    fn(0, 0, n / size_t(t));
    for (std::thread& th : pool) th.join();
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
        d.v0[a] = positions_[3 * size_t(p.v[0]) + a];
        d.v1[a] = positions_[3 * size_t(p.v[1]) + a];
        d.v2[a] = positions_[3 * size_t(p.v[2]) + a];
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

  // Bins refs begin, begin + stride, ... before end
  CD_BUILD_CLONES void bin(const Binner& b, uint32_t begin, uint32_t end, uint32_t stride, int nbins,
                           Bins* bins) const {
    auto add = [&](const Ref& ref, Bins* to) {
      v4f lo = ref.box_lo(), hi = ref.hi;
      v4i k = b.index(lo + hi);
      for (int a = 0; a < 3; ++a) {
        int j = k[a];
        to->lo[a][j] = vmin(to->lo[a][j], lo);
        to->hi[a][j] = vmax(to->hi[a][j], hi);
        to->count[a][j]++;
      }
    };
    if (end - begin < kTwoBinSets * stride) {
      for (uint32_t i = begin; i < end; i += stride) add(refs_[i], bins);
      return;
    }
    // Neighbouring refs mostly share their bins (the partitions keep them in space order):
    // even and odd refs go to separate sets, so that one ref's update does not wait for the
    // store of the one before. min, max and counts do not depend on the order: the same bins
    Bins odd;
    odd.clear(nbins);
    uint32_t i = begin;
    for (; i + stride < end; i += 2 * stride) {
      add(refs_[i], bins);
      add(refs_[i + stride], &odd);
    }
    if (i < end) add(refs_[i], bins);
    bins->merge(odd, nbins);
  }

  // The bins of range r's centroid bounds; usable[a]: whether axis a can be binned
  static Binner make_binner(const Range& r, int nbins, bool usable[3]) {
    glm::vec3 extent = r.cbox.hi - r.cbox.lo;
    Binner binner;
    binner.lo2 = vec(r.cbox.lo);
    binner.top = v4i{nbins - 1, nbins - 1, nbins - 1, 0};
    for (int a = 0; a < 3; ++a) {
      float scale = float(nbins) / extent[a];
      // A flat or denormal extent cannot be binned
      usable[a] = extent[a] > 0.0f && std::isfinite(scale);
      binner.scale2[a] = usable[a] ? scale : 0.0f;
    }
    binner.scale2[3] = 0.0f;
    return binner;
  }

  // split() of a range of two refs, without bins and the sweep (ranges of two are a third
  // of all splits): on every usable axis where the two fall in different bins, each plane
  // between them costs the sum of their boxes' areas, so the binned split takes the first
  // such axis and the plane right after the lower ref. The same result as binning, bit for
  // bit: the boxes are grown from the empty box as the bins' are.
  bool split_pair(const Range& r, const Binner& binner, const bool usable[3], Range* left, Range* right) {
    v4f c[2] = {refs_[r.begin].centroid2(), refs_[r.begin + 1].centroid2()};
    v4i k0 = binner.index(c[0]), k1 = binner.index(c[1]);
    int a = 0;
    while (a < 3 && !(usable[a] && k0[a] != k1[a])) ++a;
    if (a == 3) return false;
    int low = k0[a] < k1[a] ? 0 : 1;
    const v4f empty_lo = vec(Bounds().lo), empty_hi = vec(Bounds().hi);
    v4f lo[2], hi[2];
    for (int i = 0; i < 2; ++i) {
      lo[i] = vmin(empty_lo, refs_[r.begin + uint32_t(i)].box_lo());
      hi[i] = vmax(empty_hi, refs_[r.begin + uint32_t(i)].hi);
    }
    float cost = surface_area(lo[low], hi[low]) + surface_area(lo[1 - low], hi[1 - low]);
    if (!(cost < 1e30f)) return false;
    float split_cost = kTraversalCost + cost / std::max(surface_area(r.box), 1e-30f);
    if (!(split_cost < 2.0f)) return false;  // the leaf's cost
    if (low == 1) std::swap(refs_[r.begin], refs_[r.begin + 1]);
    *left = Range();
    *right = Range();
    left->depth = right->depth = r.depth + 1;
    left->begin = r.begin;
    left->end = right->begin = r.begin + 1;
    right->end = r.end;
    Range* side[2] = {left, right};
    for (int s = 0; s < 2; ++s) {
      int i = s == 0 ? low : 1 - low;
      side[s]->box = Bounds{glm3(lo[i]), glm3(hi[i])};
      side[s]->cbox = Bounds{glm3(vmin(empty_lo, c[i])), glm3(vmax(empty_hi, c[i]))};
    }
    return true;
  }

  // The two sides of a partition: their centroid bounds (twice the centroids) and boxes
  struct Sides {
    v4f cmin[2], cmax[2], bmin[2], bmax[2];
    Sides() {
      for (int s = 0; s < 2; ++s) {
        cmin[s] = bmin[s] = vec(Bounds().lo);
        cmax[s] = bmax[s] = vec(Bounds().hi);
      }
    }
  };

  // Partitions range r in place: refs whose bin on axis a is at most `plane` first. Returns
  // where the second side begins; the sides' centroid bounds in *sides, and with kBoxes
  // their boxes too. Inlined into split, so that it is compiled for split's ISA.
  template <bool kBoxes>
  [[gnu::always_inline]] uint32_t partition(const Range& r, const Binner& binner, int a, int plane, Sides* sides) {
    uint32_t i = r.begin, j = r.end;
    auto grow = [&](int s, const Ref& ref, v4f c) {
      sides->cmin[s] = vmin(sides->cmin[s], c);
      sides->cmax[s] = vmax(sides->cmax[s], c);
      if (kBoxes) {
        sides->bmin[s] = vmin(sides->bmin[s], ref.box_lo());
        sides->bmax[s] = vmax(sides->bmax[s], ref.hi);
      }
    };
    while (true) {
      for (; i < j; ++i) {
        v4f c = refs_[i].centroid2();
        if (binner.index(c)[a] > plane) break;
        grow(0, refs_[i], c);
      }
      for (; i < j; --j) {
        v4f c = refs_[j - 1].centroid2();
        if (binner.index(c)[a] <= plane) break;
        grow(1, refs_[j - 1], c);
      }
      if (i >= j) break;
      std::swap(refs_[i], refs_[j - 1]);
    }
    return i;
  }

  // Binned SAH split of r into *left and *right (bounds included); false: r is a leaf.
  // `parallel`: bin large ranges on every thread (the top phase, where the workers wait)
  CD_BUILD_CLONES bool split(const Range& r, Range* left, Range* right, bool parallel) {
    uint32_t count = r.end - r.begin;
    if (count <= 1 || r.depth >= kMaxBvhDepth) return false;
    // One pass bins the centroids along all three axes; small ranges get fewer bins (the
    // sweep over the bins costs as much as binning a few dozen triangles)
    int nbins = int(std::clamp<uint32_t>(count, 4, kBins));
    bool usable[3];
    Binner binner = make_binner(r, nbins, usable);
    if (count == 2) return split_pair(r, binner, usable, left, right);
    Bins bins;
    bins.clear(nbins);
    const bool sampled = count >= kSampledBinning;
    const uint32_t stride = sampled ? kSampleStride : 1;
    if (parallel && count >= kParallelBinning && threads_ > 1 && busy_.load() < threads_) {
      std::vector<Bins> part(static_cast<size_t>(threads_));
      for (Bins& p : part) p.clear(nbins);
      parallel_for_indexed(count, [&](int t, size_t b, size_t e) {
        size_t first = (b + stride - 1) / stride * stride;  // the chunk's first sampled ref
        if (first < e) bin(binner, r.begin + uint32_t(first), r.begin + uint32_t(e), stride, nbins, &part[size_t(t)]);
      });
      for (const Bins& p : part) bins.merge(p, nbins);
    } else {
      bin(binner, r.begin, r.end, stride, nbins, &bins);
    }
    int best_axis = -1, best_plane = 0;
    float best_cost = 1e30f;
    for (int a = 0; a < 3; ++a) {
      if (!usable[a]) continue;
      // Sweep: areas and counts left of each plane, then right
      std::array<float, kBins - 1> left_area, right_area;
      std::array<uint32_t, kBins - 1> left_count, right_count;
      v4f alo = bins.lo[a][0], ahi = bins.hi[a][0];
      uint32_t c = 0;
      for (int i = 0; i < nbins - 1; ++i) {
        alo = vmin(alo, bins.lo[a][i]);
        ahi = vmax(ahi, bins.hi[a][i]);
        c += bins.count[a][i];
        left_area[i] = surface_area(alo, ahi);
        left_count[i] = c;
      }
      alo = bins.lo[a][nbins - 1];
      ahi = bins.hi[a][nbins - 1];
      c = 0;
      for (int i = nbins - 1; i > 0; --i) {
        alo = vmin(alo, bins.lo[a][i]);
        ahi = vmax(ahi, bins.hi[a][i]);
        c += bins.count[a][i];
        right_area[i - 1] = surface_area(alo, ahi);
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
      // sides' centroid bounds (and, for sampled bins, boxes) on the way
      int a = best_axis;
      Sides sides;
      uint32_t mid = sampled ? partition<true>(r, binner, a, best_plane, &sides)
                             : partition<false>(r, binner, a, best_plane, &sides);
      left->end = right->begin = mid;
      left->cbox = Bounds{glm3(sides.cmin[0]), glm3(sides.cmax[0])};
      right->cbox = Bounds{glm3(sides.cmin[1]), glm3(sides.cmax[1])};
      if (!sampled) {
        for (int k = 0; k < nbins; ++k) {
          int s = k <= best_plane ? 0 : 1;
          sides.bmin[s] = vmin(sides.bmin[s], bins.lo[a][k]);
          sides.bmax[s] = vmax(sides.bmax[s], bins.hi[a][k]);
        }
      }
      left->box = Bounds{glm3(sides.bmin[0]), glm3(sides.bmax[0])};
      right->box = Bounds{glm3(sides.bmin[1]), glm3(sides.bmax[1])};
      return true;
    }
    if (count <= kMaxLeafSize) return false;
    // All centroids coincide (or no useful plane): split the range in half
    left->end = right->begin = r.begin + count / 2;
    for (Range* side : {left, right})
      for (uint32_t i = side->begin; i < side->end; ++i) {
        side->box.grow(Bounds{glm3(refs_[i].box_lo()), glm3(refs_[i].hi)});
        side->cbox.grow(glm3(refs_[i].centroid2()));
      }
    return true;
  }

  const std::vector<float>& positions_;
  const std::vector<dev::Prim>& prims_;
  const std::vector<bool>& alpha_tested_;
  const int threads_;
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
              const std::vector<bool>& alpha_tested, int threads) {
  return Builder(positions, prims, alpha_tested, threads > 0 ? threads : bvh_build_threads()).build();
}

}  // namespace candela
