#include "remora/multires/nonlinear.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <fmt/format.h>

#include "remora/common/error.h"
#include "remora/common/parallel.h"
#include "remora/common/timer.h"
#include "remora/geometry/laplacian.h"
#include "remora/geometry/measures.h"
#include "remora/linalg/anderson.h"
#include "remora/multires/best_rotation.h"
#include "remora/multires/motion_blend.h"
#include "remora/multires/rotation_blend.h"

namespace remora {

namespace {

using Matrix3 = Eigen::Matrix3d;
using Vector3 = Eigen::Vector3d;

bool is_identity(const AffineMap& t) {
  AffineMap id = AffineMap::Zero();
  id.leftCols<3>().setIdentity();
  return t == id;
}

} // namespace

std::string to_string(EditMethod method) {
  return method == EditMethod::Linear ? "linear" : "nonlinear";
}

EditMethod parse_edit_method(const std::string& name) {
  if (name == "linear") return EditMethod::Linear;
  if (name == "nonlinear") return EditMethod::Nonlinear;
  throw InvalidArgument(fmt::format(
      "unknown method '{}': use linear (the paper) or nonlinear (large rotations)", name));
}

std::string to_string(NonlinearEnergy energy) {
  switch (energy) {
  case NonlinearEnergy::Arap:
    return "arap";
  case NonlinearEnergy::RotatedLaplacian:
    return "rotated-laplacian";
  case NonlinearEnergy::PropagatedRotations:
    return "propagated";
  case NonlinearEnergy::BlendedMotions:
    break;
  }
  return "blended-motions";
}

NonlinearEnergy parse_nonlinear_energy(const std::string& name) {
  if (name == "arap") return NonlinearEnergy::Arap;
  if (name == "rotated-laplacian") return NonlinearEnergy::RotatedLaplacian;
  if (name == "propagated") return NonlinearEnergy::PropagatedRotations;
  if (name == "blended-motions") return NonlinearEnergy::BlendedMotions;
  throw InvalidArgument(fmt::format("unknown nonlinear energy '{}': use rotated-laplacian, "
                                    "propagated, blended-motions or arap",
                                    name));
}

const std::vector<std::string>& nonlinear_energy_names() {
  static const std::vector<std::string> names{"rotated-laplacian", "propagated", "blended-motions",
                                              "arap"};
  return names;
}

struct NonlinearDeformer::Impl {
  NonlinearOptions options;
  double a = 1.0, beta = 1.0;  // the energy's weights
  bool propagated = false;     // PropagatedRotations: β = 0, the rotations fixed by the handles
  bool blended = false;        // BlendedMotions: closed form, no system
  std::vector<Vector3> pivots; // per handle: its rest centroid (BlendedMotions' stretch centre)
  std::size_t n = 0;
  std::vector<int> labels;
  std::vector<int> free_vertices, row_of; // row_of: vertex -> free row or -1
  std::vector<int> cells, cell_of;        // free vertices and their neighbours
  // Per cell: its W row (neighbour, weight), CSR; the diagonal separately.
  std::vector<int> ring_begin, ring_vertex;
  std::vector<double> ring_weight, diagonal;
  RowPoints rest, x;                      // x⁰ and the current positions (every vertex)
  RowPoints delta;                        // per cell: (W x⁰)_m
  Eigen::MatrixXd weights;                // n × h handle weights
  std::vector<Matrix3> stretch, rotation; // per cell
  bool stretched = false;
  Eigen::MatrixXd rhs_constrained; // nf × 3
  std::unique_ptr<Solver> solver;
  double edge_length = 1.0;
  NonlinearStats stats;
  double current_energy = 0.0;
  bool identity = true;
  std::unique_ptr<AndersonAcceleration> anderson; // null without (options.anderson 0)
  Eigen::VectorXd previous_guess;                 // the free rows of the last guess (x⁰ at first)
  int plain_steps = 0;                            // iterations left without an extrapolation
  std::array<double, 3> decreases{0.0, 0.0, 0.0}; // of E in the last three iterations

  std::size_t nf() const { return free_vertices.size(); }

  Eigen::VectorXd free_vector() const {
    Eigen::VectorXd u(static_cast<Eigen::Index>(3 * nf()));
    for (std::size_t r = 0; r < nf(); ++r)
      for (int c = 0; c < 3; ++c) u[static_cast<Eigen::Index>(3 * r + c)] = x(free_vertices[r], c);
    return u;
  }
  void set_free(const Eigen::VectorXd& u) {
    for (std::size_t r = 0; r < nf(); ++r)
      for (int c = 0; c < 3; ++c) x(free_vertices[r], c) = u[static_cast<Eigen::Index>(3 * r + c)];
  }

  Vector3 laplacian(const RowPoints& p, std::size_t cell) const {
    const int m = cells[cell];
    Vector3 s = diagonal[cell] * p.row(m).transpose();
    for (int k = ring_begin[cell]; k < ring_begin[cell + 1]; ++k)
      s += ring_weight[static_cast<std::size_t>(k)] *
           p.row(ring_vertex[static_cast<std::size_t>(k)]).transpose();
    return s;
  }

  /// Local step on the current x: the best rotation per cell; returns E.
  double local_step(std::vector<Matrix3>& out) const {
    std::vector<double> cell_energy(cells.size());
    parallel_for(cells.size(), options.threads, [&](std::size_t c) {
      const int m = cells[c];
      const Matrix3& s = stretch[c];
      // P = a d rᵀ + Σ β w e⁰ eᵀ, accumulated in scalars: Eigen's 3 × 3 outer products wrote
      // stack temporaries in halves and read them back whole, a store-forwarding stall each.
      std::array<double, 9> p{};
      const auto add_outer = [&p](double weight, const Vector3& u, const Vector3& v) {
        for (int i = 0; i < 3; ++i) {
          const double wu = weight * u[i];
          for (int j = 0; j < 3; ++j) p[static_cast<std::size_t>(3 * i + j)] += wu * v[j];
        }
      };
      Vector3 r = Vector3::Zero(), d = Vector3::Zero();
      if (a > 0.0) {
        r = laplacian(x, c);
        d = stretched ? Vector3(s * delta.row(static_cast<Eigen::Index>(c)).transpose())
                      : Vector3(delta.row(static_cast<Eigen::Index>(c)).transpose());
        add_outer(a, d, r);
      }
      // The ring's current and rest edges, kept for the energy (a ring longer than the buffer
      // computes them again).
      constexpr int kBuffer = 24;
      std::array<Vector3, kBuffer> es, e0s;
      const auto edge = [&](int k, Vector3& e, Vector3& e0) {
        const int j = ring_vertex[static_cast<std::size_t>(k)];
        e = (x.row(m) - x.row(j)).transpose();
        e0 = (rest.row(m) - rest.row(j)).transpose();
        if (stretched) e0 = s * e0;
      };
      for (int k = ring_begin[c]; k < ring_begin[c + 1]; ++k) {
        Vector3 e, e0;
        edge(k, e, e0);
        if (k - ring_begin[c] < kBuffer) {
          es[static_cast<std::size_t>(k - ring_begin[c])] = e;
          e0s[static_cast<std::size_t>(k - ring_begin[c])] = e0;
        }
        add_outer(beta * ring_weight[static_cast<std::size_t>(k)], e0, e);
      }
      const Matrix3 rot = best_rotation(
          Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(p.data()), rotation[c]);
      out[c] = rot;
      double energy = 0.0;
      if (a > 0.0) energy += a * (r - rot * d).squaredNorm();
      for (int k = ring_begin[c]; k < ring_begin[c + 1]; ++k) {
        Vector3 e, e0;
        if (k - ring_begin[c] < kBuffer) {
          e = es[static_cast<std::size_t>(k - ring_begin[c])];
          e0 = e0s[static_cast<std::size_t>(k - ring_begin[c])];
        } else {
          edge(k, e, e0);
        }
        energy += beta * ring_weight[static_cast<std::size_t>(k)] * (e - rot * e0).squaredNorm();
      }
      cell_energy[c] = energy;
    });
    double e = 0.0;
    for (const double v : cell_energy) e += v;
    return e;
  }

  /// Σ_m a ‖(W x)_m − R_m S_m δ_m‖² at the current x for the current rotations (the energy
  /// PropagatedRotations minimizes; β = 0).
  double fixed_rotation_energy() const {
    std::vector<double> cell_energy(cells.size());
    parallel_for(cells.size(), options.threads, [&](std::size_t c) {
      Vector3 d = delta.row(static_cast<Eigen::Index>(c)).transpose();
      if (stretched) d = stretch[c] * d;
      cell_energy[c] = a * (laplacian(x, c) - rotation[c] * d).squaredNorm();
    });
    double e = 0.0;
    for (const double v : cell_energy) e += v;
    return e;
  }

  /// PropagatedRotations: each cell's rotation, the handles' rotations blended by its weights
  /// (multires/rotation_blend.h).
  void propagate_rotations(const std::vector<AffineMap>& transforms) {
    std::vector<Vector3> logs;
    for (const AffineMap& t : transforms)
      logs.push_back(rotation_log(polar_rotation(t.leftCols<3>())));
    parallel_for(cells.size(), options.threads, [&](std::size_t c) {
      rotation[c] = blend_rotations(logs, weights.row(cells[c]));
    });
  }

  /// Global step: the free positions minimizing E for the rotations `rot`, as a vector.
  Eigen::VectorXd global_step(const std::vector<Matrix3>& rot) const {
    // t_m = R_m S_m δ_m per cell.
    RowPoints t(static_cast<Eigen::Index>(cells.size()), 3);
    std::vector<Matrix3> rs(cells.size());
    parallel_for(cells.size(), options.threads, [&](std::size_t c) {
      rs[c] = stretched ? Matrix3(rot[c] * stretch[c]) : rot[c];
      t.row(static_cast<Eigen::Index>(c)) =
          (rs[c] * delta.row(static_cast<Eigen::Index>(c)).transpose()).transpose();
    });
    Eigen::MatrixXd rhs = rhs_constrained;
    parallel_for(nf(), options.threads, [&](std::size_t row) {
      const int i = free_vertices[row];
      const auto ci = static_cast<std::size_t>(cell_of[static_cast<std::size_t>(i)]);
      Vector3 s = Vector3::Zero();
      if (a > 0.0) s += a * diagonal[ci] * t.row(static_cast<Eigen::Index>(ci)).transpose();
      for (int k = ring_begin[ci]; k < ring_begin[ci + 1]; ++k) {
        const int j = ring_vertex[static_cast<std::size_t>(k)];
        const double w = ring_weight[static_cast<std::size_t>(k)];
        const auto cj = static_cast<std::size_t>(cell_of[static_cast<std::size_t>(j)]);
        if (a > 0.0) s += a * w * t.row(static_cast<Eigen::Index>(cj)).transpose();
        const Vector3 e0 = (rest.row(i) - rest.row(j)).transpose();
        s += beta * w * ((rs[ci] + rs[cj]) * e0);
      }
      rhs.row(static_cast<Eigen::Index>(row)) += s.transpose();
    });
    const Eigen::MatrixXd sol = solver->solve(rhs);
    Eigen::VectorXd u(static_cast<Eigen::Index>(3 * nf()));
    for (std::size_t r = 0; r < nf(); ++r)
      for (int c = 0; c < 3; ++c)
        u[static_cast<Eigen::Index>(3 * r + c)] = sol(static_cast<Eigen::Index>(r), c);
    return u;
  }

  void build(const Mesh& base, const Eigen::MatrixXd& rest_positions);
  void number_free_vertices();
  void find_pivots(const Eigen::MatrixXd& rest_positions);
  void find_cells(const Mesh& base);
  void read_rings(const Mesh& base, const Eigen::MatrixXd& rest_positions);
  void factorize_global_matrix();
  double mean_cell_edge_length() const;
  void update_constrained_rhs();
  void place_constrained(const std::vector<AffineMap>& transforms);
  void blend_stretches(const std::vector<AffineMap>& transforms);
  void choose_start(const RowPoints* guess);
  double max_move(const Eigen::VectorXd& u, const Eigen::VectorXd& v) const {
    double worst = 0.0;
    for (std::size_t r = 0; r < nf(); ++r)
      worst = std::max(worst, (u.segment<3>(static_cast<Eigen::Index>(3 * r)) -
                               v.segment<3>(static_cast<Eigen::Index>(3 * r)))
                                  .norm());
    return worst;
  }
  void iterate();
};

// Each cell's row of W, the rest shape's own cotan weights (not B's: B0 can be far from B inside
// the support) with negative ones clamped to 0, so that the global matrix stays positive
// definite: its neighbours in increasing order, and the diagonal minus their sum.
void NonlinearDeformer::Impl::read_rings(const Mesh& base, const Eigen::MatrixXd& rest_positions) {
  ring_begin.assign(cells.size() + 1, 0);
  for (std::size_t c = 0; c < cells.size(); ++c)
    ring_begin[c + 1] = ring_begin[c] + static_cast<int>(base.valence(VertexHandle(cells[c])));
  ring_vertex.resize(static_cast<std::size_t>(ring_begin.back()));
  ring_weight.resize(ring_vertex.size());
  diagonal.resize(cells.size());
  parallel_for(cells.size(), options.threads, [&](std::size_t c) {
    std::vector<std::pair<int, double>> ring;
    for (const HalfedgeHandle h : base.voh_range(VertexHandle(cells[c])))
      ring.emplace_back(base.to_vertex_handle(h).idx(),
                        std::max(0.0, cotan_weight(base, rest_positions, base.edge_handle(h))));
    std::sort(ring.begin(), ring.end());
    double sum = 0.0;
    auto k = static_cast<std::size_t>(ring_begin[c]);
    for (const auto& [j, w] : ring) {
      ring_vertex[k] = j;
      ring_weight[k++] = w;
      sum += w;
    }
    diagonal[c] = -sum;
  });
}

void NonlinearDeformer::Impl::build(const Mesh& base, const Eigen::MatrixXd& rest_positions) {
  n = base.n_vertices();
  number_free_vertices();
  if (free_vertices.empty()) throw InvalidArgument("nonlinear deformer: no free vertex");
  if (blended) { // no system: the handles' pivots
    find_pivots(rest_positions);
    rest = rest_positions;
    x = rest;
    return;
  }
  // β = rigidity × (mean vertex area) / (the support's area) = rigidity / n_free: the two terms
  // keep their ratio when the base is refined or the shape scaled (docs/nonlinear.md).
  if (a > 0.0 && !propagated) beta = options.rigidity / static_cast<double>(free_vertices.size());
  find_cells(base);
  read_rings(base, rest_positions);
  rest = rest_positions;
  x = rest;
  delta.resize(static_cast<Eigen::Index>(cells.size()), 3);
  for (std::size_t c = 0; c < cells.size(); ++c)
    delta.row(static_cast<Eigen::Index>(c)) = laplacian(rest, c).transpose();
  stretch.assign(cells.size(), Matrix3::Identity());
  rotation.assign(cells.size(), Matrix3::Identity());
  factorize_global_matrix();
  edge_length = mean_cell_edge_length();
}

// The free vertices in vertex order, and each vertex's row among them (row_of).
void NonlinearDeformer::Impl::number_free_vertices() {
  row_of.assign(n, -1);
  for (std::size_t v = 0; v < n; ++v)
    if (labels[v] == Region::kFree) {
      row_of[v] = static_cast<int>(free_vertices.size());
      free_vertices.push_back(static_cast<int>(v));
    }
}

// BlendedMotions: each handle's pivot, the centroid of its vertices' rest positions.
void NonlinearDeformer::Impl::find_pivots(const Eigen::MatrixXd& rest_positions) {
  const auto h = static_cast<std::size_t>(weights.cols());
  pivots.assign(h, Vector3::Zero());
  std::vector<double> count(h, 0.0);
  for (std::size_t v = 0; v < n; ++v)
    if (labels[v] >= 0 && static_cast<std::size_t>(labels[v]) < h) {
      pivots[static_cast<std::size_t>(labels[v])] +=
          rest_positions.row(static_cast<Eigen::Index>(v));
      count[static_cast<std::size_t>(labels[v])] += 1.0;
    }
  for (std::size_t j = 0; j < h; ++j)
    if (count[j] > 0.0) pivots[j] /= count[j];
}

// The cells: the free vertices and their neighbours, in vertex order (cell_of: vertex -> cell).
void NonlinearDeformer::Impl::find_cells(const Mesh& base) {
  std::vector<char> in_cell(n, 0);
  for (const int v : free_vertices) {
    in_cell[static_cast<std::size_t>(v)] = 1;
    for (const VertexHandle u : base.vv_range(VertexHandle(v)))
      in_cell[static_cast<std::size_t>(u.idx())] = 1;
  }
  cell_of.assign(n, -1);
  for (std::size_t v = 0; v < n; ++v)
    if (in_cell[v]) {
      cell_of[v] = static_cast<int>(cells.size());
      cells.push_back(static_cast<int>(v));
    }
}

// K = a (W²)_FF − 2β W_FF, from the cells' rows of W: (W²)_FF = W_CFᵀ W_CF; factorized.
void NonlinearDeformer::Impl::factorize_global_matrix() {
  const auto nfree = static_cast<Eigen::Index>(nf());
  std::vector<Eigen::Triplet<double>> cf, ff;
  for (std::size_t c = 0; c < cells.size(); ++c) {
    const int own = row_of[static_cast<std::size_t>(cells[c])];
    const auto row = static_cast<Eigen::Index>(c);
    if (own >= 0) {
      cf.emplace_back(row, own, diagonal[c]);
      ff.emplace_back(own, own, diagonal[c]);
    }
    for (int k = ring_begin[c]; k < ring_begin[c + 1]; ++k) {
      const int j = row_of[static_cast<std::size_t>(ring_vertex[static_cast<std::size_t>(k)])];
      if (j < 0) continue;
      cf.emplace_back(row, j, ring_weight[static_cast<std::size_t>(k)]);
      if (own >= 0) ff.emplace_back(own, j, ring_weight[static_cast<std::size_t>(k)]);
    }
  }
  SparseMatrix wcf(static_cast<Eigen::Index>(cells.size()), nfree), wff(nfree, nfree);
  wcf.setFromTriplets(cf.begin(), cf.end());
  wff.setFromTriplets(ff.begin(), ff.end());
  SparseMatrix k = wff * (-2.0 * beta);
  if (a > 0.0) k += a * SparseMatrix(wcf.transpose() * wcf);
  const SparseMatrix kt = k.transpose();
  k = 0.5 * (k + kt);
  k.makeCompressed();
  SolverOptions so = options.solver;
  if (so.name.empty()) so.name = default_solver_name();
  if (so.threads == 0) so.threads = options.threads;
  solver = make_solver(so);
  solver->compute(k);
}

// The base's mean edge length over the cells (the tolerance's unit); 1 without edges.
double NonlinearDeformer::Impl::mean_cell_edge_length() const {
  double sum = 0.0;
  std::size_t count = 0;
  for (std::size_t c = 0; c < cells.size(); ++c)
    for (int kk = ring_begin[c]; kk < ring_begin[c + 1]; ++kk) {
      sum += (rest.row(cells[c]) - rest.row(ring_vertex[static_cast<std::size_t>(kk)])).norm();
      ++count;
    }
  return count > 0 && sum > 0.0 ? sum / static_cast<double>(count) : 1.0;
}

// −K_FC x_C = −a (W (W x̃))_F + 2β (W x̃)_F with x̃ the constrained values (free rows zero).
void NonlinearDeformer::Impl::update_constrained_rhs() {
  if (blended) return; // no system
  RowPoints xc = x;
  for (const int v : free_vertices) xc.row(v).setZero();
  RowPoints y(static_cast<Eigen::Index>(cells.size()), 3);
  parallel_for(cells.size(), options.threads, [&](std::size_t c) {
    y.row(static_cast<Eigen::Index>(c)) = laplacian(xc, c).transpose();
  });
  rhs_constrained.resize(static_cast<Eigen::Index>(nf()), 3);
  parallel_for(nf(), options.threads, [&](std::size_t row) {
    const auto ci = static_cast<std::size_t>(cell_of[static_cast<std::size_t>(free_vertices[row])]);
    Vector3 s = 2.0 * beta * y.row(static_cast<Eigen::Index>(ci)).transpose();
    if (a > 0.0) {
      Vector3 wy = diagonal[ci] * y.row(static_cast<Eigen::Index>(ci)).transpose();
      for (int k = ring_begin[ci]; k < ring_begin[ci + 1]; ++k) {
        const auto cj = static_cast<std::size_t>(
            cell_of[static_cast<std::size_t>(ring_vertex[static_cast<std::size_t>(k)])]);
        wy += ring_weight[static_cast<std::size_t>(k)] *
              y.row(static_cast<Eigen::Index>(cj)).transpose();
      }
      s -= a * wy;
    }
    rhs_constrained.row(static_cast<Eigen::Index>(row)) = s.transpose();
  });
}

void NonlinearDeformer::Impl::iterate() {
  const Eigen::VectorXd u = free_vector();
  const double before = current_energy;
  if (propagated) { // the rotations are fixed: one solve is the minimizer
    set_free(global_step(rotation));
    current_energy = fixed_rotation_energy();
    stats.last_move = max_move(free_vector(), u) / edge_length;
    stats.energy.push_back(current_energy);
    ++stats.iterations;
    ++stats.total_iterations;
    stats.converged = true;
    return;
  }
  const Eigen::VectorXd g = global_step(rotation);
  const Eigen::VectorXd f = g - u;
  std::vector<Matrix3> rot(cells.size());
  bool accepted = false;
  if (anderson) {
    const Eigen::VectorXd candidate = anderson->extrapolate(g, f);
    // After a rejected extrapolation the next two iterations are plain (each test costs a local
    // step).
    if (plain_steps > 0) {
      --plain_steps;
    } else if (anderson->history() > 0 && candidate.allFinite()) {
      set_free(candidate);
      const double e = local_step(rot);
      if (e < current_energy) {
        accepted = true;
        current_energy = e;
        ++stats.accelerated;
      } else { // keep only the newest point
        anderson->restart();
        plain_steps = 2;
      }
    }
  }
  if (!accepted) {
    set_free(g);
    current_energy = local_step(rot);
  }
  rotation.swap(rot);
  stats.last_move = max_move(free_vector(), u) / edge_length;
  stats.energy.push_back(current_energy);
  ++stats.iterations;
  ++stats.total_iterations;
  decreases[static_cast<std::size_t>(stats.total_iterations % 3)] = before - current_energy;
  const double recent = decreases[0] + decreases[1] + decreases[2];
  stats.converged =
      stats.last_move < options.tolerance ||
      (stats.total_iterations >= 3 && recent <= 3.0 * options.energy_tolerance * current_energy);
  stats.exhausted = !stats.converged && stats.total_iterations >= options.max_iterations;
}

// The constrained values: each handle vertex's rest position under its handle's transform.
void NonlinearDeformer::Impl::place_constrained(const std::vector<AffineMap>& transforms) {
  for (std::size_t v = 0; v < n; ++v) {
    const int label = labels[v];
    if (label >= 0) {
      const AffineMap& t = transforms[static_cast<std::size_t>(label)];
      x.row(static_cast<Eigen::Index>(v)) =
          (t.leftCols<3>() * rest.row(static_cast<Eigen::Index>(v)).transpose() + t.col(3))
              .transpose();
    } // the fixed rows keep x⁰: nothing writes them
  }
}

// Each cell's stretch: the handles' stretches blended by the handle weights.
void NonlinearDeformer::Impl::blend_stretches(const std::vector<AffineMap>& transforms) {
  const int handles = static_cast<int>(weights.cols());
  std::vector<Matrix3> handle_stretch;
  stretched = false;
  for (const AffineMap& t : transforms) {
    handle_stretch.push_back(polar_stretch(t.leftCols<3>()));
    if (!(handle_stretch.back() - Matrix3::Identity()).isZero(1e-12)) stretched = true;
  }
  for (std::size_t c = 0; c < cells.size(); ++c) {
    if (!stretched) {
      stretch[c].setIdentity();
      continue;
    }
    const auto v = static_cast<Eigen::Index>(cells[c]);
    Matrix3 s = Matrix3::Zero();
    double total = 0.0;
    for (int j = 0; j < handles; ++j) {
      const double w = weights(v, j);
      s += w * handle_stretch[static_cast<std::size_t>(j)];
      total += w;
    }
    stretch[c] = s + (1.0 - total) * Matrix3::Identity();
  }
}

// Start from the lowest-energy of: the guess, and the current free positions moved as the
// guess moved since the last call (a predictor along a drag); without a guess, the current
// positions. Sets the rotations and the energy of the start.
void NonlinearDeformer::Impl::choose_start(const RowPoints* guess) {
  std::vector<Matrix3> rot(cells.size());
  if (!guess) {
    current_energy = local_step(rot);
    rotation.swap(rot);
    return;
  }
  Eigen::VectorXd g(static_cast<Eigen::Index>(3 * nf()));
  for (std::size_t r = 0; r < nf(); ++r)
    g.segment<3>(static_cast<Eigen::Index>(3 * r)) = guess->row(free_vertices[r]).transpose();
  const Eigen::VectorXd current = free_vector();
  const Eigen::VectorXd predictor = current + (g - previous_guess);
  // Positions still at the last guess (nothing iterated since) make the predictor the guess.
  const bool same = current == previous_guess;
  current_energy = std::numeric_limits<double>::infinity();
  Eigen::VectorXd best = g;
  for (const Eigen::VectorXd* candidate : {&predictor, static_cast<const Eigen::VectorXd*>(&g)}) {
    if (same && candidate == &predictor) continue;
    set_free(*candidate);
    const double e = local_step(rot);
    if (e < current_energy) {
      current_energy = e;
      rotation.swap(rot);
      best = *candidate;
    }
  }
  set_free(best);
  previous_guess = g;
  if (!std::isfinite(current_energy))
    throw NumericalError("nonlinear deformer: the start has a non-finite energy");
}

NonlinearDeformer::NonlinearDeformer(const Mesh& base, const Eigen::MatrixXd& rest,
                                     const std::vector<int>& labels,
                                     const Eigen::MatrixXd& handle_weights,
                                     const NonlinearOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  const auto n = static_cast<Eigen::Index>(base.n_vertices());
  if (rest.rows() != n || rest.cols() != 3 || labels.size() != base.n_vertices() ||
      handle_weights.rows() != n)
    throw InvalidArgument(fmt::format(
        "nonlinear deformer: {} x {} rest positions, {} labels and {} weight rows for a base of "
        "{} vertices (one row and one label per vertex expected)",
        rest.rows(), rest.cols(), labels.size(), handle_weights.rows(), n));
  if (!rest.allFinite() || !handle_weights.allFinite())
    throw InvalidArgument("nonlinear deformer: a rest position or weight is not finite");
  if (!(options.rigidity > 0.0) || options.max_iterations < 1 || !(options.tolerance > 0.0) ||
      !(options.energy_tolerance >= 0.0) || options.anderson < 0)
    throw InvalidArgument("nonlinear deformer: rigidity and tolerance must be > 0, "
                          "energy_tolerance >= 0, max_iterations >= 1 and anderson >= 0");
  m.options = options;
  m.labels = labels;
  m.weights = handle_weights;
  m.propagated = options.energy == NonlinearEnergy::PropagatedRotations;
  m.blended = options.energy == NonlinearEnergy::BlendedMotions;
  m.a = options.energy == NonlinearEnergy::Arap ? 0.0 : 1.0;
  m.beta = options.energy == NonlinearEnergy::Arap ? 1.0 : 0.0; // RotatedLaplacian: set by build()
  if (options.anderson > 0)
    m.anderson = std::make_unique<AndersonAcceleration>(options.anderson, options.threads);
  try {
    m.build(base, rest);
  } catch (const NumericalError& e) {
    throw NumericalError(std::string("nonlinear deformer: the global matrix: ") + e.what());
  }
  m.update_constrained_rhs();
  m.previous_guess = m.free_vector();
  m.stats.converged = true;
}

NonlinearDeformer::~NonlinearDeformer() = default;
NonlinearDeformer::NonlinearDeformer(NonlinearDeformer&&) noexcept = default;
NonlinearDeformer& NonlinearDeformer::operator=(NonlinearDeformer&&) noexcept = default;

void NonlinearDeformer::set_transforms(const std::vector<AffineMap>& transforms,
                                       const RowPoints* guess) {
  Impl& m = *impl_;
  const int handles = static_cast<int>(m.weights.cols());
  if (static_cast<int>(transforms.size()) != handles)
    throw InvalidArgument(fmt::format("nonlinear deformer: {} transforms for {} handles",
                                      transforms.size(), handles));
  m.stats = NonlinearStats{};
  if (m.anderson) m.anderson->clear();
  m.plain_steps = 0;
  m.decreases = {0.0, 0.0, 0.0};
  m.identity = std::all_of(transforms.begin(), transforms.end(), is_identity);
  if (m.identity) { // E = 0 at x⁰: the minimizer, exactly
    m.x = m.rest;
    m.stretch.assign(m.cells.size(), Matrix3::Identity());
    m.rotation.assign(m.cells.size(), Matrix3::Identity());
    m.stretched = false;
    m.current_energy = 0.0;
    m.previous_guess = m.free_vector();
    m.update_constrained_rhs();
    m.stats.converged = true;
    m.stats.energy.push_back(0.0);
    return;
  }
  m.place_constrained(transforms);
  if (m.blended) { // closed form: the result, no iteration
    blend_motions(m.rest, m.weights, m.free_vertices, handle_motions(transforms, m.pivots), m.x,
                  m.options.threads);
    m.current_energy = 0.0;
    m.stats.converged = true;
    return;
  }
  m.blend_stretches(transforms);
  m.update_constrained_rhs();
  if (m.propagated) { // the rotations from the handles; the start is the guess
    m.propagate_rotations(transforms);
    if (guess)
      for (const int v : m.free_vertices) m.x.row(v) = guess->row(v);
    m.current_energy = m.fixed_rotation_energy();
    m.stats.energy.push_back(m.current_energy);
    m.stats.converged = false;
    return;
  }
  m.choose_start(guess);
  m.stats.energy.push_back(m.current_energy);
  m.stats.converged = false;
}

const NonlinearStats& NonlinearDeformer::solve(double budget_ms,
                                               const std::function<bool()>& interrupt) {
  Impl& m = *impl_;
  m.stats.iterations = 0;
  m.stats.accelerated = 0;
  if (!m.stats.energy.empty())
    m.stats.energy.erase(m.stats.energy.begin(), m.stats.energy.end() - 1);
  if (m.stats.finished()) return m.stats;
  // Another iteration starts only when it would end within the budget, were it as slow as the
  // slowest of this call: a frame's budget is a bound, not a point to pass.
  const auto t0 = Clock::now();
  double slowest = 0.0;
  do {
    const auto t = Clock::now();
    m.iterate();
    slowest = std::max(slowest, ms_since(t));
  } while (!m.stats.finished() && ms_since(t0) + slowest <= budget_ms &&
           !(interrupt && interrupt()));
  return m.stats;
}

const RowPoints& NonlinearDeformer::positions() const {
  return impl_->x;
}
const std::vector<int>& NonlinearDeformer::free_vertices() const {
  return impl_->free_vertices;
}
const NonlinearStats& NonlinearDeformer::stats() const {
  return impl_->stats;
}
double NonlinearDeformer::energy() const {
  return impl_->current_energy;
}

} // namespace remora
