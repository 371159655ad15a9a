// The cascadic multigrid of paper §5.2: a hierarchy from the remesher, agreement with the direct
// solver, and fewer fine-level iterations than conjugate gradients started from zero.
#include <gtest/gtest.h>

#include "remora/common/error.h"
#include "remora/linalg/kharmonic.h"
#include "remora/linalg/solver.h"
#include "remora/mesh/primitives.h"
#include "remora/multires/multigrid.h"

namespace remora {
namespace {

/// Handle: the cap z > 0.6; fixed: z < -0.4; free in between.
Region sphere_region(const Mesh& mesh) {
  Region region{std::vector<int>(mesh.n_vertices(), Region::kFree)};
  for (auto v : mesh.vertices()) {
    const double z = mesh.point(v)[2];
    if (z > 0.6) region.label[static_cast<std::size_t>(v.idx())] = 0;
    if (z < -0.4) region.label[static_cast<std::size_t>(v.idx())] = Region::kFixed;
  }
  return region;
}

/// The rest positions, the handle lifted by 0.3 along z.
Eigen::MatrixXd lifted(const Mesh& mesh, const Region& region) {
  Eigen::MatrixXd p = positions_matrix(mesh);
  for (std::size_t i = 0; i < region.label.size(); ++i)
    if (region.label[i] == 0) p(static_cast<Eigen::Index>(i), 2) += 0.3;
  return p;
}

TEST(Multigrid, AgreesWithTheDirectSolverInFewerFineIterationsThanPlainCg) {
  const Mesh mesh = make_icosphere(5); // 10,242 vertices
  const Region region = sphere_region(mesh);
  for (int k = 1; k <= 2; ++k)
    for (MultigridMethod method : {MultigridMethod::VCycle, MultigridMethod::Cascadic}) {
      const bool vcycle = method == MultigridMethod::VCycle;
      SCOPED_TRACE(::testing::Message() << "k " << k << (vcycle ? " v-cycle" : " cascadic"));
      MultigridSolver multigrid(
          mesh, {.method = method, .k = k, .coarsest_vertices = 300, .tolerance = 1e-12});
      EXPECT_GE(multigrid.levels(), 3u);
      multigrid.set_region(region);
      const KHarmonicSystem& s = multigrid.fine_system();
      const Eigen::MatrixXd values = s.gather_constrained(lifted(mesh, region));
      const Eigen::MatrixXd x = multigrid.solve(lifted(mesh, region));

      auto direct = make_solver({.name = "ldlt"});
      direct->compute(s.matrix);
      const Eigen::MatrixXd reference = direct->solve(s.rhs(values));
      EXPECT_LE((x - reference).norm() / reference.norm(), 1e-8);

      auto cg = make_solver({.name = "cg", .tolerance = 1e-12});
      cg->compute(s.matrix);
      cg->solve(s.rhs(values));
      const auto stats = multigrid.stats();
      ASSERT_GE(stats.size(), 2u);
      EXPECT_EQ(stats.front().vertices, mesh.n_vertices());
      for (std::size_t i = 1; i < stats.size(); ++i) EXPECT_LT(stats[i].free, stats[i - 1].free);
      // The paper's cascadic scheme does not beat plain CG at this tolerance (docs/solvers.md);
      // the V-cycle preconditioner must, by far.
      if (vcycle) {
        EXPECT_LT(4 * stats.front().iterations, cg->stats().iterations)
            << "multigrid " << stats.front().iterations << " plain " << cg->stats().iterations;
      }
    }
}

TEST(Multigrid, RefusesWhatCgCannotSolveAndUseBeforeSetRegion) {
  const Mesh mesh = make_icosphere(3);
  EXPECT_THROW(MultigridSolver(mesh, {.k = 2, .areas = AreaWeights::Mixed}), InvalidArgument);
  EXPECT_THROW(MultigridSolver(mesh, {.k = 5}), InvalidArgument);
  MultigridSolver multigrid(mesh, {.coarsest_vertices = 100});
  EXPECT_THROW(multigrid.solve(Eigen::MatrixXd::Zero(3, 3)), InvalidArgument);
  EXPECT_THROW(multigrid.set_region(Region::all_fixed(mesh.n_vertices())), InvalidArgument);
}

} // namespace
} // namespace remora
