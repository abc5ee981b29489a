// Work split into fixed-size chunks on the process's threads (thread_pool.h). The chunks do not
// depend on the thread count, so anything computed per chunk (a warm-started query run, a partial
// sum combined in chunk order) is bit-identical for any number of threads. With thread_pool.h, the
// library's one thread helper.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

#include "core/default_init_allocator.h"
#include "core/thread_pool.h"

namespace qem::core {

inline unsigned resolve_threads(unsigned requested) {
  if (requested > 0) return requested;
  return std::max(1u, std::thread::hardware_concurrency());
}

/// Calls fn(chunk, begin, end) for the chunks [c * chunk_size, (c + 1) * chunk_size) of [0, n) on
/// up to `threads` threads, the calling thread among them. If no more threads can be had, the
/// ones there take the rest (same result); the first exception thrown by fn is rethrown here.
template <class Fn>
void for_chunks(std::size_t n, std::size_t chunk_size, unsigned threads, Fn&& fn) {
  threads = std::max(1u, threads);
  const std::size_t chunks = (n + chunk_size - 1) / chunk_size;
  std::atomic<std::size_t> next{0};
  std::vector<std::exception_ptr> failures(std::max(1u, threads));
  auto work = [&](unsigned t) {
    try {
      for (std::size_t c; (c = next.fetch_add(1)) < chunks;)
        fn(c, c * chunk_size, std::min(n, (c + 1) * chunk_size));
    } catch (...) {
      failures[t] = std::current_exception();
      next = chunks;  // the others stop at their next chunk
    }
  };
  const unsigned extra = unsigned(std::min<std::size_t>(threads, chunks)) - (chunks > 0 ? 1 : 0);
  run_with_helpers(extra, work);
  for (const std::exception_ptr& failure : failures)
    if (failure) std::rethrow_exception(failure);
}

/// Calls fn(lo, hi) for ranges [lo, hi) of the vertices [0, nv), one range per thread (a single
/// one below `per_range` vertices a thread), side by side. A pass over every face that touches
/// only the vertices of its range gives the serial result on any number of threads.
template <class Fn>
void for_vertex_ranges(std::size_t nv, unsigned threads, std::size_t per_range, Fn fn) {
  const std::size_t ranges = std::max<std::size_t>(1, std::min<std::size_t>(threads, nv / per_range + 1));
  for_chunks(ranges, 1, unsigned(ranges),
             [&](std::size_t r, std::size_t, std::size_t) { fn(nv * r / ranges, nv * (r + 1) / ranges); });
}

/// n copies of `value`, written in fixed chunks on the threads: a large array's first writes are
/// the kernel's page faults, a serial stretch when one thread makes them (the same array on any
/// number of threads).
template <class T>
UnzeroedVector<T> filled(std::size_t n, T value, unsigned threads) {
  UnzeroedVector<T> out(n);
  for_chunks(n, std::size_t(1) << 16, threads, [&](std::size_t, std::size_t begin, std::size_t end) {
    std::fill(out.begin() + std::ptrdiff_t(begin), out.begin() + std::ptrdiff_t(end), value);
  });
  return out;
}

/// Two independent pieces of work: side by side when there are threads (one of them on a helper
/// thread, if one is free), else one after the other. Either way the result is the same.
template <class First, class Second>
void side_by_side(unsigned threads, First first, Second second) {
  if (threads < 2) {
    first();
    second();
    return;
  }
  for_chunks(2, 1, 2, [&](std::size_t part, std::size_t, std::size_t) { part == 0 ? first() : second(); });
}

}  // namespace qem::core
