// remesh_patch(): the steps of remesh() on a patch of an earlier remesh with a locked boundary
// (remesh.h), for the editor's local bake.
#include <string>

#include <fmt/format.h>

#include "remora/common/error.h"
#include "remora/common/timer.h"
#include "remora/remesh/remesh.h"
#include "remora/remesh/remesher.h"

namespace remora {

namespace {

using namespace remesh_detail;

bool valid_on(const Mesh& mesh, const SurfacePoint& sp) {
  return sp.face.is_valid() && static_cast<std::size_t>(sp.face.idx()) < mesh.n_faces();
}

void check_patch(const Mesh& reference, const RemeshPatch& patch, const RemeshOptions& options) {
  const std::size_t n = patch.mesh.n_vertices();
  if (patch.on_reference.size() != n || patch.outside_area.size() != n ||
      patch.valence_target.size() != n || patch.reference_on_mesh.size() != reference.n_vertices())
    throw InvalidArgument(fmt::format(
        "remesh_patch: {} vertices, but {} locations on the reference, {} outside areas and {} "
        "valence targets; {} reference vertices, but {} of their locations",
        n, patch.on_reference.size(), patch.outside_area.size(), patch.valence_target.size(),
        reference.n_vertices(), patch.reference_on_mesh.size()));
  if (!(options.target_length > 0) || !(patch.target_area > 0))
    throw InvalidArgument("remesh_patch: the target length and area must be positive (those of "
                          "the whole mesh)");
  if (options.feature_angle_deg > 0)
    throw InvalidArgument("remesh_patch: feature lines are not supported (feature_angle_deg 0)");
  bool boundary = false;
  for (auto v : patch.mesh.vertices()) {
    boundary = boundary || patch.mesh.is_boundary(v);
    if (!patch.mesh.is_isolated(v) &&
        !valid_on(reference, patch.on_reference[static_cast<std::size_t>(v.idx())]))
      throw InvalidArgument(
          fmt::format("remesh_patch: vertex {} has no location on the reference", v.idx()));
  }
  if (!boundary) throw InvalidArgument("remesh_patch: the patch has no boundary to lock");
  for (const SurfacePoint& sp : patch.reference_on_mesh)
    if (sp.face.is_valid() && !valid_on(patch.mesh, sp))
      throw InvalidArgument("remesh_patch: a reference vertex is located on no face of the patch");
}

} // namespace

RemeshPatchResult remesh_patch(const Mesh& reference, const RemeshPatch& patch,
                               const RemeshOptions& options) {
  check_options(reference, options);
  check_patch(reference, patch, options);
  const auto t_total = Clock::now();
  RemeshOptions o = options;
  o.boundary_spacing = 1.0; // the boundary is locked
  RemeshPatchResult result;
  RemeshReport& report = result.report;
  Remesher rm(reference, patch.mesh, o);
  report.target_length = rm.length;
  rm.locked_boundary = true;
  rm.target_area = patch.target_area;
  rm.outside_area = patch.outside_area;
  rm.valence_target = patch.valence_target;
  // No curve vertex: the boundary is all corners and no boundary edge is split, so the
  // reference's boundary (its own border, a cut of a larger surface) is never walked along.
  rm.input_curve.assign(reference.n_edges(), 0);
  for (auto v : rm.mesh.vertices()) {
    const auto i = static_cast<std::size_t>(v.idx());
    rm.loc(v) = patch.on_reference[i];
    const bool locked = rm.mesh.is_boundary(v) || rm.mesh.is_isolated(v);
    rm.kind(v) = locked ? Kind::Corner : Kind::Interior;
    rm.origin(v) = locked ? v.idx() : -1;
  }
  init_points(rm, patch.reference_on_mesh);
  run_steps(rm, report);
  finish_correspondence(rm, result.output_on_reference, result.reference_on_output, report);
  result.origin.resize(rm.mesh.n_vertices());
  for (auto v : rm.mesh.vertices()) result.origin[static_cast<std::size_t>(v.idx())] = rm.origin(v);
  rm.take_mesh(result.mesh);
  report.milliseconds["total"] = ms_since(t_total);
  return result;
}

} // namespace remora
