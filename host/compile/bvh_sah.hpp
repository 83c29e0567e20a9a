// The binned surface-area-heuristic split of the BVH builder (bvh_builder.cpp): the refs
// and ranges the builder works on, and sah_split, which bins a range's centroids and
// partitions it where the SAH cost is lowest (bvh_sah.cpp). Private to the builder.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <glm/glm.hpp>
#include <thread>
#include <vector>

#include "base/device_types.hpp"
#include "compile/bvh_builder.hpp"
#include "scene/scene.hpp"

namespace candela::bvh_build {

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
// Ranges of at least this many refs are binned into two sets of bins (Splitter::bin)
constexpr uint32_t kTwoBinSets = 256;
// Ranges of at least kSampledBinning refs choose their split plane from the bins of every
// kSampleStride-th ref (8192 refs or more): half the binning work at the top levels, where
// it streams the array from memory, for trees of the same SAH cost within 0.01 % on the
// 1 M and 10 M meshes measured (every fourth ref gave 1.4 % more on the 10 M one). The sides' boxes then come from the
// partition, which reads every ref.
constexpr uint32_t kSampledBinning = 16384;
constexpr uint32_t kSampleStride = 2;

// Four floats in one SSE/NEON register (GCC and Clang vector extensions); lane 3 unused
typedef float v4f __attribute__((vector_size(16)));
typedef int32_t v4i __attribute__((vector_size(16)));

inline v4f vmin(v4f a, v4f b) { return a < b ? a : b; }
inline v4f vmax(v4f a, v4f b) { return a > b ? a : b; }
inline v4f vec(const glm::vec3& p) { return v4f{p.x, p.y, p.z, 0.0f}; }
inline glm::vec3 glm3(v4f v) { return glm::vec3(v[0], v[1], v[2]); }

inline float surface_area(const Bounds& b) {
  if (b.empty()) return 0.0f;
  glm::vec3 d = b.hi - b.lo;
  return 2.0f * (d.x * d.y + d.y * d.z + d.z * d.x);
}

inline float surface_area(v4f lo, v4f hi) {
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

// fn(thread, begin, end) over [0, n) in up to `threads` contiguous chunks of at least
// `grain`, chunk 0 on the calling thread
template <class Fn>
void parallel_for_indexed(int threads, size_t n, Fn fn, size_t grain = 4096) {
  int t = int(std::min<size_t>(size_t(threads), std::max<size_t>(1, n / grain)));
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

// Binned SAH split of r (refs[r.begin, r.end)) into *left and *right (bounds included),
// partitioning the refs in place; false: r is a leaf. `parallel`: bin large ranges on
// every thread (the top phase, where the workers wait) while fewer than `threads` are busy
bool sah_split(UninitVector<Ref>& refs, int threads, const std::atomic<int>& busy, const Range& r, Range* left,
               Range* right, bool parallel);

}  // namespace candela::bvh_build
