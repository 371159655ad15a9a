// read_mesh(): a reader followed by the repair, and the report's text and JSON forms.
#include "remora/common/error.h"
#include "remora/mesh/io.h"
#include "remora/mesh/repair.h"

namespace remora {

namespace {

LoadResult repair_file(SoupFile file, const std::string& name, const RepairOptions& options) {
  RepairResult repaired = repair_soup(file.soup, options);
  if (repaired.mesh.n_faces() == 0)
    throw IoError(name, "no faces left to load: all " +
                            std::to_string(repaired.report.triangles_in()) +
                            " triangles were degenerate or duplicates");
  LoadResult result;
  result.mesh = std::move(repaired.mesh);
  result.source_vertex = std::move(repaired.source_vertex);
  result.report.path = name;
  result.report.file = std::move(file.info);
  result.report.repair = repaired.report;
  return result;
}

} // namespace

LoadResult read_mesh(const std::string& path, const RepairOptions& options,
                     const ReadLimits& limits) {
  return repair_file(read_soup(path, limits), path, options);
}

LoadResult read_mesh_from_memory(std::string_view bytes, MeshFormat format, const std::string& name,
                                 const RepairOptions& options, const ReadLimits& limits) {
  return repair_file(read_soup_from_memory(bytes, format, name, limits), name, options);
}

} // namespace remora
