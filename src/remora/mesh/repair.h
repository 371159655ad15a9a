// Turning a polygon soup into a manifold half-edge Mesh without dropping anything silently.
//
// Steps, each counted in RepairReport, in this order:
//  1. drop vertices no polygon references;
//  2. weld coincident vertices (bit-identical coordinates, -0 == +0; STL shares no vertices),
//     then vertices closer than weld_tolerance x the bounding-box diagonal (CAD exports whose
//     patches meet at 1e-16 instead of 0 would otherwise keep cracks along every seam);
//  3. triangulate polygons with more than three corners (ear clipping in the best-fit plane);
//  4. drop triangles with a repeated vertex (after welding; PLY strip "swap" triangles), and
//     duplicate triangles (the same three vertices in any order; the first is kept, or none when
//     the copies form a zero-thickness flap hinged on one edge);
//  5. orient the triangles consistently per connected component (closed components outward, open
//     ones keeping the majority of the file's winding); a non-orientable component is cut where the
//     orientation conflicts;
//  6. split non-manifold edges (more than two triangles) and non-manifold vertices (more than
//     one fan of triangles) by duplicating vertices, so the half-edge build accepts every triangle.
// Zero-area triangles are kept and counted: later stages cope with them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "remora/mesh/mesh.h"
#include "remora/mesh/soup.h"

namespace remora {

struct RepairOptions {
  bool weld = true; ///< weld bit-identical vertices, and near ones (weld_tolerance)
  /// Vertices closer than this x the bounding-box diagonal are merged into the first of them in
  /// file order (0: bit-identical ones only). 1e-10 is far below any real feature and far above
  /// double rounding at the coordinates' scale.
  double weld_tolerance = 1e-10;
  bool orient = true;  ///< make the orientation consistent per component
  bool outward = true; ///< closed components: normals point outward (positive signed volume)
};

struct RepairReport {
  // What came in.
  std::size_t vertices_in = 0; ///< soup vertices
  std::size_t polygons_in = 0; ///< soup polygons (faces as stored in the file)
  // Vertices.
  std::size_t unreferenced_vertices = 0; ///< referenced by no polygon; dropped
  std::size_t welded_vertices = 0;       ///< merged into a bit-identical vertex
  std::size_t near_welded_vertices = 0;  ///< merged into a vertex within the weld tolerance
  std::size_t split_vertices = 0;        ///< non-manifold vertices (more than one fan), each split
  std::size_t vertices_added_by_split = 0; ///< copies created by splitting (and by detaching)
  std::size_t orphaned_vertices = 0; ///< left without a triangle once dropped ones were removed
  // Faces: triangles_in = polygons_in + triangles_added_by_triangulation
  //                     = faces_loaded + dropped_repeated_vertex + dropped_duplicate +
  //                       dropped_flap + dropped_degenerate_polygon (= faces_loaded +
  //                       faces_dropped()).
  std::size_t polygons_triangulated = 0;            ///< polygons with more than three corners
  std::size_t triangles_added_by_triangulation = 0; ///< extra triangles they became
  std::size_t dropped_degenerate_polygon = 0;       ///< polygons with fewer than three corners
  std::size_t dropped_repeated_vertex = 0; ///< triangles using one vertex twice (after welding)
  std::size_t dropped_duplicate = 0;       ///< the same vertex triple as an earlier triangle
  std::size_t dropped_flap = 0; ///< both copies of a triangle listed twice as a zero-thickness flap
  std::size_t flipped_faces = 0;     ///< triangles whose winding was reversed
  std::size_t orientation_cuts = 0;  ///< edges cut because orientations conflict (non-orientable)
  std::size_t nonmanifold_edges = 0; ///< edges with more than two triangles, split
  std::size_t faces_detached = 0;    ///< triangles given vertex copies of their own (not expected)
  std::size_t components_in =
      0; ///< components of the welded triangles (sharing vertices), before splits
  std::size_t zero_area_faces = 0; ///< area <= 1e-12 * (bounding-box diagonal)^2, kept
  // What came out.
  std::size_t vertices_loaded = 0;
  std::size_t faces_loaded = 0;

  std::size_t triangles_in() const { return polygons_in + triangles_added_by_triangulation; }
  // vertices_in = unreferenced + welded + near_welded + orphaned + vertices_loaded
  //               - vertices_added_by_split.
  std::size_t faces_dropped() const {
    return dropped_repeated_vertex + dropped_duplicate + dropped_flap + dropped_degenerate_polygon;
  }
};

/// A file's account: what the reader saw and what the repair changed.
struct LoadReport {
  std::string path;
  FileInfo file;
  RepairReport repair;
};

struct RepairResult {
  Mesh mesh;
  RepairReport report;
  /// For every vertex of `mesh` (by index), the soup vertex it came from.
  std::vector<std::uint32_t> source_vertex;
};

/// Builds a manifold, consistently oriented half-edge mesh from `soup`. Throws InvalidArgument if a
/// polygon references a vertex that does not exist. An empty result is not an error here (the
/// readers decide); check report.faces_loaded.
RepairResult repair_soup(const PolygonSoup& soup, const RepairOptions& options = {});

/// One line per repair step that changed something ("welded 12,888 coincident vertices", ...);
/// empty when the soup needed no repair.
std::vector<std::string> describe(const RepairReport& report);

/// Every counter under a stable snake_case key.
nlohmann::json to_json(const RepairReport& report);
nlohmann::json to_json(const LoadReport& report);

/// Faces with area <= kZeroAreaRelative * (bounding-box diagonal)^2.
std::size_t count_zero_area_faces(const Mesh& mesh);

} // namespace remora
