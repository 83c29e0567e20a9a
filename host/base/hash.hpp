// 64-bit FNV-1a, for cache keys.
#pragma once

#include <cstdint>
#include <string_view>

namespace candela {

inline uint64_t fnv1a64(std::string_view data, uint64_t h = 0xcbf29ce484222325ull) {
  for (unsigned char c : data) {
    h ^= c;
    h *= 0x100000001b3ull;
  }
  return h;
}

}  // namespace candela
