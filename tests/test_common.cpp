// common/: the data-parallel loop, the allocator settings of the apps and the wall clock.
#include <atomic>
#include <chrono>
#include <cstddef>
#include <stdexcept>
#include <thread>
#include <vector>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <gtest/gtest.h>

#include "remora/common/memory.h"
#include "remora/common/parallel.h"
#include "remora/common/timer.h"

namespace remora {
namespace {

TEST(ParallelFor, VisitsEveryIndexOnceWhateverTheThreadCount) {
  for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{1024}, std::size_t{1025},
                        std::size_t{100003}}) {
    for (int threads : {1, 2, 0}) {
      std::vector<std::atomic<int>> visits(n);
      parallel_for(n, threads, [&](std::size_t i) { visits[i].fetch_add(1); });
      for (std::size_t i = 0; i < n; ++i)
        ASSERT_EQ(visits[i].load(), 1) << "n = " << n << ", threads = " << threads << ", i = " << i;
    }
  }
}

TEST(ParallelFor, WithSerialOpenMpRunsTheRegionsItOpensOnOneThread) {
  if (omp_get_max_threads() < 2 || omp_get_max_active_levels() > 1)
    GTEST_SKIP() << "needs two threads and libgomp's default of one active level";
  int outside = 0, inside = 0;
#pragma omp parallel num_threads(4)
  {
#pragma omp master
    outside = omp_get_num_threads();
  }
  with_serial_openmp([&] {
#pragma omp parallel num_threads(4)
    {
#pragma omp master
      inside = omp_get_num_threads();
    }
  });
  EXPECT_GT(outside, 1);
  EXPECT_EQ(inside, 1);
  // What the body throws comes out of it.
  EXPECT_THROW(with_serial_openmp([] { throw std::runtime_error("from the body"); }),
               std::runtime_error);
}

// GCC defines __SANITIZE_ADDRESS__ under AddressSanitizer; clang 14 only answers __has_feature.
#if defined(__SANITIZE_ADDRESS__)
#define REMORA_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define REMORA_TEST_ASAN 1
#endif
#endif

TEST(Memory, KeepFreedMemoryServesLargeBlocksFromTheHeap) {
#if !defined(__GLIBC__) || defined(REMORA_TEST_ASAN)
  GTEST_SKIP() << "glibc's allocator only (the sanitizers bring their own)";
#else
  ASSERT_TRUE(keep_freed_memory());
  // 64 MiB is above glibc's largest automatic mmap threshold (32 MiB): by default such a block
  // is a fresh mapping, counted in hblkhd, and unmapped on free.
  const std::size_t mapped_before = mallinfo2().hblkhd;
  {
    std::vector<char> big(std::size_t{64} << 20, 1);
    EXPECT_EQ(mallinfo2().hblkhd, mapped_before) << "the block was mapped, not taken from the heap";
  }
#endif
}

TEST(Memory, KeepFreedMemoryServesAnotherThreadsLargeBlocksFromTheHeap) {
#if !defined(__GLIBC__) || defined(REMORA_TEST_ASAN)
  GTEST_SKIP() << "glibc's allocator only (the sanitizers bring their own)";
#else
  ASSERT_TRUE(keep_freed_memory());
  // A thread of its own arena grows it in mappings of at most 64 MiB: a 64 MiB block would be a
  // fresh mapping, counted in hblkhd, whatever the thresholds.
  const std::size_t mapped_before = mallinfo2().hblkhd;
  std::size_t mapped_during = 0;
  std::thread([&] {
    std::vector<char> big(std::size_t{64} << 20, 1);
    mapped_during = mallinfo2().hblkhd;
  }).join();
  EXPECT_EQ(mapped_during, mapped_before)
      << "the thread's block was mapped, not taken from the heap";
#endif
}

// After warm_heap(64 MiB), a block of 48 MiB comes from warm pages: writing all of it faults in
// almost nothing (without the warming, about 12,000 pages of 4 KiB).
TEST(Memory, WarmHeapLeavesPagesThatALaterBlockReusesWithoutFaults) {
#if !defined(__GLIBC__) || defined(REMORA_TEST_ASAN)
  GTEST_SKIP() << "glibc's allocator only (the sanitizers bring their own)";
#else
  ASSERT_TRUE(keep_freed_memory());
  const std::size_t page = 4096, warm = std::size_t{64} << 20, later = std::size_t{48} << 20;
  warm_heap(warm);
  const std::uint64_t before = minor_page_faults();
  {
    std::vector<char> block(later, 1);
    EXPECT_EQ(block[later - 1], 1);
  }
  EXPECT_LT(minor_page_faults() - before, later / page / 20)
      << "the block was not served from warm pages";
  EXPECT_LT(warm_heap(warm), warm / page / 20) << "warming warm pages again faulted";
#endif
}

TEST(Timer, MsSinceIsTheElapsedSteadyTimeInMilliseconds) {
  const Clock::time_point t0 = Clock::now();
  EXPECT_GE(ms_since(t0), 0.0);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  // Bracketed by two readings of the same clock: the unit is the millisecond, not the tick.
  const Clock::time_point before = Clock::now();
  const double ms = ms_since(t0);
  const Clock::time_point after = Clock::now();
  const auto to_ms = [](Clock::duration d) {
    return std::chrono::duration<double, std::milli>(d).count();
  };
  EXPECT_GE(ms, 20.0); // sleep_for waits at least that long
  EXPECT_GE(ms, to_ms(before - t0));
  EXPECT_LE(ms, to_ms(after - t0));
}

} // namespace
} // namespace remora
