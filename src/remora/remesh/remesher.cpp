#include "remora/remesh/remesher.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "remora/common/error.h"
#include "remora/geometry/measures.h"

namespace remora::remesh_detail {

Remesher::Remesher(const Mesh& input_mesh, const RemeshOptions& remesh_options)
    : input(input_mesh), options(remesh_options), mesh(input_mesh) {
  add_properties();
  set_lengths();
}

Remesher::Remesher(const Mesh& input_mesh, const Mesh& working, const RemeshOptions& remesh_options)
    : input(input_mesh), options(remesh_options), mesh(working) {
  add_properties();
  set_lengths();
}

void Remesher::set_lengths() {
  const LengthScale scale = length_scale(input);
  length = options.target_length > 0 ? options.target_length : options.length_factor * scale.length;
  length_from_area = options.target_length <= 0 && scale.needles;
  if (!std::isfinite(length) || length <= 0)
    throw InvalidArgument("remesh: the target edge length must be positive and finite (got " +
                          std::to_string(length) + ")");
  // Bounded work: a remesh at length l has about area / (√3/4 l²) faces. Splitting stops at
  // eight times that (plus the input's own count), whatever the geometry does.
  max_faces = static_cast<std::size_t>(std::min(
                  1e9, 8.0 * surface_area(input) / (std::sqrt(3.0) / 4.0 * length * length))) +
              2 * input.n_faces();
  live_faces = mesh.n_faces();
  lo2 = (0.8 * length) * (0.8 * length);
  guard_rad = options.equalize_guard_deg * M_PI / 180.0;
  cos_guard = std::cos(guard_rad);
  hi = 4.0 / 3.0 * length;
  hi2 = hi * hi;
  flat_cross = 1e-6 * length * length;
}

void Remesher::add_properties() {
  mesh.add_property(vertex_state_);
  mesh.add_property(feature_);
  mesh.add_property(points_);
}

void Remesher::adopt_renumbered(Mesh&& renumbered, const MeshOrder& order) {
  OpenMesh::VPropHandleT<VertexState> vertex_state;
  OpenMesh::EPropHandleT<char> feature;
  OpenMesh::FPropHandleT<PointList> points;
  renumbered.add_property(vertex_state);
  renumbered.add_property(feature);
  renumbered.add_property(points);
  for (std::size_t r = 0; r < order.vertices.size(); ++r)
    renumbered.property(vertex_state, VertexHandle(static_cast<int>(r))) =
        mesh.property(vertex_state_, VertexHandle(order.vertices[r]));
  for (std::size_t r = 0; r < order.edges.size(); ++r)
    renumbered.property(feature, EdgeHandle(static_cast<int>(r))) =
        mesh.property(feature_, EdgeHandle(order.edges[r]));
  for (std::size_t r = 0; r < order.faces.size(); ++r)
    renumbered.property(points, FaceHandle(static_cast<int>(r))) =
        mesh.property(points_, FaceHandle(order.faces[r]));
  mesh = std::move(renumbered);
  vertex_state_ = vertex_state;
  feature_ = feature;
  points_ = points;
}

void Remesher::take_mesh(Mesh& out) {
  mesh.remove_property(vertex_state_);
  mesh.remove_property(feature_);
  mesh.remove_property(points_);
  out = std::move(mesh);
}

} // namespace remora::remesh_detail
