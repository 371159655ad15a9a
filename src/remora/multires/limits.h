// The sizes the apps accept (the CLI's edit and remesh, the server) and how they follow from the
// editor's measured memory, so that a mesh or a region too large for the machine is refused with
// a message before the memory is allocated instead of ending in the out-of-memory killer
// (docs/limits.md has the measurements).
#pragma once

#include <cstddef>
#include <cstdint>

namespace remora {

/// The share of the physical memory the limits plan with; the rest is left to the system and to
/// other programs.
inline constexpr double kMemoryShare = 0.75;

/// Peak resident memory of the editor's preprocessing per input triangle (loading, base surface,
/// area-equalizing remesh, correspondence, and a small region), which is linear in the mesh: the
/// peak measured with `remora edit`, with a margin (docs/limits.md, "How the defaults were
/// chosen").
inline constexpr std::uint64_t kEditorBytesPerTriangle = 1536;

/// Memory of a region per free base vertex for k = 1, 2, 3 (index k - 1), with one handle: the
/// sparse Cholesky factor (which grows a little faster than the region), the basis functions and
/// the Phong details; measured with supports covering a whole mesh, with a margin that holds up
/// to the mesh limit (docs/limits.md, "How the defaults were chosen").
inline constexpr std::uint64_t kRegionBytesPerFreeVertex[3] = {2048, 4096, 8192};

/// The memory each of `editors` editors alive at once may plan with: kMemoryShare of
/// `memory_bytes`, split evenly. 0 (no limit) when the memory is unknown (0).
std::uint64_t editor_memory_share(std::uint64_t memory_bytes, int editors = 1);

/// What the mesh limit plans per triangle: the preprocessing and a region covering the whole mesh
/// at k = 2 (a remeshed base has about half a free base vertex per input triangle, at
/// kRegionBytesPerFreeVertex[1] each; docs/limits.md, "How the defaults were chosen").
inline constexpr std::uint64_t kMeshBytesPerTriangle = kEditorBytesPerTriangle + 2048;

/// The most triangles an editor fits in editor_memory_share() with a region over all of them at
/// k = 2 (kMeshBytesPerTriangle; at least 1; 0 when the memory is unknown).
std::uint64_t editor_triangle_limit(std::uint64_t memory_bytes, int editors = 1);

/// The estimated memory of a region of `free_vertices` free base vertices at order k with
/// `handles` handles (each handle beyond the first adds 4 basis columns and 4 solutions).
std::uint64_t region_bytes(std::size_t free_vertices, int k, int handles);

/// How much heap an app warms after building an editor (common/memory.h, warm_heap()): a
/// region over every base vertex at order k (region_bytes), at most kWarmHeapBytes. The first
/// regions then fault in no fresh pages (docs/server.md, "A warm heap").
inline constexpr std::uint64_t kWarmHeapBytes = std::uint64_t(256) << 20;
std::uint64_t warm_heap_bytes(std::size_t base_vertices, int k);

/// The handles an edit may have. Each handle adds four solutions to set_region and four columns
/// per free vertex to the basis every frame blends (n_free x (3 + 4h) doubles): at 16 handles
/// 536 bytes per free vertex (docs/limits.md, "How the defaults were chosen", has the basis of a
/// region over a whole mesh).
inline constexpr int kMaxHandles = 16;

} // namespace remora
