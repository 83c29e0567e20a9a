// `candela merge`: images of disjoint sample ranges of one render (shards, e.g. from
// several machines), combined into the image of all their samples.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace candela {

struct MergeArgs {
  std::vector<std::string> inputs;  // .exr files written by `candela render`
  std::string output;               // .exr
  bool quiet = false;
};

// Half-open ranges [begin, end) of sample indices an image holds: candela:sample_ranges
// ("B:E,B:E", written by merge), else [sample_offset, sample_offset + spp)
using SampleRanges = std::vector<std::pair<uint64_t, uint64_t>>;

// Reads the inputs, checks that they are shards of one render (same size, the same
// settings where the settings' table says they must match (settings.hpp: scene, seed,
// strategy, filter, ...), camera and lighting; disjoint sample ranges; candela metadata
// present) and writes the per-pixel mean weighted by each file's spp. Throws
// Error naming the first mismatch. Returns the process exit code.
int run_merge(const MergeArgs& args);

}  // namespace candela
