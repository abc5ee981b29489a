// Work split into fixed-size chunks on std::threads. The chunks do not depend on the thread count,
// so anything computed per chunk (a warm-started query run, a partial sum combined in chunk order)
// is bit-identical for any number of threads. Used by the error metric and the refit.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <thread>
#include <vector>

namespace qem::core {

inline unsigned resolve_threads(unsigned requested) {
  if (requested > 0) return requested;
  return std::max(1u, std::thread::hardware_concurrency());
}

/// Calls fn(chunk, begin, end) for the chunks [c * chunk_size, (c + 1) * chunk_size) of [0, n) on
/// `threads` threads, the calling thread among them.
template <class Fn>
void for_chunks(std::size_t n, std::size_t chunk_size, unsigned threads, Fn&& fn) {
  const std::size_t chunks = (n + chunk_size - 1) / chunk_size;
  std::atomic<std::size_t> next{0};
  auto work = [&] {
    for (std::size_t c; (c = next.fetch_add(1)) < chunks;)
      fn(c, c * chunk_size, std::min(n, (c + 1) * chunk_size));
  };
  const unsigned extra = unsigned(std::min<std::size_t>(threads, chunks)) - (chunks > 0 ? 1 : 0);
  std::vector<std::thread> pool;
  for (unsigned t = 0; t < extra; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
}

}  // namespace qem::core
