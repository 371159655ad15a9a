// Process-wide allocator settings for the apps (the library itself never calls this).
#pragma once

#include <cstddef>
#include <cstdint>

namespace remora {

/// The machine's physical memory in bytes (sysconf), 0 where it cannot be told.
std::uint64_t physical_memory_bytes();

/// Asks the C library to serve large allocations from its heap instead of fresh mappings, from
/// every thread (one arena), and not to hand freed memory back to the system before exit. A
/// remesh of a million triangles allocates and frees hundreds of megabytes per phase (a
/// compaction copies the whole mesh), and `remora serve` runs each job on a thread of its own;
/// with fresh mappings every page is faulted in again each time (docs/benchmarks.md and
/// docs/server.md have the cost). The price: the process keeps its peak heap until it exits.
/// Called once at the start of `remora` and of the benchmarks, before any thread allocates
/// (glibc hands a new thread an arena left by a thread that ended before it counts arenas). The
/// settings hold for the whole process, a host program's own threads included. A no-op where
/// the C library is not glibc. Returns whether the settings took effect.
bool keep_freed_memory();

/// Allocates `bytes`, writes a byte of every page and frees them, so that under
/// keep_freed_memory() a later allocation of up to that size finds pages already faulted in
/// (where a page's first touch is slow, as on a VM, a region's factor otherwise pays for each of
/// its pages; docs/server.md, "A warm heap"). Cheap where the heap already holds a free block
/// that large (its pages are warm). Returns the page faults it took (getrusage's minor
/// faults of the process, so other threads' count too); 0 and nothing done when the allocation
/// fails.
std::uint64_t warm_heap(std::size_t bytes);

/// The process's minor page faults so far (getrusage), 0 where it cannot be told.
std::uint64_t minor_page_faults();

} // namespace remora
