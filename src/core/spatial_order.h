// Ordering points along a Morton (Z-order) curve, so that points close in space are close in
// memory or in processing order. The simplifier renumbers its vertices this way (its loop touches
// a vertex's neighbours, their quadrics, faces and pairs: with an arbitrary input order each is a
// cache miss); the error metric orders its closest-point queries this way (each query then starts
// next to the previous answer).
#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/default_init_allocator.h"
#include "core/parallel_chunks.h"
#include "core/quadric.h"
#include "core/radix_sort.h"
#include "geometry/box.h"

namespace qem::core {

/// Spreads the low 21 bits of x so that two zero bits separate each (for 3D interleaving).
/// Inline: it runs three times for every point ordered.
inline std::uint64_t spread_bits_3d(std::uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffULL;
  x = (x | x << 16) & 0x1f0000ff0000ffULL;
  x = (x | x << 8) & 0x100f00f00f00f00fULL;
  x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
  x = (x | x << 2) & 0x1249249249249249ULL;
  return x;
}

/// The Morton code of point p (21 bits an axis) on the grid of cubic cells whose corner is `lo`,
/// `scale` cells a unit. Each coordinate is clamped before the conversion (NaN, inf and
/// out-of-range doubles must never reach the cast: undefined behaviour, found by fuzz_simplify
/// with coordinates near 1e308).
inline std::uint64_t morton_code(const double p[3], const double lo[3], double scale) {
  std::uint64_t code = 0;
  for (int a = 0; a < 3; ++a) {
    const double c = (p[a] - lo[a]) * scale;
    code |= spread_bits_3d(c >= 0 ? std::uint64_t(std::min(c, double((1 << 21) - 1))) : 0) << a;
  }
  return code;
}

/// Indices 0..n-1 sorted by the Morton code of point_of(i) (a Vec3) over the points' bounding
/// box, ties by index: the order is fully determined by the input. The box and the codes are made
/// in fixed chunks on up to `threads` threads (per-chunk boxes merged in chunk order: min and max
/// are exact), and so is the sort (radix_sort.h): the same order on any number of threads.
template <class PointOf>
std::vector<std::uint32_t> morton_order(std::size_t n, PointOf point_of, unsigned threads = 1) {
  constexpr std::size_t kChunk = std::size_t(1) << 16;
  std::vector<BoxOfPoints> chunk_boxes((n + kChunk - 1) / kChunk);
  for_chunks(n, kChunk, threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const Vec3 p = point_of(i);
      const double xyz[3] = {p.x, p.y, p.z};
      chunk_boxes[c].add(xyz);
    }
  });
  BoxOfPoints all;
  for (const BoxOfPoints& b : chunk_boxes) all.add(b);
  const Box box = all.box();
  const Vec3 lo{box.lo[0], box.lo[1], box.lo[2]}, hi{box.hi[0], box.hi[1], box.hi[2]};
  // One scale for all axes keeps the cells cubic.
  const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  const double scale = extent > 0 ? double((1 << 21) - 1) / extent : 0;
  std::vector<std::uint64_t, DefaultInitAllocator<std::uint64_t>> code(n);
  std::vector<std::uint32_t> order(n), scratch;
  for_chunks(n, kChunk, threads, [&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const Vec3 p = point_of(i);
      const double xyz[3] = {p.x, p.y, p.z}, corner[3] = {lo.x, lo.y, lo.z};
      code[i] = morton_code(xyz, corner, scale);
      order[i] = std::uint32_t(i);
    }
  });
  // Sorted by (code, index): a stable radix sort on the code's top 32 of 63 bits, then each run of
  // equal top bits, almost always a single point, by its full code. Linear time, so cheaper on
  // large meshes than the comparison sort of (code, index) it replaces (docs/benchmarks.md,
  // "Measurements behind the code").
  radix_sort_by_key(order, scratch, [&](std::uint32_t i) { return std::uint32_t(code[i] >> 31); }, threads);
  // On the threads: first where each chunk's first run starts (reads only; a run may reach
  // through several chunks), then the runs from there to the next chunk's first, each sorted
  // whole by one thread: the same order on any number.
  const auto top = [&](std::size_t k) { return code[order[k]] >> 31; };
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<std::size_t> run_start(chunks + 1, n);
  for_chunks(n, kChunk, threads, [&](std::size_t c, std::size_t begin, std::size_t) {
    while (begin > 0 && begin < n && top(begin) == top(begin - 1)) ++begin;
    run_start[c] = begin;
  });
  for_chunks(chunks, 1, threads, [&](std::size_t c, std::size_t, std::size_t) {
    for (std::size_t begin = run_start[c], end; begin < run_start[c + 1]; begin = end) {
      end = begin + 1;
      while (end < run_start[c + 1] && top(end) == top(begin)) ++end;  // runs end at the next start
      if (end - begin > 1)
        std::sort(order.begin() + std::ptrdiff_t(begin), order.begin() + std::ptrdiff_t(end),
                  [&](std::uint32_t a, std::uint32_t b) { return code[a] != code[b] ? code[a] < code[b] : a < b; });
    }
  });
  return order;
}

}  // namespace qem::core
