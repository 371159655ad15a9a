// The local bake's patch (bake.h, step 3): the base faces to remesh again, and the part of S'
// under them, each as a mesh of its own.
#include <cmath>

#include <fmt/format.h>

#include "remora/geometry/measures.h"
#include "remora/mesh/topology.h"
#include "remora/multires/bake_steps.h"
#include "remora/multires/face_patch.h"

namespace remora::bake_detail {

namespace {

// The patch's locked (border) vertices: their mixed area in the faces outside the patch (at B')
// and their valence target in the patch (bake.h; RemeshPatch).
void locked_vertices(const Bake& b, PatchMeshes& m) {
  const TriangleTopology& t = b.old.topology;
  RemeshPatch& p = m.patch;
  const std::size_t n = m.patch_vertices.size();
  p.outside_area.assign(n, 0.0);
  p.valence_target.assign(n, 6);
  auto point = [&](int v) {
    return Vec3(b.base_points(v, 0), b.base_points(v, 1), b.base_points(v, 2));
  };
  for (std::size_t l = 0; l < n; ++l) {
    const VertexHandle local(static_cast<int>(l));
    if (!p.mesh.is_boundary(local)) continue;
    const int v = m.patch_vertices[l];
    const VertexHandle whole(v);
    for (int k = t.vertex_offsets[std::size_t(v)]; k < t.vertex_offsets[std::size_t(v) + 1]; ++k) {
      const int f = t.vertex_faces[static_cast<std::size_t>(k)];
      if (b.patch[static_cast<std::size_t>(f)]) continue;
      const auto& fv = t.faces[static_cast<std::size_t>(f)];
      const auto parts = triangle_mixed_areas(point(fv[0]), point(fv[1]), point(fv[2]));
      for (int c = 0; c < 3; ++c)
        if (fv[static_cast<std::size_t>(c)] == v)
          p.outside_area[l] += parts[static_cast<std::size_t>(c)];
    }
    const int outside =
        static_cast<int>(b.old.base.valence(whole)) - static_cast<int>(p.mesh.valence(local));
    p.valence_target[l] = (b.old.base.is_boundary(whole) ? 4 : 6) - outside;
  }
}

} // namespace

bool select_patch(Bake& b) {
  const TriangleTopology& t = b.old.topology;
  const std::size_t nf = t.faces.size();
  b.patch.assign(nf, 0);
  std::vector<char> checked(nf, 0);
  std::vector<int> faces;
  const double tolerance = b.settings.distortion;
  auto length2 = [](const Eigen::MatrixXd& p, int i, int j) {
    return (p.row(i) - p.row(j)).squaredNorm();
  };
  for (std::size_t v = 0; v < b.moved.size(); ++v) {
    if (!b.moved[v]) continue;
    for (int k = t.vertex_offsets[v]; k < t.vertex_offsets[v + 1]; ++k) {
      const int f = t.vertex_faces[static_cast<std::size_t>(k)];
      if (checked[static_cast<std::size_t>(f)]) continue;
      checked[static_cast<std::size_t>(f)] = 1;
      const auto& fv = t.faces[static_cast<std::size_t>(f)];
      for (int c = 0; c < 3; ++c) {
        const int i = fv[static_cast<std::size_t>(c)],
                  j = fv[static_cast<std::size_t>((c + 1) % 3)];
        const double ratio =
            std::sqrt(length2(b.base_points, i, j) / length2(b.old.base_rest, i, j));
        if (!(std::abs(ratio - 1.0) <= tolerance)) {
          b.patch[static_cast<std::size_t>(f)] = 1;
          faces.push_back(f);
          break;
        }
      }
    }
  }
  if (faces.empty()) return false;
  grow_rings(t, b.settings.rings, b.patch, faces);
  close_patch(b.old.base, t, true, b.patch, faces);
  b.report.patch_faces = faces.size();
  if (static_cast<double>(faces.size()) > b.settings.max_fraction * static_cast<double>(nf))
    throw NotLocal(
        fmt::format("the patch to remesh holds {} of the {} base faces", faces.size(), nf));
  return true;
}

PatchMeshes patch_meshes(const Bake& b) {
  PatchMeshes m;
  const TriangleTopology& t = b.old.topology;
  const TriangleTopology& ti = b.old.input_topology;
  // The patch: B' on its faces, in face order.
  std::vector<int> faces;
  for (std::size_t f = 0; f < b.patch.size(); ++f)
    if (b.patch[f]) faces.push_back(static_cast<int>(f));
  std::vector<int> local(t.vertex_offsets.size() - 1, -1);
  m.patch.mesh = sub_mesh(t, b.base_points, faces, local, m.patch_vertices);
  std::vector<int> patch_face(b.patch.size(), -1);
  for (std::size_t i = 0; i < faces.size(); ++i)
    patch_face[static_cast<std::size_t>(faces[i])] = static_cast<int>(i);
  for (const ComponentTopology& c : component_topology(m.patch.mesh))
    if (c.closed) throw NotLocal("the patch covers a whole closed part of the base");
  // The reference: the input faces under the patch's vertices and around every input vertex
  // located on the patch, grown by three rings, S' on them.
  std::vector<char> in(ti.faces.size(), 0);
  std::vector<int> rfaces;
  for (const int v : m.patch_vertices) {
    const int f = b.old.base_on_input[static_cast<std::size_t>(v)].face.idx();
    if (!in[static_cast<std::size_t>(f)]) {
      in[static_cast<std::size_t>(f)] = 1;
      rfaces.push_back(f);
    }
  }
  const auto ni = b.old.input_on_base.size();
  for (std::size_t i = 0; i < ni; ++i) {
    const FaceHandle f = b.old.input_on_base[i].face;
    if (f.is_valid() && b.patch[static_cast<std::size_t>(f.idx())])
      add_fan(ti, static_cast<int>(i), in, rfaces);
  }
  grow_rings(ti, 3, in, rfaces);
  close_patch(b.old.input, ti, false, in, rfaces);
  std::sort(rfaces.begin(), rfaces.end());
  std::vector<int> rlocal(ni, -1);
  m.reference = sub_mesh(ti, b.smooth, rfaces, rlocal, m.reference_vertices);
  m.reference_faces = rfaces;
  b.report.reference_faces = rfaces.size();
  std::vector<int> reference_face(ti.faces.size(), -1);
  for (std::size_t i = 0; i < rfaces.size(); ++i)
    reference_face[static_cast<std::size_t>(rfaces[i])] = static_cast<int>(i);
  // Both ways between them.
  RemeshPatch& p = m.patch;
  p.on_reference.resize(m.patch_vertices.size());
  for (std::size_t l = 0; l < m.patch_vertices.size(); ++l) {
    const SurfacePoint& sp = b.old.base_on_input[static_cast<std::size_t>(m.patch_vertices[l])];
    p.on_reference[l] = {FaceHandle(reference_face[static_cast<std::size_t>(sp.face.idx())]),
                         sp.bary};
  }
  p.reference_on_mesh.assign(m.reference_vertices.size(),
                             SurfacePoint{FaceHandle(), {1.0, 0.0, 0.0}});
  for (std::size_t r = 0; r < m.reference_vertices.size(); ++r) {
    const SurfacePoint& sp = b.old.input_on_base[static_cast<std::size_t>(m.reference_vertices[r])];
    if (sp.face.is_valid() && b.patch[static_cast<std::size_t>(sp.face.idx())])
      p.reference_on_mesh[r] = {FaceHandle(patch_face[static_cast<std::size_t>(sp.face.idx())]),
                                sp.bary};
  }
  locked_vertices(b, m);
  p.target_area = b.old.report.base_quality.mixed_area.mean;
  if (!(p.target_area > 0)) throw NotLocal("the base's mean vertex area is not known");
  return m;
}

} // namespace remora::bake_detail
