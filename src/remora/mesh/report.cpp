// The repair report's text and JSON forms.
#include <nlohmann/json.hpp>

#include "remora/common/text.h"
#include "remora/mesh/repair.h"

namespace remora {

namespace {
const auto grouped = group_thousands;
} // namespace

std::vector<std::string> describe(const RepairReport& r) {
  std::vector<std::string> lines;
  auto add = [&](std::size_t n, const std::string& what) {
    if (n > 0) lines.push_back(grouped(n) + " " + what);
  };
  add(r.unreferenced_vertices, "unreferenced vertices dropped");
  add(r.welded_vertices, "coincident vertices welded");
  add(r.near_welded_vertices, "vertices welded to a vertex within the weld tolerance");
  if (r.polygons_triangulated > 0)
    lines.push_back(grouped(r.polygons_triangulated) + " polygons triangulated into " +
                    grouped(r.polygons_triangulated + r.triangles_added_by_triangulation) +
                    " triangles");
  add(r.dropped_degenerate_polygon, "faces with fewer than 3 corners dropped");
  add(r.dropped_repeated_vertex, "faces with a repeated vertex dropped");
  add(r.dropped_duplicate, "duplicate faces dropped");
  add(r.dropped_flap, "faces dropped that doubled up into zero-thickness flaps");
  add(r.orphaned_vertices, "vertices dropped with their faces");
  add(r.flipped_faces, "faces flipped to orient their component consistently");
  add(r.orientation_cuts, "edges cut where the orientation conflicts (non-orientable)");
  add(r.nonmanifold_edges, "non-manifold edges split");
  if (r.split_vertices > 0)
    lines.push_back(grouped(r.split_vertices) + " non-manifold vertices split (" +
                    grouped(r.vertices_added_by_split) + " copies added)");
  add(r.faces_detached, "faces detached onto their own vertices");
  add(r.zero_area_faces, "zero-area faces (kept)");
  return lines;
}

nlohmann::json to_json(const RepairReport& r) {
  return {{"vertices_in", r.vertices_in},
          {"polygons_in", r.polygons_in},
          {"triangles_in", r.triangles_in()},
          {"unreferenced_vertices", r.unreferenced_vertices},
          {"welded_vertices", r.welded_vertices},
          {"near_welded_vertices", r.near_welded_vertices},
          {"orphaned_vertices", r.orphaned_vertices},
          {"split_vertices", r.split_vertices},
          {"vertices_added_by_split", r.vertices_added_by_split},
          {"polygons_triangulated", r.polygons_triangulated},
          {"triangles_added_by_triangulation", r.triangles_added_by_triangulation},
          {"dropped_degenerate_polygon", r.dropped_degenerate_polygon},
          {"dropped_repeated_vertex", r.dropped_repeated_vertex},
          {"dropped_duplicate", r.dropped_duplicate},
          {"dropped_flap", r.dropped_flap},
          {"components_in", r.components_in},
          {"faces_dropped", r.faces_dropped()},
          {"flipped_faces", r.flipped_faces},
          {"orientation_cuts", r.orientation_cuts},
          {"nonmanifold_edges", r.nonmanifold_edges},
          {"faces_detached", r.faces_detached},
          {"zero_area_faces", r.zero_area_faces},
          {"vertices_loaded", r.vertices_loaded},
          {"faces_loaded", r.faces_loaded}};
}

nlohmann::json to_json(const LoadReport& r) {
  return {{"path", r.path},
          {"format", r.file.format},
          {"encoding", r.file.encoding},
          {"vertices_in_file", r.file.vertices_in_file},
          {"faces_in_file", r.file.faces_in_file},
          {"skipped", r.file.skipped},
          {"repair", to_json(r.repair)}};
}

} // namespace remora
