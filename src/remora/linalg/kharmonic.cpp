#include "remora/linalg/kharmonic.h"

#include <algorithm>
#include <string>

#include "remora/common/error.h"
#include "remora/geometry/laplacian.h"
#include "remora/geometry/measures.h"
#include "remora/mesh/topology.h"

namespace remora {

namespace {

using RowMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;
using Triplet = Eigen::Triplet<double>;

void validate(const Mesh& mesh, const Region& region, const KHarmonicOptions& options) {
  if (options.k < 1 || options.k > 3)
    throw InvalidArgument("k-harmonic system: k = " + std::to_string(options.k) +
                          " is not supported; use 1, 2 or 3");
  const std::size_t n = mesh.n_vertices();
  if (region.label.size() != n)
    throw InvalidArgument("k-harmonic system: the region has " +
                          std::to_string(region.label.size()) + " labels for a mesh of " +
                          std::to_string(n) + " vertices; give one per vertex");
  for (std::size_t i = 0; i < n; ++i)
    if (region.label[i] < Region::kFixed)
      throw InvalidArgument("k-harmonic system: vertex " + std::to_string(i) + " has label " +
                            std::to_string(region.label[i]) +
                            "; use -1 (free), -2 (fixed) or a handle index >= 0");
  if (region.free_count() == 0)
    throw InvalidArgument("k-harmonic system: no vertex is free; the support is empty");

  // Every handle has a vertex and touches a free vertex.
  const int handles = region.handle_count();
  std::vector<char> has_vertex(static_cast<std::size_t>(handles), 0),
      touches_free(static_cast<std::size_t>(handles), 0);
  for (auto v : mesh.vertices()) {
    const int j = region.label[static_cast<std::size_t>(v.idx())];
    if (j < 0) continue;
    has_vertex[static_cast<std::size_t>(j)] = 1;
    for (auto w : mesh.vv_range(v))
      if (region.label[static_cast<std::size_t>(w.idx())] == Region::kFree)
        touches_free[static_cast<std::size_t>(j)] = 1;
  }
  for (int j = 0; j < handles; ++j) {
    if (!has_vertex[static_cast<std::size_t>(j)])
      throw InvalidArgument("k-harmonic system: handle " + std::to_string(j) +
                            " has no vertex (handles are numbered 0.." +
                            std::to_string(handles - 1) + " without gaps)");
    if (!touches_free[static_cast<std::size_t>(j)])
      throw InvalidArgument("k-harmonic system: handle " + std::to_string(j) +
                            " touches no free vertex, so moving it would move nothing; put it "
                            "inside or next to the support");
  }

  // Every component with a free vertex has a constrained one.
  const Components components = connected_components(mesh);
  std::vector<int> free_witness(static_cast<std::size_t>(components.count), -1);
  std::vector<char> constrained(static_cast<std::size_t>(components.count), 0);
  for (auto v : mesh.vertices()) {
    const int c = components.vertex_component[static_cast<std::size_t>(v.idx())];
    if (c < 0) continue;
    if (region.label[static_cast<std::size_t>(v.idx())] == Region::kFree) {
      if (free_witness[static_cast<std::size_t>(c)] < 0)
        free_witness[static_cast<std::size_t>(c)] = v.idx();
    } else {
      constrained[static_cast<std::size_t>(c)] = 1;
    }
  }
  for (int c = 0; c < components.count; ++c)
    if (free_witness[static_cast<std::size_t>(c)] >= 0 && !constrained[static_cast<std::size_t>(c)])
      throw InvalidArgument(
          "k-harmonic system: the support covers a whole connected component of the mesh (the "
          "one with vertex " +
          std::to_string(free_witness[static_cast<std::size_t>(c)]) +
          ") with no fixed or handle vertex, so its position is undetermined; fix at least one "
          "vertex of that component or make the support smaller");
}

// Numbers the free vertices in vertex order: system.free_vertices and system.row_of (-1 for a
// vertex that is not free), over the region's n labels.
void number_free_vertices(const Region& region, KHarmonicSystem& system) {
  const auto n = static_cast<Eigen::Index>(region.label.size());
  system.row_of.assign(static_cast<std::size_t>(n), -1);
  for (Eigen::Index v = 0; v < n; ++v)
    if (region.label[static_cast<std::size_t>(v)] == Region::kFree) {
      system.row_of[static_cast<std::size_t>(v)] = static_cast<int>(system.free_vertices.size());
      system.free_vertices.push_back(static_cast<int>(v));
    }
}

// The inverse vertex areas of the inner factors: 1 / mixed area, floored at 1e-12 times the mean
// positive area; all 1 for Mean (the Ā^k factor drops out of the rows).
Eigen::VectorXd inverse_areas(const Mesh& mesh, AreaWeights areas) {
  const auto n = static_cast<Eigen::Index>(mesh.n_vertices());
  Eigen::VectorXd inverse_area = Eigen::VectorXd::Ones(n);
  if (areas == AreaWeights::Mean) return inverse_area;
  const Eigen::VectorXd area = vertex_areas_mixed(mesh);
  double mean = 0;
  Eigen::Index counted = 0;
  for (Eigen::Index v = 0; v < n; ++v)
    if (area[v] > 0) {
      mean += area[v];
      ++counted;
    }
  mean = counted > 0 ? mean / static_cast<double>(counted) : 1.0;
  // A vertex whose faces all have zero area (needles of a raw scan) gets a floor instead of
  // an infinite inverse; its row of W is zero anyway.
  for (Eigen::Index v = 0; v < n; ++v) inverse_area[v] = 1.0 / std::max(area[v], 1e-12 * mean);
  return inverse_area;
}

// Rows `free_vertices` of −W, in that order (free × all vertices).
RowMatrix free_rows(const SparseMatrix& minus_w, const std::vector<int>& free_vertices) {
  const auto nf = static_cast<Eigen::Index>(free_vertices.size());
  RowMatrix rows(nf, minus_w.cols());
  std::vector<Triplet> triplets;
  triplets.reserve(static_cast<std::size_t>(nf) * 7);
  for (Eigen::Index r = 0; r < nf; ++r) {
    const int v = free_vertices[static_cast<std::size_t>(r)];
    for (SparseMatrix::InnerIterator it(minus_w, v); it; ++it) // W is symmetric: column = row
      triplets.emplace_back(r, it.row(), it.value());
  }
  rows.setFromTriplets(triplets.begin(), triplets.end());
  return rows;
}

// The free vertices' rows of the k-th power: R = rows F of (−W), then R ← R · A⁻¹(−W) for each
// further power; for Mixed areas each row is then scaled by its vertex's inverse area.
RowMatrix power_rows(const SparseMatrix& minus_w, const Eigen::VectorXd& inverse_area,
                     const std::vector<int>& free_vertices, const KHarmonicOptions& options) {
  RowMatrix rows = free_rows(minus_w, free_vertices);
  if (options.k > 1) {
    const SparseMatrix step = inverse_area.asDiagonal() * minus_w;
    for (int power = 1; power < options.k; ++power) rows = RowMatrix(rows * step);
  }
  if (options.areas == AreaWeights::Mixed)
    for (Eigen::Index r = 0; r < rows.rows(); ++r)
      rows.row(r) *= inverse_area[free_vertices[static_cast<std::size_t>(r)]];
  return rows;
}

// Splits the non-zero entries of `rows` by column: the free vertices' into system.matrix (by
// row_of), the constrained vertices' into system.coupling (numbered in vertex order into
// system.constrained_vertices).
void split_columns(const RowMatrix& rows, KHarmonicSystem& system) {
  const Eigen::Index nf = rows.rows();
  std::vector<int> column_of(static_cast<std::size_t>(rows.cols()), -1);
  std::vector<Triplet> free_part, constrained_part;
  free_part.reserve(static_cast<std::size_t>(rows.nonZeros()));
  for (Eigen::Index r = 0; r < nf; ++r)
    for (RowMatrix::InnerIterator it(rows, r); it; ++it) {
      if (it.value() == 0.0) continue;
      const auto v = static_cast<std::size_t>(it.col());
      if (system.row_of[v] >= 0) {
        free_part.emplace_back(r, system.row_of[v], it.value());
      } else {
        if (column_of[v] < 0) column_of[v] = 0; // numbered below, in vertex order
        constrained_part.emplace_back(r, static_cast<Eigen::Index>(v), it.value());
      }
    }
  for (std::size_t v = 0; v < column_of.size(); ++v)
    if (column_of[v] >= 0) {
      column_of[v] = static_cast<int>(system.constrained_vertices.size());
      system.constrained_vertices.push_back(static_cast<int>(v));
    }
  for (Triplet& t : constrained_part)
    t = Triplet(t.row(), column_of[static_cast<std::size_t>(t.col())], t.value());
  system.matrix.resize(nf, nf);
  system.matrix.setFromTriplets(free_part.begin(), free_part.end());
  system.coupling.resize(nf, static_cast<Eigen::Index>(system.constrained_vertices.size()));
  system.coupling.setFromTriplets(constrained_part.begin(), constrained_part.end());
}

} // namespace

int Region::handle_count() const {
  int h = 0;
  for (int l : label) h = std::max(h, l + 1);
  return h;
}

std::size_t Region::free_count() const {
  return static_cast<std::size_t>(std::count(label.begin(), label.end(), kFree));
}

std::string to_string(AreaWeights weights) {
  switch (weights) {
  case AreaWeights::Mixed:
    return "mixed";
  case AreaWeights::Mean:
    return "mean";
  case AreaWeights::MixedSymmetric:
    return "mixed-symmetric";
  }
  return "?";
}

AreaWeights parse_area_weights(const std::string& name) {
  if (name == "mixed") return AreaWeights::Mixed;
  if (name == "mean") return AreaWeights::Mean;
  if (name == "mixed-symmetric") return AreaWeights::MixedSymmetric;
  throw InvalidArgument("unknown area weighting '" + name +
                        "'; use mixed, mean or mixed-symmetric");
}

Eigen::MatrixXd KHarmonicSystem::rhs(const Eigen::MatrixXd& constrained_values) const {
  if (constrained_values.rows() != coupling.cols())
    throw InvalidArgument("k-harmonic system: " + std::to_string(constrained_values.rows()) +
                          " constrained values given for " + std::to_string(coupling.cols()) +
                          " constrained vertices");
  return -(coupling * constrained_values);
}

Eigen::MatrixXd KHarmonicSystem::gather_constrained(const Eigen::MatrixXd& positions) const {
  Eigen::MatrixXd out(static_cast<Eigen::Index>(constrained_vertices.size()), positions.cols());
  for (std::size_t c = 0; c < constrained_vertices.size(); ++c)
    out.row(static_cast<Eigen::Index>(c)) = positions.row(constrained_vertices[c]);
  return out;
}

KHarmonicSystem assemble_kharmonic(const Mesh& mesh, const Region& region,
                                   const KHarmonicOptions& options) {
  validate(mesh, region, options);
  KHarmonicSystem system;
  system.symmetric = options.areas != AreaWeights::Mixed;
  number_free_vertices(region, system);
  const SparseMatrix minus_w = -cotan_weights(mesh);
  const Eigen::VectorXd inverse_area = inverse_areas(mesh, options.areas);
  split_columns(power_rows(minus_w, inverse_area, system.free_vertices, options), system);
  if (system.symmetric) {
    // Exactly symmetric (the products above agree with their transposes only to round-off).
    const SparseMatrix transposed = system.matrix.transpose();
    system.matrix = 0.5 * (system.matrix + transposed);
  }
  system.matrix.makeCompressed();
  system.coupling.makeCompressed();
  return system;
}

Eigen::MatrixXd positions_matrix(const Mesh& mesh) {
  Eigen::MatrixXd p(static_cast<Eigen::Index>(mesh.n_vertices()), 3);
  for (auto v : mesh.all_vertices()) {
    const Vec3& q = mesh.point(v);
    p.row(v.idx()) << q[0], q[1], q[2];
  }
  return p;
}

void set_positions(Mesh& mesh, const Eigen::MatrixXd& positions) {
  if (positions.rows() != static_cast<Eigen::Index>(mesh.n_vertices()) || positions.cols() != 3)
    throw InvalidArgument("set_positions: " + std::to_string(positions.rows()) + " x " +
                          std::to_string(positions.cols()) + " positions for a mesh of " +
                          std::to_string(mesh.n_vertices()) + " vertices (n x 3 expected)");
  for (auto v : mesh.all_vertices()) {
    const auto r = positions.row(v.idx());
    mesh.set_point(v, Vec3(r[0], r[1], r[2]));
  }
}

} // namespace remora
