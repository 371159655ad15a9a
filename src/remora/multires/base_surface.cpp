#include "remora/multires/base_surface.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <queue>
#include <utility>
#include <vector>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCore>
#include <fmt/format.h>

#include "remora/common/error.h"
#include "remora/geometry/measures.h"
#include "remora/geometry/thickness.h"

namespace remora {

namespace {

void check_options(const LowPassOptions& o) {
  if (!(o.smoothing >= 0.0) || !std::isfinite(o.smoothing) || !(o.feature_cap >= 0.0) ||
      !std::isfinite(o.feature_cap) || !(o.cap_slope > 0.0) || !std::isfinite(o.cap_slope) ||
      o.steps < 1 || !(o.tolerance > 0.0))
    throw InvalidArgument(fmt::format(
        "low-pass filter: smoothing {} and feature_cap {} must be finite and >= 0, cap_slope {} "
        "finite and > 0, steps {} >= 1, tolerance {} > 0",
        o.smoothing, o.feature_cap, o.cap_slope, o.steps, o.tolerance));
}

} // namespace

Eigen::VectorXd smoothing_field(const Mesh& mesh, double sigma, const LowPassOptions& options) {
  check_options(options);
  if (!(sigma >= 0.0) || !std::isfinite(sigma))
    throw InvalidArgument(fmt::format("low-pass filter: σ {} must be finite and >= 0", sigma));
  const auto n = static_cast<Eigen::Index>(mesh.n_vertices());
  Eigen::VectorXd field = Eigen::VectorXd::Constant(n, sigma);
  if (options.feature_cap == 0.0 || sigma == 0.0) return field;
  // Faces met closer than a thousandth of σ are the vertex's own folds, not the far side; a
  // half-width beyond σ / cap caps nothing.
  const Eigen::VectorXd half = vertex_half_widths(
      mesh, {.min_distance = 1e-3 * sigma,
             .max_distance = std::max(2 * sigma / options.feature_cap, 2e-3 * sigma),
             .threads = options.threads});
  // The largest field below min(σ, cap × half-width) that grows by at most cap_slope per unit
  // length along edges: Dijkstra from every vertex at once.
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  for (Eigen::Index i = 0; i < n; ++i) {
    field[i] = std::min(sigma, options.feature_cap * half[i]);
    if (field[i] < sigma) queue.emplace(field[i], static_cast<int>(i));
  }
  while (!queue.empty()) {
    const auto [value, i] = queue.top();
    queue.pop();
    if (value > field[i]) continue;
    const VertexHandle v(i);
    for (const VertexHandle w : mesh.vv_range(v)) {
      const double reach = value + options.cap_slope * (mesh.point(w) - mesh.point(v)).norm();
      if (reach < field[w.idx()]) {
        field[w.idx()] = reach;
        queue.emplace(reach, w.idx());
      }
    }
  }
  return field;
}

namespace {

using Sparse = Eigen::SparseMatrix<double>;

// Edge weights times σ_i σ_j, the diagonal again minus the row's sum.
void scale_by_field(Sparse& w, const Eigen::VectorXd& field) {
  for (int k = 0; k < w.outerSize(); ++k) {
    double sum = 0.0;
    double* diagonal = nullptr;
    for (Sparse::InnerIterator it(w, k); it; ++it) {
      if (it.row() == it.col()) {
        diagonal = &it.valueRef();
      } else {
        it.valueRef() *= field[it.row()] * field[it.col()];
        sum += it.value();
      }
    }
    if (diagonal) *diagonal = -sum;
  }
}

// Rows: interior vertices, then boundary ones; each vertex's place in its own block.
struct RowBlocks {
  std::vector<char> on_boundary;   ///< per vertex
  std::vector<Eigen::Index> place; ///< per vertex, its row in its block
  std::vector<Eigen::Index> interior, boundary;
};

RowBlocks row_blocks(const Mesh& mesh) {
  const auto n = static_cast<std::size_t>(mesh.n_vertices());
  RowBlocks rows;
  rows.on_boundary.assign(n, 0);
  rows.place.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const VertexHandle v(static_cast<int>(i));
    // Isolated vertices count as interior (OpenMesh calls them boundary).
    rows.on_boundary[i] = !mesh.is_isolated(v) && mesh.is_boundary(v);
    auto& list = rows.on_boundary[i] ? rows.boundary : rows.interior;
    rows.place[i] = static_cast<Eigen::Index>(list.size());
    list.push_back(static_cast<Eigen::Index>(i));
  }
  return rows;
}

// The interior system (M − tW)_II into `a`, its mass into `mass_out`, and the triplets of t W_IB
// (the boundary's values) into `couple`; `w` is already scaled by what `scale` leaves out. A
// closed mesh has no boundary block: its matrix is built in place, faster than from triplets.
void interior_system(const Sparse& w, const Eigen::VectorXd& mass, double scale,
                     const RowBlocks& rows, Sparse& a, Eigen::VectorXd& mass_out,
                     std::vector<Eigen::Triplet<double>>& couple) {
  const auto ni = static_cast<Eigen::Index>(rows.interior.size());
  mass_out.resize(ni);
  if (rows.boundary.empty()) {
    mass_out = mass;
    a = -scale * w;
    for (Eigen::Index i = 0; i < ni; ++i) a.coeffRef(i, i) += mass_out[i];
    a.makeCompressed();
    return;
  }
  auto is_boundary = [&](Eigen::Index i) {
    return rows.on_boundary[static_cast<std::size_t>(i)] != 0;
  };
  std::vector<Eigen::Triplet<double>> inner;
  for (int k = 0; k < w.outerSize(); ++k)
    for (Sparse::InnerIterator it(w, k); it; ++it) {
      const Eigen::Index r = it.row(), c = it.col();
      if (is_boundary(r)) continue;
      const auto br = rows.place[static_cast<std::size_t>(r)];
      const auto bc = rows.place[static_cast<std::size_t>(c)];
      if (is_boundary(c))
        couple.emplace_back(br, bc, scale * it.value());
      else
        inner.emplace_back(br, bc, -scale * it.value());
    }
  for (Eigen::Index i = 0; i < ni; ++i) {
    mass_out[i] = mass[rows.interior[static_cast<std::size_t>(i)]];
    inner.emplace_back(i, i, mass_out[i]);
  }
  a.resize(ni, ni);
  a.setFromTriplets(inner.begin(), inner.end());
}

// The loops' curve system (M_b − W_b, W_b of weight σ²/length per boundary edge, M_b half the
// adjacent lengths) over the boundary block, its mass into `mass`; each loop's σ is capped by
// feature_cap × its radius (perimeter / 2π), counted in `capped_loops`. Lengths are floored for
// coincident boundary vertices; each boundary vertex has exactly two boundary neighbours.
Sparse loop_system(const Mesh& mesh, const RowBlocks& rows, double sigma_max, double feature_cap,
                   Eigen::VectorXd& mass, std::size_t& capped_loops) {
  const auto nb = static_cast<Eigen::Index>(rows.boundary.size());
  const double floor = 1e-9 * sigma_max;
  std::vector<Eigen::Triplet<double>> curve;
  mass = Eigen::VectorXd::Zero(nb);
  std::vector<char> done(mesh.n_halfedges(), 0);
  std::vector<HalfedgeHandle> loop;
  for (auto start : mesh.halfedges()) {
    if (!mesh.is_boundary(start) || done[static_cast<std::size_t>(start.idx())]) continue;
    loop.clear();
    double perimeter = 0.0;
    for (HalfedgeHandle h = start; !done[static_cast<std::size_t>(h.idx())];
         h = mesh.next_halfedge_handle(h)) {
      done[static_cast<std::size_t>(h.idx())] = 1;
      loop.push_back(h);
      perimeter += mesh.calc_edge_length(h);
    }
    const double sigma =
        feature_cap > 0.0 ? std::min(sigma_max, feature_cap * perimeter / (2.0 * std::numbers::pi))
                          : sigma_max;
    capped_loops += sigma < sigma_max ? 1 : 0;
    for (const HalfedgeHandle h : loop) {
      const auto i = rows.place[static_cast<std::size_t>(mesh.from_vertex_handle(h).idx())];
      const auto j = rows.place[static_cast<std::size_t>(mesh.to_vertex_handle(h).idx())];
      const double length = std::max(mesh.calc_edge_length(h), floor);
      const double w = sigma * sigma / length;
      curve.emplace_back(i, i, w);
      curve.emplace_back(j, j, w);
      curve.emplace_back(i, j, -w);
      curve.emplace_back(j, i, -w);
      mass[i] += 0.5 * length;
      mass[j] += 0.5 * length;
    }
  }
  for (Eigen::Index i = 0; i < nb; ++i) curve.emplace_back(i, i, mass[i]);
  Sparse loops(nb, nb);
  loops.setFromTriplets(curve.begin(), curve.end());
  return loops;
}

} // namespace

LowPassFilter::LowPassFilter(const Mesh& mesh, const LowPassOptions& options)
    : n_(static_cast<Eigen::Index>(mesh.n_vertices())), tolerance_(options.tolerance),
      steps_(options.steps) {
  check_options(options);
  stats_.sigma = stats_.sigma_min = options.smoothing * length_scale(mesh).length;
  if (!(stats_.sigma > 0.0)) return; // identity
  const Eigen::VectorXd field = smoothing_field(mesh, stats_.sigma, options);
  for (Eigen::Index i = 0; i < n_; ++i) {
    stats_.sigma_min = std::min(stats_.sigma_min, field[i]);
    stats_.capped += field[i] < stats_.sigma ? 1 : 0;
  }
  IntrinsicLaplacian lap = intrinsic_delaunay_laplacian(mesh);
  Eigen::VectorXd mass = std::move(lap.mass);
  // Isolated vertices (no face, zero mass) get an identity row.
  for (Eigen::Index i = 0; i < n_; ++i)
    if (!(mass[i] > 0.0)) mass[i] = 1.0;
  // Nothing capped: σ² everywhere, exactly t W as without the cap.
  const bool uniform = stats_.capped == 0;
  if (!uniform) scale_by_field(lap.weights, field);
  const double scale = uniform ? stats_.sigma * stats_.sigma : 1.0;

  RowBlocks rows = row_blocks(mesh);
  std::vector<Eigen::Triplet<double>> couple;
  interior_system(lap.weights, mass, scale, rows, system_, mass_, couple);
  lap.weights.resize(0, 0);
  stats_.laplacian_stats = std::move(lap);
  coupling_.resize(static_cast<Eigen::Index>(rows.interior.size()),
                   static_cast<Eigen::Index>(rows.boundary.size()));
  coupling_.setFromTriplets(couple.begin(), couple.end());
  if (!rows.boundary.empty())
    loops_ = loop_system(mesh, rows, stats_.sigma, options.feature_cap, boundary_mass_,
                         stats_.capped_loops);
  interior_ = std::move(rows.interior);
  boundary_ = std::move(rows.boundary);
  place_ = std::move(rows.place);
  on_boundary_ = std::move(rows.on_boundary);
  solved_ = true;
}

LowPassFilter::LowPassFilter(LowPassFilter&&) noexcept = default;
LowPassFilter& LowPassFilter::operator=(LowPassFilter&&) noexcept = default;
LowPassFilter::~LowPassFilter() = default;

namespace {

// Solves a x = b column by column by Jacobi-preconditioned CG (a SPD, both triangles stored),
// from `guess` when given; throws NumericalError when a column misses the tolerance.
Eigen::MatrixXd cg_solve(const Sparse& a, const Eigen::MatrixXd& b, const Eigen::MatrixXd* guess,
                         double tolerance) {
  Eigen::ConjugateGradient<Sparse, Eigen::Lower | Eigen::Upper,
                           Eigen::DiagonalPreconditioner<double>>
      cg;
  cg.setTolerance(tolerance);
  cg.setMaxIterations(static_cast<int>(std::max<Eigen::Index>(10 * a.rows(), 100)));
  cg.compute(a);
  Eigen::MatrixXd x(b.rows(), b.cols());
  for (Eigen::Index c = 0; c < b.cols(); ++c) {
    if (b.col(c).squaredNorm() == 0) {
      x.col(c).setZero();
      continue;
    }
    if (guess)
      x.col(c) = cg.solveWithGuess(b.col(c), guess->col(c));
    else
      x.col(c) = cg.solve(b.col(c));
    if (cg.info() != Eigen::Success || !x.col(c).allFinite())
      throw NumericalError(fmt::format(
          "low-pass filter: CG did not converge after {} iterations (relative residual {:.3g}, "
          "tolerance {:.3g}); lower the smoothing or repair the mesh",
          cg.iterations(), cg.error(), tolerance));
  }
  return x;
}

// The rows and columns `keep` of the symmetric matrix a (CSC, both triangles); `local` maps a's
// indices to positions in `keep` (−1 elsewhere).
Sparse principal_block(const Sparse& a, const std::vector<Eigen::Index>& keep,
                       const std::vector<int>& local) {
  std::vector<Eigen::Triplet<double>> t;
  for (std::size_t c = 0; c < keep.size(); ++c)
    for (Sparse::InnerIterator it(a, keep[c]); it; ++it) {
      const int r = local[static_cast<std::size_t>(it.row())];
      if (r >= 0) t.emplace_back(r, static_cast<int>(c), it.value());
    }
  Sparse block(static_cast<Eigen::Index>(keep.size()), static_cast<Eigen::Index>(keep.size()));
  block.setFromTriplets(t.begin(), t.end());
  return block;
}

} // namespace

Eigen::MatrixXd LowPassFilter::apply(const Eigen::MatrixXd& values) const {
  if (values.rows() != n_)
    throw InvalidArgument(
        fmt::format("low-pass filter: {} rows given for a mesh of {} vertices", values.rows(), n_));
  if (!solved_) return values;
  const Eigen::Index cols = values.cols();
  const auto ni = static_cast<Eigen::Index>(interior_.size());
  const auto nb = static_cast<Eigen::Index>(boundary_.size());
  Eigen::MatrixXd xi(ni, cols), xb(nb, cols);
  for (Eigen::Index i = 0; i < ni; ++i) xi.row(i) = values.row(interior_[std::size_t(i)]);
  for (Eigen::Index i = 0; i < nb; ++i) xb.row(i) = values.row(boundary_[std::size_t(i)]);
  for (int s = 0; s < steps_; ++s) {
    if (nb > 0) {
      const Eigen::MatrixXd b = boundary_mass_.asDiagonal() * xb;
      xb = cg_solve(loops_, b, &xb, tolerance_);
    }
    if (ni > 0) {
      Eigen::MatrixXd b = mass_.asDiagonal() * xi;
      if (nb > 0) b += coupling_ * xb;
      xi = cg_solve(system_, b, &xi, tolerance_);
    }
  }
  Eigen::MatrixXd x(n_, cols);
  for (Eigen::Index i = 0; i < ni; ++i) x.row(interior_[std::size_t(i)]) = xi.row(i);
  for (Eigen::Index i = 0; i < nb; ++i) x.row(boundary_[std::size_t(i)]) = xb.row(i);
  return x;
}

Eigen::MatrixXd LowPassFilter::apply_local(const std::vector<int>& region,
                                           const Eigen::MatrixXd& values) const {
  if (values.rows() != static_cast<Eigen::Index>(region.size()))
    throw InvalidArgument(fmt::format("low-pass filter: {} rows given for a region of {} vertices",
                                      values.rows(), region.size()));
  for (const int v : region)
    if (v < 0 || v >= n_)
      throw InvalidArgument(fmt::format(
          "low-pass filter: region vertex {} is out of range (the mesh has {} vertices)", v, n_));
  if (!solved_) return values;
  // The region's rows of each block (interior, boundary) and their places in the region.
  std::vector<Eigen::Index> inner, outer;           // block rows
  std::vector<Eigen::Index> inner_rows, outer_rows; // rows of `values`
  for (std::size_t r = 0; r < region.size(); ++r) {
    const auto v = static_cast<std::size_t>(region[r]);
    (on_boundary_[v] ? outer : inner).push_back(place_[v]);
    (on_boundary_[v] ? outer_rows : inner_rows).push_back(static_cast<Eigen::Index>(r));
  }
  std::vector<int> local_inner(interior_.size(), -1), local_outer(boundary_.size(), -1);
  for (std::size_t k = 0; k < inner.size(); ++k)
    local_inner[static_cast<std::size_t>(inner[k])] = static_cast<int>(k);
  for (std::size_t k = 0; k < outer.size(); ++k)
    local_outer[static_cast<std::size_t>(outer[k])] = static_cast<int>(k);
  const Eigen::Index cols = values.cols();
  Eigen::MatrixXd xi(static_cast<Eigen::Index>(inner.size()), cols);
  Eigen::MatrixXd xb(static_cast<Eigen::Index>(outer.size()), cols);
  Eigen::VectorXd mi(xi.rows()), mb(xb.rows());
  for (Eigen::Index k = 0; k < xi.rows(); ++k) {
    xi.row(k) = values.row(inner_rows[std::size_t(k)]);
    mi[k] = mass_[inner[std::size_t(k)]];
  }
  for (Eigen::Index k = 0; k < xb.rows(); ++k) {
    xb.row(k) = values.row(outer_rows[std::size_t(k)]);
    mb[k] = boundary_mass_[outer[std::size_t(k)]];
  }
  const Sparse a = principal_block(system_, inner, local_inner);
  const Sparse loops = xb.rows() > 0 ? principal_block(loops_, outer, local_outer) : Sparse();
  // t W between the region's interior and boundary rows.
  std::vector<Eigen::Triplet<double>> t;
  for (std::size_t c = 0; c < outer.size(); ++c)
    for (Sparse::InnerIterator it(coupling_, outer[c]); it; ++it) {
      const int r = local_inner[static_cast<std::size_t>(it.row())];
      if (r >= 0) t.emplace_back(r, static_cast<int>(c), it.value());
    }
  Sparse couple(xi.rows(), xb.rows());
  couple.setFromTriplets(t.begin(), t.end());
  for (int s = 0; s < steps_; ++s) {
    if (xb.rows() > 0) xb = cg_solve(loops, mb.asDiagonal() * xb, &xb, tolerance_);
    if (xi.rows() > 0) {
      Eigen::MatrixXd b = mi.asDiagonal() * xi;
      if (xb.rows() > 0) b += couple * xb;
      xi = cg_solve(a, b, &xi, tolerance_);
    }
  }
  Eigen::MatrixXd x(values.rows(), cols);
  for (Eigen::Index k = 0; k < xi.rows(); ++k) x.row(inner_rows[std::size_t(k)]) = xi.row(k);
  for (Eigen::Index k = 0; k < xb.rows(); ++k) x.row(outer_rows[std::size_t(k)]) = xb.row(k);
  return x;
}

} // namespace remora
