// A polygon soup: what a mesh file says, before any repair. Readers fill it; repair.h turns it
// into a half-edge Mesh without dropping anything silently.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "remora/mesh/mesh.h"

namespace remora {

/// Polygons in compressed-row form: polygon f has the vertex ids
/// indices[offsets[f]] .. indices[offsets[f+1]-1], in the file's winding order.
struct PolygonSoup {
  std::vector<Vec3> points;
  std::vector<std::uint32_t> offsets{0};
  std::vector<std::uint32_t> indices;

  std::size_t num_polygons() const { return offsets.size() - 1; }
  std::size_t polygon_size(std::size_t f) const { return offsets[f + 1] - offsets[f]; }
  void add_polygon(const std::uint32_t* ids, std::size_t n) {
    indices.insert(indices.end(), ids, ids + n);
    offsets.push_back(static_cast<std::uint32_t>(indices.size()));
  }
  void add_triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    const std::uint32_t t[3] = {a, b, c};
    add_polygon(t, 3);
  }
};

/// What a reader saw in the file besides the soup itself.
struct FileInfo {
  std::string format;               ///< "obj", "off", "ply", "stl"
  std::string encoding;             ///< "ascii", "binary_little_endian", "binary_big_endian"
  std::size_t vertices_in_file = 0; ///< vertex records in the file
  std::size_t faces_in_file =
      0; ///< faces as stored (polygons; for PLY tristrips the triangles the strips encode)
  std::vector<std::string>
      skipped; ///< what was read past on purpose, e.g. "element camera (1)", "12 'vt' lines"
};

/// What a reader accepts (0 = no limit). A file over a limit is refused with an IoError before
/// the memory for it is allocated: counts a header declares (PLY, OFF, binary STL) are checked as
/// the header is read, the records of files without such counts (OBJ, ascii STL) as they are
/// read, and the triangles polygons and strips make once the file is read, before the repair.
struct ReadLimits {
  std::uint64_t max_triangles = 0; ///< triangles (a polygon of n corners makes n - 2)
  /// Vertex records: 3 per triangle, what an STL of max_triangles holds.
  std::uint64_t max_vertices() const { return 3 * max_triangles; }
};

/// A soup read from a file together with what the reader saw.
struct SoupFile {
  PolygonSoup soup;
  FileInfo info;
};

} // namespace remora
