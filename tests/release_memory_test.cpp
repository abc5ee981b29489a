// core::release_free_memory hands freed heap memory back to the system: the resident set falls.
#include "core/release_memory.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

namespace {

// Resident pages of this process, in bytes (Linux); 0 when unknown.
std::size_t resident_bytes() {
  long pages = 0, resident = 0;
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return 0;
  const bool read = std::fscanf(f, "%ld %ld", &pages, &resident) == 2;
  std::fclose(f);
  return read ? std::size_t(resident) * std::size_t(sysconf(_SC_PAGESIZE)) : 0;
}

// `count` blocks of 64 KB (below glibc's mmap threshold: they come from the heap), written, then
// all freed but the last, which keeps the heap's top where it is: glibc gives nothing back by
// itself. Returns the last block (free it at the end) and sets `freed` to the bytes freed.
std::unique_ptr<char[]> freed_heap_blocks(std::size_t count, std::size_t& freed) {
  constexpr std::size_t kBlock = 64 * 1024;
  std::vector<std::unique_ptr<char[]>> blocks;
  for (std::size_t i = 0; i < count; ++i) {
    blocks.emplace_back(new char[kBlock]);
    std::memset(blocks.back().get(), int(i), kBlock);
  }
  freed = kBlock * (count - 1);
  return std::move(blocks.back());  // the others are freed here
}

// Only glibc's own allocator (not a sanitizer's) keeps freed blocks that malloc_trim hands back,
// and only Linux says how much is resident.
class ReleaseMemory : public ::testing::Test {
 protected:
  void SetUp() override {
#if !defined(__GLIBC__) || defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
    GTEST_SKIP() << "glibc's own allocator only";
#endif
    if (resident_bytes() == 0) GTEST_SKIP() << "no /proc/self/statm";
  }
};

}  // namespace

// 64 MB of freed heap blocks: after release_free_memory the resident set is at least half of
// that lower.
TEST_F(ReleaseMemory, FreedHeapBlocksLeaveTheResidentSet) {
  std::size_t freed = 0;
  const std::unique_ptr<char[]> last = freed_heap_blocks(1024, freed);
  const std::size_t before = resident_bytes();
  qem::core::release_free_memory();
  const std::size_t after = resident_bytes();
  EXPECT_LT(after + freed / 2, before) << "resident " << before << " -> " << after << " bytes";
}

// Below kReleaseFromFaces nothing is handed back (the next phase would fault the pages in again).
TEST_F(ReleaseMemory, SmallPhasesKeepTheirMemory) {
  std::size_t freed = 0;
  const std::unique_ptr<char[]> last = freed_heap_blocks(512, freed);
  const std::size_t before = resident_bytes();
  qem::core::release_free_memory_after(qem::core::kReleaseFromFaces - 1);
  EXPECT_GT(resident_bytes() + freed / 2, before);
  qem::core::release_free_memory_after(qem::core::kReleaseFromFaces);
  EXPECT_LT(resident_bytes() + freed / 2, before);
}
