// Stable sort of ids by a 32-bit key, in linear time: three 11-bit least-significant-digit passes.
// It is the "sort them cheaply" step of the pass-based contraction scheme (the scheme of
// meshoptimizer's simplifier), where float costs are mapped so that unsigned order is float order
// (negatives included: quadric errors can round to a tiny negative). Stability makes ties keep
// the ids' incoming order, so the result is deterministic.
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/parallel_chunks.h"

namespace qem::core {

inline std::uint32_t sortable_bits(float key) {
  std::uint32_t bits;
  std::memcpy(&bits, &key, sizeof bits);
  return (bits & 0x80000000u) ? ~bits : (bits | 0x80000000u);
}

/// Sorts `ids` by the unsigned key key_of(id), stably. `scratch` is reused storage. The keys are
/// read again in each digit pass instead of being stored beside the ids: half the memory, which
/// matters more than the extra reads on the meshes this sorts. `Ids`: a vector of uint32 (any
/// allocator). With `threads`, a large array's passes run in fixed chunks on the threads: each
/// chunk counts its digits, and scatters to where the chunks before it (and the smaller digits)
/// end, which is where the one-thread pass puts each id: the same order on any number of threads.
/// (On a ten-million-face mesh the serial sort was a tenth of a second beside idle threads.)
template <class Ids, class KeyOf>
void radix_sort_by_key(Ids& ids, Ids& scratch, KeyOf key_of, unsigned threads = 1) {
  constexpr int kBits = 11, kBuckets = 1 << kBits, kDigits = 3;
  constexpr std::size_t kChunk = std::size_t(1) << 18;
  const std::size_t n = ids.size();
  scratch.resize(n);
  if (threads > 1 && n > kChunk) {
    const std::size_t chunks = (n + kChunk - 1) / kChunk;
    std::vector<std::array<std::uint32_t, kBuckets>> count(chunks);
    for (int d = 0; d < kDigits; ++d) {
      const auto digit = [&](std::uint32_t id) { return (key_of(id) >> (d * kBits)) & (kBuckets - 1); };
      for_chunks(n, kChunk, threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
        count[c].fill(0);
        for (std::size_t i = begin; i < end; ++i) ++count[c][digit(ids[i])];
      });
      std::uint32_t sum = 0;  // each (digit, chunk) bucket's start: digits in order, chunks within
      for (int b = 0; b < kBuckets; ++b)
        for (std::size_t c = 0; c < chunks; ++c) {
          const std::uint32_t here = count[c][b];
          count[c][b] = sum;
          sum += here;
        }
      for_chunks(n, kChunk, threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
          const std::uint32_t id = ids[i];
          scratch[count[c][digit(id)]++] = id;
        }
      });
      ids.swap(scratch);
    }
    return;
  }
  std::vector<std::array<std::uint32_t, kBuckets>> count(kDigits);
  for (auto& c : count) c.fill(0);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t key = key_of(ids[i]);
    for (int d = 0; d < kDigits; ++d) ++count[d][(key >> (d * kBits)) & (kBuckets - 1)];
  }
  for (int d = 0; d < kDigits; ++d) {
    std::uint32_t sum = 0;
    for (std::uint32_t& c : count[d]) {
      const std::uint32_t here = c;
      c = sum;
      sum += here;
    }
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t id = ids[i];
      scratch[count[d][(key_of(id) >> (d * kBits)) & (kBuckets - 1)]++] = id;
    }
    ids.swap(scratch);
  }
}

/// Sorts `ids` by the float key key_of(id), stably.
template <class KeyOf>
void radix_sort_by_float_key(std::vector<std::uint32_t>& ids, std::vector<std::uint32_t>& scratch, KeyOf key_of) {
  radix_sort_by_key(ids, scratch, [&](std::uint32_t id) { return sortable_bits(key_of(id)); });
}

}  // namespace qem::core
