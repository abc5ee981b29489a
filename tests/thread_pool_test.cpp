// for_chunks and side_by_side on the process's thread pool (core/thread_pool.h): every chunk runs
// exactly once whatever the thread count, calls made from inside a chunk (nested) finish, and an
// exception thrown by one chunk reaches the caller and leaves the pool usable.
#include <gtest/gtest.h>

#include <atomic>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "core/parallel_chunks.h"

namespace qem::core {
namespace {

TEST(ThreadPool, EveryChunkRunsOnceForAnyThreadCount) {
  for (unsigned threads : {1u, 2u, 3u, 8u}) {
    for (int repeat = 0; repeat < 20; ++repeat) {  // the pool's threads, reused call after call
      const std::size_t n = 1000 + 37 * std::size_t(repeat);
      std::vector<std::atomic<int>> seen(n);
      for_chunks(n, 64, threads, [&](std::size_t chunk, std::size_t begin, std::size_t end) {
        EXPECT_EQ(begin, chunk * 64);
        for (std::size_t i = begin; i < end; ++i) seen[i].fetch_add(1);
      });
      for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(seen[i].load(), 1) << threads << " threads, item " << i;
    }
  }
}

TEST(ThreadPool, NestedCallsFinishWithEveryChunk) {
  std::atomic<long> sum{0};
  for_chunks(16, 1, 4, [&](std::size_t outer, std::size_t, std::size_t) {
    for_chunks(100, 7, 4, [&](std::size_t, std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) sum += long(outer * 1000 + i);
    });
  });
  long expected = 0;
  for (long outer = 0; outer < 16; ++outer)
    for (long i = 0; i < 100; ++i) expected += outer * 1000 + i;
  EXPECT_EQ(sum.load(), expected);
}

TEST(ThreadPool, AnExceptionReachesTheCallerAndThePoolGoesOn) {
  EXPECT_THROW(for_chunks(50, 1, 3,
                          [&](std::size_t chunk, std::size_t, std::size_t) {
                            if (chunk == 17) throw std::runtime_error("chunk 17");
                          }),
               std::runtime_error);
  std::atomic<int> count{0};
  for_chunks(50, 1, 3, [&](std::size_t, std::size_t, std::size_t) { ++count; });
  EXPECT_EQ(count.load(), 50);
}

TEST(ThreadPool, SideBySideRunsBoth) {
  for (unsigned threads : {1u, 2u}) {
    int first = 0, second = 0;
    side_by_side(threads, [&] { first = 1; }, [&] { second = 2; });
    EXPECT_EQ(first, 1);
    EXPECT_EQ(second, 2);
  }
  EXPECT_THROW(side_by_side(2, [] { throw std::runtime_error("first"); }, [] {}), std::runtime_error);
}

}  // namespace
}  // namespace qem::core
