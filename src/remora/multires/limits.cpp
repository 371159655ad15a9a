#include "remora/multires/limits.h"

#include <algorithm>

namespace remora {

std::uint64_t editor_memory_share(std::uint64_t memory_bytes, int editors) {
  return static_cast<std::uint64_t>(kMemoryShare * double(memory_bytes) / std::max(editors, 1));
}

std::uint64_t editor_triangle_limit(std::uint64_t memory_bytes, int editors) {
  if (memory_bytes == 0) return 0;
  return std::max<std::uint64_t>(1, editor_memory_share(memory_bytes, editors) /
                                        kMeshBytesPerTriangle);
}

std::uint64_t region_bytes(std::size_t free_vertices, int k, int handles) {
  const std::uint64_t per_vertex = kRegionBytesPerFreeVertex[std::clamp(k, 1, 3) - 1] +
                                   64 * static_cast<std::uint64_t>(std::max(handles - 1, 0));
  return per_vertex * free_vertices;
}

std::uint64_t warm_heap_bytes(std::size_t base_vertices, int k) {
  return std::min(region_bytes(base_vertices, k, 1), kWarmHeapBytes);
}

} // namespace remora
