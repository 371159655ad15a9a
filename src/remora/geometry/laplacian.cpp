#include "remora/geometry/laplacian.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "remora/common/error.h"
#include "remora/common/parallel.h"
#include "remora/geometry/measures.h"
#include "remora/geometry/per_face.h"

namespace remora {
namespace {

/// The mesh's own vertex positions, as half_cotangents() reads them.
auto own_point(const Mesh& mesh) {
  return [&mesh](VertexHandle v) { return mesh.point(v); };
}

// Doubled area over the longest squared edge (about the smallest angle in radians) at or below
// which a face counts as zero-area: its cotangents would be rounding noise of size up to 1e16.
constexpr double kZeroAreaFace = 1e-12;

/// Half the cotangent of each corner of face f, with the edge opposite it: {weight, edge idx()}
/// per corner; weight 0 for a zero-area face. `point(v)`: vertex v's position.
template <class PointOf>
std::array<std::pair<double, int>, 3> half_cotangents(const Mesh& mesh, FaceHandle f,
                                                      const PointOf& point) {
  const HalfedgeHandle h0 = mesh.halfedge_handle(f);
  const HalfedgeHandle h1 = mesh.next_halfedge_handle(h0);
  const HalfedgeHandle h2 = mesh.next_halfedge_handle(h1);
  // Corner k sits opposite halfedge opposite[k].
  const std::array<HalfedgeHandle, 3> opposite{h1, h2, h0};
  const std::array<Vec3, 3> p{point(mesh.from_vertex_handle(h0)), point(mesh.to_vertex_handle(h0)),
                              point(mesh.to_vertex_handle(h1))};
  // e[k] is the edge opposite corner k.
  const std::array<Vec3, 3> e{p[2] - p[1], p[0] - p[2], p[1] - p[0]};
  const std::array<double, 3> l{e[0].sqrnorm(), e[1].sqrnorm(), e[2].sqrnorm()};
  // The doubled area from the two shortest edges (the most accurate pair).
  const std::size_t longest =
      l[0] >= l[1] && l[0] >= l[2] ? 0 : (l[1] >= l[2] ? std::size_t{1} : std::size_t{2});
  const double twice_area = (e[(longest + 1) % 3] % e[(longest + 2) % 3]).norm();
  std::array<std::pair<double, int>, 3> out;
  for (std::size_t k = 0; k < 3; ++k) {
    out[k] = {0.0, mesh.edge_handle(opposite[k]).idx()};
    if (!(twice_area > kZeroAreaFace * l[longest])) continue;
    // The corner's edge vectors are -e[k+1] and e[k+2]; cot = their dot / |their cross|.
    out[k].first = 0.5 * (-(e[(k + 1) % 3] | e[(k + 2) % 3]) / twice_area);
  }
  return out;
}

/// W_ij for every edge, indexed by edge idx() (0 for deleted edges). The faces' cotangents are
/// computed in parallel and added in face order: the same sums as one sequential loop.
std::vector<double> edge_weights(const Mesh& mesh) {
  const auto halves = per_face<std::array<std::pair<double, int>, 3>>(
      mesh, [&](FaceHandle f) { return half_cotangents(mesh, f, own_point(mesh)); });
  std::vector<double> weights(mesh.n_edges(), 0.0);
  for (const FaceHandle f : mesh.faces())
    for (const auto& [w, e] : halves[static_cast<std::size_t>(f.idx())])
      weights[static_cast<std::size_t>(e)] += w;
  return weights;
}

/// W_ij of edge e, its faces' halves added in face order, as edge_weights() adds them.
template <class PointOf>
double edge_weight(const Mesh& mesh, EdgeHandle e, const PointOf& point) {
  FaceHandle faces[2] = {mesh.face_handle(mesh.halfedge_handle(e, 0)),
                         mesh.face_handle(mesh.halfedge_handle(e, 1))};
  if (faces[0].idx() > faces[1].idx()) std::swap(faces[0], faces[1]);
  double w = 0.0;
  for (const FaceHandle f : faces) {
    if (!f.is_valid()) continue;
    for (const auto& [half, edge] : half_cotangents(mesh, f, point))
      if (edge == e.idx()) w += half;
  }
  return w;
}

} // namespace

std::vector<double> cotan_edge_weights(const Mesh& mesh) {
  return edge_weights(mesh);
}

double cotan_weight(const Mesh& mesh, EdgeHandle e) {
  return edge_weight(mesh, e, own_point(mesh));
}

double cotan_weight(const Mesh& mesh, const Eigen::MatrixXd& points, EdgeHandle e) {
  return edge_weight(mesh, e, [&](VertexHandle v) {
    return Vec3(points(v.idx(), 0), points(v.idx(), 1), points(v.idx(), 2));
  });
}

Eigen::SparseMatrix<double> weights_matrix(const Mesh& mesh, const std::vector<double>& weights) {
  if (weights.size() != mesh.n_edges())
    throw InvalidArgument("weights_matrix: " + std::to_string(weights.size()) +
                          " edge weights for a mesh with " + std::to_string(mesh.n_edges()) +
                          " edges");
  const std::size_t n = mesh.n_vertices();
  // The diagonal, summed in edge order.
  std::vector<double> diagonal(n, 0.0);
  std::vector<char> has_edge(n, 0);
  for (const EdgeHandle e : mesh.edges()) {
    const HalfedgeHandle h = mesh.halfedge_handle(e, 0);
    const auto i = static_cast<std::size_t>(mesh.from_vertex_handle(h).idx());
    const auto j = static_cast<std::size_t>(mesh.to_vertex_handle(h).idx());
    const double w = weights[static_cast<std::size_t>(e.idx())];
    diagonal[i] -= w;
    diagonal[j] -= w;
    has_edge[i] = has_edge[j] = 1;
  }
  // Column j holds the edges out of j and its diagonal, sorted by row (a halfedge mesh has one
  // edge per pair of vertices). Built in parallel, column by column, in place.
  const auto size = static_cast<Eigen::Index>(n);
  Eigen::SparseMatrix<double> W(size, size);
  int* outer = W.outerIndexPtr();
  outer[0] = 0;
  parallel_for(n, 0, [&](std::size_t j) {
    const VertexHandle v(static_cast<int>(j));
    int count = has_edge[j] ? 1 : 0;
    if (!mesh.status(v).deleted())
      for (auto h = mesh.cvoh_iter(v); h.is_valid(); ++h)
        count += mesh.status(mesh.edge_handle(*h)).deleted() ? 0 : 1;
    outer[j + 1] = count;
  });
  for (std::size_t j = 0; j < n; ++j) outer[j + 1] += outer[j];
  W.resizeNonZeros(outer[n]);
  std::atomic<int> repeated{-1}; // a vertex with two edges to the same neighbour
  int* rows = W.innerIndexPtr();
  double* values = W.valuePtr();
  parallel_for(n, 0, [&](std::size_t j) {
    const VertexHandle v(static_cast<int>(j));
    thread_local std::vector<std::pair<int, double>> entries;
    entries.clear();
    if (has_edge[j]) entries.emplace_back(static_cast<int>(j), diagonal[j]);
    if (!mesh.status(v).deleted())
      for (auto h = mesh.cvoh_iter(v); h.is_valid(); ++h) {
        const EdgeHandle e = mesh.edge_handle(*h);
        if (!mesh.status(e).deleted())
          entries.emplace_back(mesh.to_vertex_handle(*h).idx(),
                               weights[static_cast<std::size_t>(e.idx())]);
      }
    std::sort(entries.begin(), entries.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    for (std::size_t k = 1; k < entries.size(); ++k)
      if (entries[k].first == entries[k - 1].first) repeated = static_cast<int>(j);
    for (std::size_t k = 0; k < entries.size(); ++k) {
      rows[static_cast<std::size_t>(outer[j]) + k] = entries[k].first;
      values[static_cast<std::size_t>(outer[j]) + k] = entries[k].second;
    }
  });
  if (repeated >= 0)
    throw Error("weights_matrix: vertex " + std::to_string(repeated.load()) +
                " has two edges to the same neighbour; the mesh's connectivity is corrupt");
  return W;
}

Eigen::SparseMatrix<double> cotan_weights(const Mesh& mesh) {
  return weights_matrix(mesh, edge_weights(mesh));
}

double laplacian_symmetry_defect(const Mesh& mesh, SymmetryRows rows) {
  const std::vector<double> weights = edge_weights(mesh);
  const Eigen::VectorXd areas = vertex_areas_mixed(mesh);
  // Per row of W: the diagonal and the sum of the squared off-diagonal entries.
  std::vector<double> diagonal(mesh.n_vertices(), 0.0);
  std::vector<double> squares(mesh.n_vertices(), 0.0);
  for (const EdgeHandle e : mesh.edges()) {
    const HalfedgeHandle h = mesh.halfedge_handle(e, 0);
    const int i = mesh.from_vertex_handle(h).idx();
    const int j = mesh.to_vertex_handle(h).idx();
    const double w = weights[e.idx()];
    diagonal[i] -= w;
    diagonal[j] -= w;
    squares[i] += w * w;
    squares[j] += w * w;
  }
  double area_sum = 0.0;
  std::size_t counted = 0;
  const auto counts = [&](VertexHandle v) {
    return !mesh.is_isolated(v) && (rows == SymmetryRows::All || !mesh.is_boundary(v));
  };
  for (const VertexHandle v : mesh.vertices()) {
    if (!counts(v)) continue;
    area_sum += areas[v.idx()];
    ++counted;
  }
  if (counted == 0 || !(area_sum > 0.0)) return 0.0;
  const double mean = area_sum / static_cast<double>(counted);
  // Row i of A^-1 W is row i of W over A_i; of A_bar^-1 W over A_bar. Their difference is row i of
  // W times (A_bar - A_i) / (A_i A_bar), which is exactly 0 when the areas are equal.
  double difference = 0.0;
  double norm = 0.0;
  for (const VertexHandle v : mesh.vertices()) {
    const double a = areas[v.idx()];
    if (!counts(v) || !(a > 0.0)) continue;
    const double row = squares[v.idx()] + diagonal[v.idx()] * diagonal[v.idx()];
    const double scale = (mean - a) / (a * mean);
    difference += row * scale * scale;
    norm += row / (a * a);
  }
  return norm > 0.0 ? std::sqrt(difference / norm) : 0.0;
}

} // namespace remora
