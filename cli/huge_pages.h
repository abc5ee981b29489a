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
#pragma once

#include <cstddef>
#include <cstdint>

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

}  // namespace qem::cli
