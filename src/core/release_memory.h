// Handing the memory a finished phase freed back to the system before the next phase allocates.
#pragma once

#include <cstddef>

namespace qem::core {

/// Returns the allocator's free memory to the system (glibc: malloc_trim; elsewhere nothing).
/// glibc keeps freed blocks below its mmap threshold, which grows to 32 MB as large blocks are
/// freed, in its heaps, one per thread's arena: after the parts of a partitioned run, or the
/// core's working arrays, most of a gigabyte on a 10M-face input stayed resident under the
/// refit's own arrays, and the run's peak was their sum.
void release_free_memory();

/// From this many faces a phase's freed memory is handed back (docs/benchmarks.md, "Partitioned,
/// every core"): on small inputs the pages given back would only be faulted in again by the next
/// phase, a cost of their own.
inline constexpr std::size_t kReleaseFromFaces = 1'000'000;

/// release_free_memory() when the phase that ends worked on at least kReleaseFromFaces faces.
inline void release_free_memory_after(std::size_t faces) {
  if (faces >= kReleaseFromFaces) release_free_memory();
}

}  // namespace qem::core
