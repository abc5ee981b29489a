// The command-line tool's large allocations are advised for transparent huge pages
// (madvise(MADV_HUGEPAGE)), as glibc's malloc does for its own with
// GLIBC_TUNABLES=glibc.malloc.hugetlb=1. A run over millions of faces allocates arrays of hundreds
// of megabytes, many anew in each stage (the core's lists, the refit's projections, the trees),
// and each small page of them costs a page fault when first touched; a huge page stands for 512 of
// them, and for as many TLB entries. Whether that is faster depends on the machine: on a virtual
// machine whose host backs the guest with small pages, a huge page faulted for the first time can
// cost more than its 512 small ones (docs/benchmarks.md, "Measurements behind the code", has both
// cases). QEM_HUGE_PAGES=0 in the environment turns the advice off. The library does not do it (a
// program that links it chooses its own allocator): the command line replaces operator new and
// delete (cli/huge_pages.cpp).
//
// The small blocks and glibc's own heap get the same from glibc itself: `with_malloc_tunables`
// starts the program again with GLIBC_TUNABLES asking malloc for huge pages on its heaps
// (hugetlb=1), to grow its heap 64 MB at a time (top_pad) and never to hand freed memory back to
// the kernel (trim and mmap thresholds), so that a stage's arrays reuse the pages of the stage
// before instead of faulting in fresh ones. glibc reads those only when a program starts (mallopt
// has no huge pages and caps its mmap threshold at 32 MB), hence the second start.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

// AddressSanitizer's build keeps the sanitizer's operator new (see huge_pages.cpp).
#if defined(__SANITIZE_ADDRESS__)
#define QEM_SANITIZED_ALLOCATOR 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define QEM_SANITIZED_ALLOCATOR 1
#endif
#endif
#ifndef QEM_SANITIZED_ALLOCATOR
#define QEM_SANITIZED_ALLOCATOR 0
#endif

namespace qem::cli {

/// Whether this build's operator new gives the advice (all but AddressSanitizer's).
inline constexpr bool kAdvisesHugePages = !QEM_SANITIZED_ALLOCATOR;

inline constexpr std::size_t kHugePageBytes = std::size_t(2) << 20;
/// Allocations from this size on are advised: two huge pages, so that at least one whole huge
/// page lies inside any such block.
inline constexpr std::size_t kAdvisedFromBytes = std::size_t(4) << 20;

/// The whole huge pages inside [p, p + bytes): [begin, end), empty (begin == end) when none.
struct AddressRange {
  std::uintptr_t begin = 0, end = 0;
};
AddressRange whole_huge_pages(const void* p, std::size_t bytes);

/// Whether the advice is given, from the value of QEM_HUGE_PAGES (null: not set): all but "0".
bool huge_pages_wanted(const char* setting);

/// The tunables with_malloc_tunables adds to GLIBC_TUNABLES.
inline constexpr const char* kMallocTunables =
    "glibc.malloc.hugetlb=1:glibc.malloc.top_pad=67108864:glibc.malloc.mmap_threshold=4294967295:"
    "glibc.malloc.trim_threshold=4294967295";

/// What GLIBC_TUNABLES should be for a run whose environment has `tunables` (null: not set): the
/// user's with kMallocTunables after them, or null (leave it) when the user tunes malloc already.
const char* tuned_malloc_environment(const char* tunables, std::string& storage);

/// A second start costs about what the first did (the kernel's exec and the loader's work again),
/// which the tunables win back only on inputs of some 15,000 faces and more: the size of the
/// largest file an argument names from which the second start is made (docs/benchmarks.md).
inline constexpr std::uintmax_t kMallocTunedFromBytes = std::uintmax_t(256) << 10;

/// The size of the largest regular file named by one of `argv`'s arguments (0: none).
std::uintmax_t largest_file_named(char** argv);

/// Called first in main: if an argument names a file of `from_bytes` or more
/// (largest_file_named), and unless QEM_HUGE_PAGES=0, the user's GLIBC_TUNABLES tune malloc
/// already, the program runs under valgrind, or this build keeps AddressSanitizer's allocator, starts the
/// program again (execv of the file /proc/self/exe links to: the same process, arguments and descriptors)
/// with kMallocTunables added. In the program so started it puts the environment back as the user had it
/// (children never see the tunables) and returns. If the second start fails, it returns and the run goes on
/// untuned.
void with_malloc_tunables(char** argv, std::uintmax_t from_bytes = kMallocTunedFromBytes);

}  // namespace qem::cli
