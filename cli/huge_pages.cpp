#include "huge_pages.h"

#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
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

const char* tuned_malloc_environment(const char* tunables, std::string& storage) {
  if (!tunables || !*tunables) return kMallocTunables;
  if (std::string_view(tunables).find("glibc.malloc.") != std::string_view::npos) return nullptr;
  storage = std::string(tunables) + ":" + kMallocTunables;
  return storage.c_str();
}

namespace {
// Set in the environment of the second start: "-" when the user had no GLIBC_TUNABLES, else "="
// and the user's value.
constexpr const char* kStartedAgain = "QEM_MALLOC_TUNED";

// GLIBC_TUNABLES as the user had it (null: unset), and no marker.
void restore_environment(const char* user_tunables) {
  if (user_tunables)
    setenv("GLIBC_TUNABLES", user_tunables, 1);
  else
    unsetenv("GLIBC_TUNABLES");
  unsetenv(kStartedAgain);
}
}  // namespace

std::uintmax_t largest_file_named(char** argv) {
  std::uintmax_t largest = 0;
  for (char** a = argv + 1; *a; ++a) {
    struct stat st;
    if (stat(*a, &st) == 0 && S_ISREG(st.st_mode)) largest = std::max(largest, std::uintmax_t(st.st_size));
  }
  return largest;
}

void with_malloc_tunables(char** argv, std::uintmax_t from_bytes) {
  if (const char* again = std::getenv(kStartedAgain)) {
    restore_environment(again[0] == '=' ? again + 1 : nullptr);
    return;
  }
  if (!kAdvisesHugePages || !huge_pages_wanted(std::getenv("QEM_HUGE_PAGES"))) return;
  if (!argv || !argv[0] || largest_file_named(argv) < from_bytes) return;
  // Under valgrind (its preloaded core), whose tools would not follow the second start by default:
  // the profile would be of the first start alone.
  if (const char* preload = std::getenv("LD_PRELOAD");
      preload && std::string_view(preload).find("vgpreload") != std::string_view::npos)
    return;
  const char* user = std::getenv("GLIBC_TUNABLES");
  std::string storage;
  const char* tuned = tuned_malloc_environment(user, storage);
  if (!tuned) return;
  const std::string had = user ? std::string("=") + user : std::string("-");
  setenv(kStartedAgain, had.c_str(), 1);
  setenv("GLIBC_TUNABLES", tuned, 1);
  // The program's own path, not /proc/self/exe, whose name ("exe") ps and top would show.
  char self[4096];
  const ssize_t length = readlink("/proc/self/exe", self, sizeof self - 1);
  if (length > 0) {
    self[length] = 0;
    execv(self, argv);
  }
  // Not started again (no /proc, say): the environment as it was, and on untuned.
  restore_environment(user);
}

}  // namespace qem::cli

#if !QEM_SANITIZED_ALLOCATOR
namespace {

// The advice on a large block's whole huge pages, before anything touches them (glibc gives a
// block this large fresh pages of its own mapping, or reused heap whose advice is kept). The
// partial pages at its two ends stay small: aligning each block to whole huge pages saved a few
// more faults but raised the peak memory by a rounding per live block (docs/benchmarks.md). A
// kernel without transparent huge pages refuses the advice: the block is used as it is.
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

// Every replaceable form, so that each block is freed by the allocator that made it whichever form
// the standard library calls (std::stable_sort's buffer: nothrow new, sized delete). Not under
// AddressSanitizer, whose own forms check that new meets delete and new[] meets delete[].
void* operator new(std::size_t bytes) { return allocate(bytes); }
void* operator new[](std::size_t bytes) { return allocate(bytes); }
void* operator new(std::size_t bytes, const std::nothrow_t&) noexcept {
  try {
    return allocate(bytes);
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}
void* operator new[](std::size_t bytes, const std::nothrow_t& tag) noexcept {
  return operator new(bytes, tag);
}
void* operator new(std::size_t bytes, std::align_val_t align) { return allocate_aligned(bytes, align); }
void* operator new[](std::size_t bytes, std::align_val_t align) { return allocate_aligned(bytes, align); }
void* operator new(std::size_t bytes, std::align_val_t align, const std::nothrow_t&) noexcept {
  try {
    return allocate_aligned(bytes, align);
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}
void* operator new[](std::size_t bytes, std::align_val_t align, const std::nothrow_t& tag) noexcept {
  return operator new(bytes, align, tag);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
#endif
