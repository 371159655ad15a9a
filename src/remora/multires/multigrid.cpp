#include "remora/multires/multigrid.h"

#include <algorithm>

#include "remora/common/error.h"
#include "remora/geometry/measures.h"
#include "remora/remesh/remesh.h"

namespace remora {

struct MultigridSolver::Level {
  Region region;
  KHarmonicSystem system; // Cascadic: every level; VCycle: level 0 only
  std::unique_ptr<Solver> solver;
  MultigridLevelStats stats;
  // VCycle
  SparseMatrix a;       // the operator on this level's free vertices
  SparseMatrix prolong; // next coarser level's free values -> this level's
  Eigen::VectorXd inverse_diagonal;
  std::vector<int> free_vertices; // row -> vertex
};

MultigridSolver::~MultigridSolver() = default;
MultigridSolver::MultigridSolver(MultigridSolver&&) noexcept = default;
MultigridSolver& MultigridSolver::operator=(MultigridSolver&&) noexcept = default;

MultigridSolver::MultigridSolver(const Mesh& fine, const MultigridOptions& options)
    : options_(options) {
  if (fine.n_faces() == 0) throw InvalidArgument("multigrid: the mesh has no faces");
  if (options.areas == AreaWeights::Mixed)
    throw InvalidArgument("multigrid: conjugate gradients need a symmetric system; use the "
                          "'mean' or 'mixed-symmetric' areas");
  if (options.k < 1 || options.k > 3) throw InvalidArgument("multigrid: k must be 1, 2 or 3");
  if (options.max_levels < 1) throw InvalidArgument("multigrid: max_levels must be >= 1");
  meshes_.push_back(fine);
  double length = mean_edge_length(fine);
  while (static_cast<int>(meshes_.size()) < options.max_levels &&
         meshes_.back().n_vertices() > options.coarsest_vertices) {
    length *= 2.0;
    RemeshOptions remesh_options;
    remesh_options.target_length = length;
    remesh_options.compute_report = false;
    remesh_options.threads = options.threads;
    RemeshResult coarse = remesh(meshes_.back(), remesh_options);
    // Stop when coarsening no longer pays (tiny components keep their vertices).
    if (coarse.mesh.n_vertices() * 10 > meshes_.back().n_vertices() * 7) break;
    to_coarser_.push_back(std::move(coarse.input_on_output));
    to_finer_.push_back(std::move(coarse.output_on_input));
    meshes_.push_back(std::move(coarse.mesh));
  }
}

namespace {

// The labels of level i+1 from those of level i: each coarse vertex takes the label of the
// finer vertex with the largest weight at its location.
Region coarsen_region(const Mesh& finer, const Region& finer_region, std::size_t coarse_vertices,
                      const std::vector<SurfacePoint>& coarse_on_finer) {
  Region out;
  out.label.assign(coarse_vertices, Region::kFixed);
  for (std::size_t c = 0; c < coarse_vertices; ++c) {
    const SurfacePoint& sp = coarse_on_finer[c];
    if (!sp.face.is_valid()) continue;
    const auto fv = face_vertices(finer, sp.face);
    const auto k = static_cast<std::size_t>(std::max_element(sp.bary.begin(), sp.bary.end()) -
                                            sp.bary.begin());
    out.label[c] = finer_region.label[static_cast<std::size_t>(fv[k].idx())];
  }
  return out;
}

} // namespace

void MultigridSolver::set_region(const Region& region) {
  active_.clear();
  if (options_.method == MultigridMethod::VCycle)
    set_region_vcycle(region);
  else
    set_region_cascadic(region);
}

void MultigridSolver::set_region_vcycle(const Region& region) {
  auto fine = std::make_unique<Level>();
  fine->region = region;
  fine->system = assemble_kharmonic(meshes_[0], region, {.k = options_.k, .areas = options_.areas});
  fine->a = fine->system.matrix;
  fine->free_vertices = fine->system.free_vertices;
  fine->stats.vertices = meshes_[0].n_vertices();
  fine->stats.free = fine->free_vertices.size();
  active_.push_back(std::move(fine));
  for (std::size_t i = 1; i < meshes_.size(); ++i) {
    Level& finer = *active_.back();
    if (finer.free_vertices.size() <= options_.coarsest_vertices) break;
    auto level = std::make_unique<Level>();
    level->region =
        coarsen_region(meshes_[i - 1], finer.region, meshes_[i].n_vertices(), to_finer_[i - 1]);
    // Prolongation: each finer free vertex interpolates the free corners of its coarse face.
    std::vector<int> column(meshes_[i].n_vertices(), -1);
    std::vector<Eigen::Triplet<double>> weights;
    for (std::size_t r = 0; r < finer.free_vertices.size(); ++r) {
      const SurfacePoint& sp = to_coarser_[i - 1][static_cast<std::size_t>(finer.free_vertices[r])];
      if (!sp.face.is_valid()) continue;
      const auto fv = face_vertices(meshes_[i], sp.face);
      for (int k = 0; k < 3; ++k) {
        const auto c = static_cast<std::size_t>(fv[k].idx());
        const double w = sp.bary[static_cast<std::size_t>(k)];
        if (level->region.label[c] != Region::kFree || !(w > 0)) continue;
        if (column[c] < 0) {
          column[c] = static_cast<int>(level->free_vertices.size());
          level->free_vertices.push_back(static_cast<int>(c));
        }
        weights.emplace_back(static_cast<Eigen::Index>(r), column[c], w);
      }
    }
    const std::size_t n_coarse = level->free_vertices.size();
    if (n_coarse == 0 || n_coarse * 10 > finer.free_vertices.size() * 8) break;
    finer.prolong.resize(static_cast<Eigen::Index>(finer.free_vertices.size()),
                         static_cast<Eigen::Index>(n_coarse));
    finer.prolong.setFromTriplets(weights.begin(), weights.end());
    const SparseMatrix ap = finer.a * finer.prolong;
    level->a = SparseMatrix(finer.prolong.transpose()) * ap;
    level->stats.vertices = meshes_[i].n_vertices();
    level->stats.free = n_coarse;
    active_.push_back(std::move(level));
  }
  // Factor the coarsest; a level that does not factor (a coarse region too thin to keep every
  // free vertex coupled) is dropped.
  while (true) {
    Level& coarsest = *active_.back();
    coarsest.prolong = SparseMatrix();
    try {
      coarsest.solver = make_solver({});
      coarsest.solver->compute(coarsest.a);
      break;
    } catch (const NumericalError&) {
      if (active_.size() == 1) throw;
      active_.pop_back();
    }
  }
  for (auto& level : active_) level->inverse_diagonal = level->a.diagonal().cwiseInverse();
}

void MultigridSolver::set_region_cascadic(const Region& region) {
  for (std::size_t i = 0; i < meshes_.size(); ++i) {
    auto level = std::make_unique<Level>();
    if (i == 0)
      level->region = region;
    else
      level->region = coarsen_region(meshes_[i - 1], active_.back()->region,
                                     meshes_[i].n_vertices(), to_finer_[i - 1]);
    try {
      level->system =
          assemble_kharmonic(meshes_[i], level->region, {.k = options_.k, .areas = options_.areas});
    } catch (const InvalidArgument&) {
      if (i == 0) throw;
      break; // the region does not survive this coarsening: use the finer levels only
    }
    level->stats.vertices = meshes_[i].n_vertices();
    level->stats.free = level->system.free_vertices.size();
    active_.push_back(std::move(level));
  }
  // Conjugate gradients on every level but the coarsest, which is factored.
  for (std::size_t i = 0; i < active_.size(); ++i) {
    SolverOptions solver_options;
    if (i + 1 < active_.size()) {
      solver_options.name = "cg";
      solver_options.tolerance = i == 0 ? options_.tolerance : options_.coarse_tolerance;
      solver_options.max_iterations = options_.max_iterations;
    }
    active_[i]->solver = make_solver(solver_options);
    active_[i]->solver->compute(active_[i]->system.matrix);
  }
}

const KHarmonicSystem& MultigridSolver::fine_system() const {
  if (active_.empty()) throw InvalidArgument("multigrid: call set_region() first");
  return active_.front()->system;
}

std::vector<MultigridLevelStats> MultigridSolver::stats() const {
  std::vector<MultigridLevelStats> out;
  for (const auto& level : active_) out.push_back(level->stats);
  return out;
}

Eigen::MatrixXd MultigridSolver::solve(const Eigen::MatrixXd& vertex_values) {
  if (active_.empty()) throw InvalidArgument("multigrid: call set_region() first");
  if (vertex_values.rows() != static_cast<Eigen::Index>(meshes_[0].n_vertices()))
    throw InvalidArgument("multigrid: " + std::to_string(vertex_values.rows()) +
                          " rows of vertex values for a mesh of " +
                          std::to_string(meshes_[0].n_vertices()) + " vertices");
  if (!vertex_values.allFinite())
    throw InvalidArgument("multigrid: the vertex values contain a NaN or Inf");
  if (options_.method == MultigridMethod::Cascadic) return solve_cascadic(vertex_values);
  const KHarmonicSystem& system = active_[0]->system;
  const Eigen::MatrixXd b = system.rhs(system.gather_constrained(vertex_values));
  // Preconditioned conjugate gradients, one column at a time, from zero.
  const Level& fine = *active_[0];
  const int limit =
      options_.max_iterations > 0 ? options_.max_iterations : static_cast<int>(10 * fine.a.rows());
  Eigen::MatrixXd x = Eigen::MatrixXd::Zero(b.rows(), b.cols());
  int most = 0;
  for (Eigen::Index c = 0; c < b.cols(); ++c) {
    const Eigen::VectorXd rhs = b.col(c);
    const double norm_b = rhs.norm();
    if (norm_b == 0) continue;
    Eigen::VectorXd xc = Eigen::VectorXd::Zero(rhs.size());
    Eigen::VectorXd r = rhs;
    Eigen::VectorXd z = vcycle(0, r);
    Eigen::VectorXd p = z;
    double rz = r.dot(z);
    int it = 0;
    while (r.norm() > options_.tolerance * norm_b) {
      if (it == limit)
        throw NumericalError("multigrid: no convergence after " + std::to_string(limit) +
                             " iterations (relative residual " + std::to_string(r.norm() / norm_b) +
                             "); raise max_iterations or use a direct solver");
      const Eigen::VectorXd ap = fine.a * p;
      const double alpha = rz / p.dot(ap);
      xc += alpha * p;
      r -= alpha * ap;
      z = vcycle(0, r);
      const double rz_next = r.dot(z);
      p = z + (rz_next / rz) * p;
      rz = rz_next;
      ++it;
    }
    x.col(c) = xc;
    most = std::max(most, it);
  }
  active_[0]->stats.iterations = most;
  return x;
}

// One V-cycle for A_level e = r from e = 0: damped Jacobi, coarse correction, damped Jacobi
// (symmetric, so it preconditions CG).
Eigen::VectorXd MultigridSolver::vcycle(std::size_t level, const Eigen::VectorXd& r) const {
  const Level& l = *active_[level];
  if (level + 1 == active_.size()) return l.solver->solve(r).col(0);
  const double w = options_.jacobi_damping;
  Eigen::VectorXd e = w * l.inverse_diagonal.cwiseProduct(r);
  for (int s = 1; s < options_.smoothing_sweeps; ++s)
    e += w * l.inverse_diagonal.cwiseProduct(r - l.a * e);
  const Eigen::VectorXd coarse = vcycle(level + 1, l.prolong.transpose() * (r - l.a * e));
  e += l.prolong * coarse;
  for (int s = 0; s < options_.smoothing_sweeps; ++s)
    e += w * l.inverse_diagonal.cwiseProduct(r - l.a * e);
  return e;
}

Eigen::MatrixXd MultigridSolver::solve_cascadic(const Eigen::MatrixXd& vertex_values) {
  const std::size_t levels = active_.size();
  const Eigen::Index columns = vertex_values.cols();
  // Values of every constrained vertex on every level: at a coarse vertex's location on the finer
  // level, interpolated when the whole finer face is constrained, else the value of the vertex
  // whose label the coarse vertex took.
  std::vector<Eigen::MatrixXd> values(levels);
  values[0] = vertex_values;
  for (std::size_t i = 1; i < levels; ++i) {
    const Region& finer = active_[i - 1]->region;
    const Region& region = active_[i]->region;
    const Mesh& finer_mesh = meshes_[i - 1];
    values[i].setZero(static_cast<Eigen::Index>(meshes_[i].n_vertices()), columns);
    for (std::size_t c = 0; c < meshes_[i].n_vertices(); ++c) {
      if (region.label[c] == Region::kFree) continue;
      const SurfacePoint& sp = to_finer_[i - 1][c];
      if (!sp.face.is_valid()) continue;
      const auto fv = face_vertices(finer_mesh, sp.face);
      bool all = true;
      for (int k = 0; k < 3; ++k)
        all = all && finer.label[static_cast<std::size_t>(fv[k].idx())] != Region::kFree;
      auto row = values[i].row(static_cast<Eigen::Index>(c));
      if (all) {
        for (int k = 0; k < 3; ++k)
          row += sp.bary[static_cast<std::size_t>(k)] * values[i - 1].row(fv[k].idx());
      } else {
        const auto k = static_cast<std::size_t>(std::max_element(sp.bary.begin(), sp.bary.end()) -
                                                sp.bary.begin());
        row = values[i - 1].row(fv[k].idx());
      }
    }
  }
  // Coarsest directly, then up the hierarchy; `full` holds every vertex of the level just solved.
  Eigen::MatrixXd full, free_values;
  for (std::size_t step = 0; step < levels; ++step) {
    const std::size_t i = levels - 1 - step;
    Level& level = *active_[i];
    const Eigen::MatrixXd b = level.system.rhs(level.system.gather_constrained(values[i]));
    if (step == 0) {
      free_values = level.solver->solve(b);
      level.stats.iterations = 0;
    } else {
      // Start value: the coarser solution at each free vertex's location on it.
      Eigen::MatrixXd guess = Eigen::MatrixXd::Zero(
          static_cast<Eigen::Index>(level.system.free_vertices.size()), columns);
      const Mesh& coarse = meshes_[i + 1];
      for (std::size_t r = 0; r < level.system.free_vertices.size(); ++r) {
        const SurfacePoint& sp =
            to_coarser_[i][static_cast<std::size_t>(level.system.free_vertices[r])];
        if (!sp.face.is_valid()) continue;
        const auto fv = face_vertices(coarse, sp.face);
        auto row = guess.row(static_cast<Eigen::Index>(r));
        for (int k = 0; k < 3; ++k)
          row += sp.bary[static_cast<std::size_t>(k)] * full.row(fv[k].idx());
      }
      free_values = level.solver->solve(b, &guess);
      level.stats.iterations = level.solver->stats().iterations;
    }
    if (i == 0) break;
    full = values[i];
    for (std::size_t r = 0; r < level.system.free_vertices.size(); ++r)
      full.row(level.system.free_vertices[r]) = free_values.row(static_cast<Eigen::Index>(r));
  }
  return free_values;
}

} // namespace remora
