#include "remora/common/memory.h"

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

} // namespace remora
