// Multigrid solvers for the k-harmonic systems of linalg/kharmonic.h on a hierarchy built by the
// remesher: the paper's cascadic scheme (Botsch & Kobbelt 2004, §5.2) and, by default, conjugate
// gradients preconditioned by a V-cycle with Galerkin coarse operators.
//
// The hierarchy is built by the remesher: level 0 is the given (fine) mesh, level i+1 the remesh
// of level i at twice its target length, until a level has at most `coarsest_vertices` vertices.
// The remesher's correspondence links consecutive levels: every vertex of level i has a location
// (face + barycentric coordinates) on level i+1 (prolongation) and every vertex of level i+1 one on
// level i (restriction of labels and boundary values).
//
// set_region() maps the region down the hierarchy: a coarse vertex takes the label of the finer
// vertex with the largest barycentric weight at its location.
//
// Cascadic (the paper): every level's system is assembled the same way, the coarsest is solved
// directly, the whole vertex solution is prolongated to the next finer level by barycentric
// interpolation and its free part starts conjugate gradients (Jacobi) there, up to level 0.
// Measured (tests, docs/solvers.md): it needs *more* fine-level iterations than plain CG from
// zero, because each coarse problem has its own, slightly shifted region boundary, and the smooth
// error that leaves is what CG reduces slowest.
//
// VCycle (default): the prolongation P_i (free vertices of level i+1 -> free vertices of level i,
// barycentric weights through the correspondence) defines Galerkin coarse operators
// A_{i+1} = P_iᵀ A_i P_i, so every level is consistent with the fine system; a V-cycle (damped
// Jacobi pre- and post-smoothing, direct solve on the coarsest) preconditions CG on level 0.
#pragma once

#include <memory>
#include <vector>

#include "remora/linalg/kharmonic.h"
#include "remora/linalg/solver.h"
#include "remora/mesh/mesh.h"
#include "remora/mesh/surface_point.h"

namespace remora {

enum class MultigridMethod { VCycle, Cascadic };

struct MultigridOptions {
  MultigridMethod method = MultigridMethod::VCycle;
  int smoothing_sweeps = 2; ///< VCycle: damped Jacobi sweeps before and after the coarse correction
  double jacobi_damping = 0.6;
  int k = 2;
  AreaWeights areas = AreaWeights::Mean; ///< Mean or MixedSymmetric (CG needs SPD)
  std::size_t coarsest_vertices = 500;   ///< stop coarsening at this many vertices or fewer
  int max_levels = 12;
  double tolerance = 1e-10;       ///< relative residual on level 0
  double coarse_tolerance = 1e-4; ///< relative residual on the intermediate levels
  int max_iterations = 0;         ///< per level and column; 0 = 10 × the dimension
  int threads = 0;                ///< remeshing threads (0 = all)
};

struct MultigridLevelStats {
  std::size_t vertices = 0, free = 0;
  /// Cascadic: CG iterations of the last solve on this level (0 on the coarsest, solved
  /// directly). VCycle: the preconditioned CG iterations on level 0, 0 elsewhere.
  int iterations = 0;
};

class MultigridSolver {
public:
  /// Builds the hierarchy of `fine` (copied). Throws InvalidArgument for an empty mesh or
  /// unsupported options.
  MultigridSolver(const Mesh& fine, const MultigridOptions& options = {});

  /// Maps `region` (on the fine mesh) to every level, assembles the systems, factors the
  /// coarsest. Levels whose mapped region is unusable (a handle too small to survive, no free
  /// vertex left) are dropped from the bottom, down to level 0 alone.
  void set_region(const Region& region);

  /// The fine system's free values (rows in the order of fine_system().free_vertices) for the
  /// given values of the constrained vertices: `vertex_values` has one row per fine vertex (any
  /// number of columns, e.g. x, y, z); only the constrained rows are read. The whole constrained
  /// region is needed, not only the vertices coupled to free ones: coarse levels take their
  /// boundary values from wherever their vertices lie on the finer level.
  Eigen::MatrixXd solve(const Eigen::MatrixXd& vertex_values);

  const KHarmonicSystem& fine_system() const;
  std::size_t levels() const { return meshes_.size(); }
  /// The levels in use after set_region(), fine first.
  std::vector<MultigridLevelStats> stats() const;

private:
  struct Level;
  MultigridOptions options_;
  std::vector<Mesh> meshes_;
  // to_coarser_[i][v]: vertex v of level i on level i+1; to_finer_[i][c]: vertex c of level i+1
  // on level i.
  std::vector<std::vector<SurfacePoint>> to_coarser_, to_finer_;
  std::vector<std::unique_ptr<Level>> active_;
  void set_region_vcycle(const Region& region);
  void set_region_cascadic(const Region& region);
  Eigen::MatrixXd solve_cascadic(const Eigen::MatrixXd& vertex_values);
  Eigen::VectorXd vcycle(std::size_t level, const Eigen::VectorXd& r) const;

public:
  ~MultigridSolver();
  MultigridSolver(MultigridSolver&&) noexcept;
  MultigridSolver& operator=(MultigridSolver&&) noexcept;
};

} // namespace remora
