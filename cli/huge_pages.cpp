// Large arrays on transparent huge pages (Linux), for the qem executable only.
//
// A multi-million-face mesh needs a few hundred MB of flat arrays (positions, quadrics, faces,
// pairs, per-vertex lists), and each array is written once from start to end right after it is
// allocated. With 4 KiB pages that is one page fault per 4 KiB: on the virtual machines our users
// (and our benchmarks) run on, those faults were a large part of the simplifier's setup time
// (docs/benchmarks.md, "Measurements behind the code"). Kernels that leave transparent huge pages
// to `madvise` (Debian's default) serve a region marked MADV_HUGEPAGE with 2 MiB pages, 512 times
// fewer faults. So the executable replaces the global allocation functions: blocks of 4 MiB or
// more are 2 MiB-aligned and marked; smaller ones are plain malloc. Everything is released with
// free(), which accepts both.
//
// The library itself does not do this: applications own their allocator. Under AddressSanitizer
// the replacement is left out, so the sanitizer's own new/delete checks stay in force.
#include <cstdlib>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define QEM_NO_HUGE_PAGE_NEW 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define QEM_NO_HUGE_PAGE_NEW 1
#endif

#if defined(__linux__) && !defined(QEM_NO_HUGE_PAGE_NEW)

namespace {

constexpr std::size_t kHugePage = std::size_t(2) << 20;
constexpr std::size_t kHugeThreshold = std::size_t(4) << 20;

void* allocate(std::size_t size) {
  if (size >= kHugeThreshold) {
    const std::size_t rounded = (size + kHugePage - 1) / kHugePage * kHugePage;
    if (void* p = std::aligned_alloc(kHugePage, rounded)) {
      madvise(p, rounded, MADV_HUGEPAGE);  // advice only: failure changes nothing
      return p;
    }
  }
  return std::malloc(size == 0 ? 1 : size);
}

void* allocate_or_throw(std::size_t size) {
  for (;;) {
    if (void* p = allocate(size)) return p;
    std::new_handler handler = std::get_new_handler();
    if (!handler) throw std::bad_alloc();
    handler();
  }
}

}  // namespace

void* operator new(std::size_t size) { return allocate_or_throw(size); }
void* operator new[](std::size_t size) { return allocate_or_throw(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return allocate(size); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return allocate(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }

#endif
