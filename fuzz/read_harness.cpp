// run_reader() and run_harness() of harness.h.
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include <OpenMesh/Tools/Utils/MeshCheckerT.hh>

#include "harness.h"
#include "inputs.h"
#include "remora/common/error.h"
#include "remora/mesh/io.h"

namespace remora::fuzz {

namespace {

[[noreturn]] void fail(const std::string& what) {
  throw CheckFailed(what);
}

void check(bool ok, const std::string& what) {
  if (!ok) fail(what);
}

/// The file a variant reads, and its name (the extension names the format).
std::pair<std::string, std::string> file_of(ReaderVariant variant, std::string_view input) {
  switch (variant) {
  case ReaderVariant::Obj:
    return {std::string(input), "fuzz.obj"};
  case ReaderVariant::Off:
    return {std::string(input), "fuzz.off"};
  case ReaderVariant::PlyAscii:
    return {std::string(input), "fuzz.ply"};
  case ReaderVariant::PlyBinary:
    return {ply_file(input, PlyVariant::Binary), "fuzz.ply"};
  case ReaderVariant::PlyTristrips:
    return {ply_file(input, PlyVariant::Tristrips), "fuzz.ply"};
  case ReaderVariant::StlAscii:
    return {std::string(input), "fuzz.stl"};
  case ReaderVariant::StlBinary:
    return {binary_stl_file(input), "fuzz.stl"};
  }
  throw std::invalid_argument("unknown reader variant");
}

/// What every loaded mesh promises (io.h, repair.h, docs/io.md): faces, finite points, a valid
/// manifold half-edge structure of triangles, a source for every vertex, an account that
/// balances.
void check_loaded(const LoadResult& r) {
  const Mesh& m = r.mesh;
  const RepairReport& a = r.report.repair;
  check(m.n_faces() > 0, "a loaded mesh without faces");
  check(a.faces_loaded == m.n_faces() && a.vertices_loaded == m.n_vertices(),
        "the report's loaded counts differ from the mesh");
  check(a.triangles_in() == a.faces_loaded + a.faces_dropped(),
        "the face account does not balance");
  check(a.vertices_in + a.vertices_added_by_split == a.unreferenced_vertices + a.welded_vertices +
                                                         a.near_welded_vertices +
                                                         a.orphaned_vertices + a.vertices_loaded,
        "the vertex account does not balance");
  check(r.source_vertex.size() == m.n_vertices(), "source_vertex has the wrong size");
  for (const std::uint32_t s : r.source_vertex)
    check(s < a.vertices_in, "a source vertex beyond the file's vertices");
  for (const VertexHandle v : m.vertices()) {
    const Vec3& p = m.point(v);
    check(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]), "a non-finite point");
    check(m.is_manifold(v), "a non-manifold vertex");
  }
  for (const FaceHandle f : m.faces()) check(m.valence(f) == 3, "a face that is not a triangle");
  std::ostringstream problems;
  if (!OpenMesh::Utils::MeshCheckerT<Mesh>(m).check(OpenMesh::Utils::MeshCheckerT<Mesh>::CHECK_ALL,
                                                    problems))
    fail("the half-edge structure is inconsistent: " + problems.str());
}

} // namespace

void run_reader(ReaderVariant variant, std::string_view input) {
  const auto [file, name] = file_of(variant, input);
  LoadResult loaded;
  try {
    loaded = read_mesh_from_memory(file, format_from_path(name), name);
  } catch (const IoError&) {
    return; // the clean refusal every malformed file gets
  }
  check_loaded(loaded);
  // Loading is idempotent: the loaded mesh, written exactly (binary PLY of doubles) and read
  // again, loads with the same faces.
  const std::string again = write_mesh_to_memory(loaded.mesh, MeshFormat::Ply, "again.ply");
  const LoadResult reloaded = read_mesh_from_memory(again, MeshFormat::Ply, "again.ply");
  check(reloaded.mesh.n_faces() == loaded.mesh.n_faces(),
        "a loaded mesh written and read again has " + std::to_string(reloaded.mesh.n_faces()) +
            " faces instead of " + std::to_string(loaded.mesh.n_faces()));
}

void run_harness(const std::string& name, std::string_view input) {
  static const std::pair<const char*, ReaderVariant> readers[] = {
      {"obj", ReaderVariant::Obj},
      {"off", ReaderVariant::Off},
      {"ply_ascii", ReaderVariant::PlyAscii},
      {"ply_binary", ReaderVariant::PlyBinary},
      {"ply_tristrips", ReaderVariant::PlyTristrips},
      {"stl_ascii", ReaderVariant::StlAscii},
      {"stl_binary", ReaderVariant::StlBinary}};
  for (const auto& [reader, variant] : readers)
    if (name == reader) return run_reader(variant, input);
  if (name == "edit_request") return run_edit_request(input);
  if (name == "server") return run_server_script(input);
  throw std::invalid_argument("no fuzz harness '" + name + "'");
}

} // namespace remora::fuzz
