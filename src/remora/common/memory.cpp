#include "remora/common/memory.h"

#include <sys/resource.h>
#include <unistd.h>

#include <cstdlib> // defines __GLIBC__ under glibc

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace remora {

std::uint64_t physical_memory_bytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  return pages > 0 && page > 0 ? std::uint64_t(pages) * std::uint64_t(page) : 0;
}

bool keep_freed_memory() {
#if defined(__GLIBC__)
  constexpr int kGiB = 1 << 30;
  // Allocations below 1 GiB come from the heap; the heap's top is returned only above 1 GiB free;
  // every thread allocates from that one heap (a thread's own arena grows in mappings of at most
  // 64 MiB, so a thread's large blocks are fresh mappings whatever the thresholds).
  return mallopt(M_MMAP_THRESHOLD, kGiB) == 1 && mallopt(M_TRIM_THRESHOLD, kGiB) == 1 &&
         mallopt(M_ARENA_MAX, 1) == 1;
#else
  return false;
#endif
}

std::uint64_t minor_page_faults() {
  rusage u{};
  return getrusage(RUSAGE_SELF, &u) == 0 ? static_cast<std::uint64_t>(u.ru_minflt) : 0;
}

std::uint64_t warm_heap(std::size_t bytes) {
  const std::uint64_t before = minor_page_faults();
  auto* block = static_cast<volatile char*>(std::malloc(bytes));
  if (block == nullptr) return 0;
  const auto page =
      static_cast<std::size_t>(sysconf(_SC_PAGESIZE) > 0 ? sysconf(_SC_PAGESIZE) : 4096);
  for (std::size_t i = 0; i < bytes; i += page) block[i] = 0;
  std::free(const_cast<char*>(block));
  return minor_page_faults() - before;
}

} // namespace remora
