#include "huge_pages.h"

#include <sys/mman.h>

#include <cstdlib>
#include <new>
#include <string_view>

namespace qem::cli {

AddressRange whole_huge_pages(const void* p, std::size_t bytes) {
  const std::uintptr_t at = reinterpret_cast<std::uintptr_t>(p);
  AddressRange r;
  r.begin = (at + kHugePageBytes - 1) & ~std::uintptr_t(kHugePageBytes - 1);
  r.end = (at + bytes) & ~std::uintptr_t(kHugePageBytes - 1);
  if (r.end < r.begin) r.end = r.begin;
  return r;
}

bool huge_pages_wanted(const char* setting) { return !setting || std::string_view(setting) != "0"; }

}  // namespace qem::cli

namespace {

// The advice on a large block's whole huge pages, before anything touches them (glibc gives a
// block this large fresh pages of its own mapping, or reused heap whose advice is kept). The
// partial pages at its two ends stay small: aligning each block to whole huge pages took the
// faults of the 10M-face torus from 181k to 137k but its peak memory up by 100 MB (6 %), a
// rounding per live block. A kernel without transparent huge pages refuses the advice: the block
// is used as it is.
void* advised(void* p, std::size_t bytes) {
  if (!p) throw std::bad_alloc();
  static const bool wanted = qem::cli::huge_pages_wanted(std::getenv("QEM_HUGE_PAGES"));
  if (bytes >= qem::cli::kAdvisedFromBytes && wanted) {
    const qem::cli::AddressRange r = qem::cli::whole_huge_pages(p, bytes);
    if (r.end > r.begin) madvise(reinterpret_cast<void*>(r.begin), r.end - r.begin, MADV_HUGEPAGE);
  }
  return p;
}

void* allocate(std::size_t bytes) { return advised(std::malloc(bytes ? bytes : 1), bytes); }

void* allocate_aligned(std::size_t bytes, std::align_val_t align) {
  const std::size_t a = std::size_t(align);
  if (bytes > SIZE_MAX - a) throw std::bad_alloc();
  return advised(std::aligned_alloc(a, (bytes + a - 1) / a * a), bytes);  // a multiple of a, as it asks
}

}  // namespace

// The replaceable forms that the others (nothrow, sized) fall back on in libstdc++.
void* operator new(std::size_t bytes) { return allocate(bytes); }
void* operator new[](std::size_t bytes) { return allocate(bytes); }
void* operator new(std::size_t bytes, std::align_val_t align) { return allocate_aligned(bytes, align); }
void* operator new[](std::size_t bytes, std::align_val_t align) { return allocate_aligned(bytes, align); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
