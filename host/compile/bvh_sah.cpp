#include "compile/bvh_sah.hpp"

#include <array>
#include <cmath>

namespace candela::bvh_build {
namespace {

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

class Splitter {
 public:
  Splitter(UninitVector<Ref>& refs, int threads, const std::atomic<int>& busy)
      : refs_(refs), threads_(threads), busy_(busy) {}

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
      parallel_for_indexed(threads_, count, [&](int t, size_t b, size_t e) {
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

  UninitVector<Ref>& refs_;
  const int threads_;
  const std::atomic<int>& busy_;
};

}  // namespace

bool sah_split(UninitVector<Ref>& refs, int threads, const std::atomic<int>& busy, const Range& r, Range* left,
               Range* right, bool parallel) {
  return Splitter(refs, threads, busy).split(r, left, right, parallel);
}

}  // namespace candela::bvh_build
