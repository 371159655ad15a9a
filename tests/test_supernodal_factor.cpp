// The supernodal numeric factorization (linalg/supernodal_factor.h) against CHOLMOD's own on the
// same symbolic analysis: the same factor to round-off for k = 1, 2, 3 and both supernode
// settings, a refactorization with new numbers, and a matrix that is not positive definite. The
// sweeps (linalg/supernodal_solve.h) of both machine codes solve the system.
#ifdef REMORA_WITH_GPL_SOLVERS
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include <cholmod.h>

#include "remora/common/cpu.h"
#include "remora/common/error.h"
#include "remora/linalg/cholmod_settings.h"
#include "remora/linalg/kharmonic.h"
#include "remora/linalg/supernodal_factor.h"
#include "remora/linalg/supernodal_solve.h"
#include "remora/mesh/primitives.h"

namespace remora {
namespace {

/// The lower triangle of a k-harmonic system on an icosphere with its lowest vertices fixed.
SparseMatrix lower_system(int k) {
  const Mesh mesh = make_icosphere(4);
  Region region{std::vector<int>(mesh.n_vertices(), Region::kFree)};
  for (auto v : mesh.vertices())
    if (mesh.point(v)[2] < -0.5) region.label[static_cast<std::size_t>(v.idx())] = Region::kFixed;
  SparseMatrix lower = assemble_kharmonic(mesh, region, {.k = k, .areas = AreaWeights::Mean})
                           .matrix.triangularView<Eigen::Lower>();
  lower.makeCompressed();
  return lower;
}

class Cholmod {
public:
  Cholmod() {
    cholmod_start(&c);
    c.print = 0;
  }
  ~Cholmod() {
    for (cholmod_factor* f : factors) cholmod_free_factor(&f, &c);
    cholmod_finish(&c);
  }
  Cholmod(const Cholmod&) = delete;
  Cholmod& operator=(const Cholmod&) = delete;
  cholmod_sparse view(SparseMatrix& a) {
    return lower_view(static_cast<std::size_t>(a.rows()), static_cast<std::size_t>(a.nonZeros()),
                      a.outerIndexPtr(), a.innerIndexPtr(), a.valuePtr());
  }
  /// The supernodal analysis (AMD), kept until the end of the test.
  cholmod_factor* analyze(SparseMatrix& a, bool coarse) {
    cholmod_sparse m = view(a);
    c.supernodal = CHOLMOD_SUPERNODAL;
    set_supernodes(c, coarse);
    factors.push_back(cholmod_analyze(&m, &c));
    return factors.back();
  }
  cholmod_factor* copy(cholmod_factor* f) {
    factors.push_back(cholmod_copy_factor(f, &c));
    return factors.back();
  }
  cholmod_common c{};
  std::vector<cholmod_factor*> factors;
};

/// The largest difference of the two factors' values over the largest value.
double factor_difference(const cholmod_factor& a, const cholmod_factor& b) {
  const auto* x = static_cast<const double*>(a.x);
  const auto* y = static_cast<const double*>(b.x);
  double diff = 0.0, scale = 0.0;
  for (std::size_t i = 0; i < a.xsize; ++i) {
    diff = std::max(diff, std::abs(x[i] - y[i]));
    scale = std::max(scale, std::abs(y[i]));
  }
  return diff / scale;
}

TEST(SupernodalFactor, FactorsAsCholmodDoesOnTheSameAnalysis) {
  for (int k = 1; k <= 3; ++k)
    for (const bool coarse : {true, false}) {
      SCOPED_TRACE(::testing::Message() << "k " << k << (coarse ? ", coarse" : ", default"));
      SparseMatrix a = lower_system(k);
      Cholmod cm;
      cholmod_factor* ours = cm.analyze(a, coarse);
      ASSERT_NE(ours, nullptr);
      ASSERT_TRUE(ours->is_super);
      cholmod_factor* theirs = cm.copy(ours);
      SupernodalNumeric numeric(*ours, a.outerIndexPtr(), a.innerIndexPtr(),
                                static_cast<int>(a.rows()));
      ASSERT_TRUE(numeric.factorize(*ours, a.valuePtr(), cm.c));
      cholmod_sparse m = cm.view(a);
      ASSERT_TRUE(cholmod_factorize(&m, theirs, &cm.c));
      ASSERT_EQ(theirs->minor, theirs->n);
      EXPECT_EQ(ours->minor, ours->n);
      ASSERT_EQ(ours->xsize, theirs->xsize);
      EXPECT_LE(factor_difference(*ours, *theirs), 1e-13);
      // New numbers on the same analysis: 4 A has the factor 2 L.
      SparseMatrix b = 4.0 * a;
      ASSERT_TRUE(numeric.factorize(*ours, b.valuePtr(), cm.c));
      auto* x = static_cast<double*>(theirs->x);
      std::transform(x, x + theirs->xsize, x, [](double v) { return 2.0 * v; });
      EXPECT_LE(factor_difference(*ours, *theirs), 1e-13);
    }
}

TEST(SupernodalFactor, RefusesAMatrixThatIsNotPositiveDefinite) {
  SparseMatrix a = lower_system(2);
  Cholmod cm;
  cholmod_factor* f = cm.analyze(a, true);
  SupernodalNumeric numeric(*f, a.outerIndexPtr(), a.innerIndexPtr(), static_cast<int>(a.rows()));
  SparseMatrix negative = -a;
  EXPECT_FALSE(numeric.factorize(*f, negative.valuePtr(), cm.c));
  EXPECT_LT(f->minor, f->n);
  // One row made indefinite: the pivot fails in that row's column of the factor (the columns
  // before it do not read its diagonal).
  SparseMatrix one = a;
  const int row = static_cast<int>(a.rows()) / 2;
  one.coeffRef(row, row) = -1.0;
  EXPECT_FALSE(numeric.factorize(*f, one.valuePtr(), cm.c));
  const auto* perm = static_cast<const int*>(f->Perm);
  const auto at = static_cast<std::size_t>(std::find(perm, perm + f->n, row) - perm);
  EXPECT_EQ(f->minor, at);
  ASSERT_TRUE(numeric.factorize(*f, a.valuePtr(), cm.c)); // and the good numbers again
  EXPECT_EQ(f->minor, f->n);
}

TEST(SupernodalFactor, RefusesAnAnalysisThatDoesNotFit) {
  SparseMatrix a = lower_system(1);
  Cholmod cm;
  cm.c.supernodal = CHOLMOD_SIMPLICIAL;
  cholmod_sparse m = cm.view(a);
  cm.factors.push_back(cholmod_analyze(&m, &cm.c));
  EXPECT_THROW(SupernodalNumeric(*cm.factors.back(), a.outerIndexPtr(), a.innerIndexPtr(),
                                 static_cast<int>(a.rows())),
               InvalidArgument);
  cholmod_factor* f = cm.analyze(a, true);
  EXPECT_THROW(
      SupernodalNumeric(*f, a.outerIndexPtr(), a.innerIndexPtr(), static_cast<int>(a.rows()) - 1),
      InvalidArgument);
}

// Both machine codes of the sweeps (the AVX2 one where this processor has it) solve P A Pᵀ y = z
// for 1, 3 (the nonlinear deformer's) and 7 (a handle's basis functions) right-hand sides at once,
// and agree to round-off.
TEST(SupernodalSolve, BothMachineCodesSolveTheSystem) {
  SparseMatrix a = lower_system(2);
  Cholmod cm;
  cholmod_factor* f = cm.analyze(a, false);
  cholmod_sparse m = cm.view(a);
  ASSERT_TRUE(cholmod_factorize(&m, f, &cm.c));
  ASSERT_EQ(f->minor, f->n);
  const auto n = static_cast<int>(a.rows());
  const auto* perm = static_cast<const int*>(f->Perm);
  const SparseMatrix full = a.selfadjointView<Eigen::Lower>();
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (const int columns : {1, 3, 7}) {
    SCOPED_TRACE(::testing::Message() << columns << " columns");
    std::vector<double> z(static_cast<std::size_t>(n) * static_cast<std::size_t>(columns));
    for (double& v : z) v = uniform(random);
    std::vector<double> best = z, baseline = z;
    supernodal_forward(*f, best.data(), columns);
    supernodal_backward(*f, best.data(), columns);
    set_baseline_code(true);
    supernodal_forward(*f, baseline.data(), columns);
    supernodal_backward(*f, baseline.data(), columns);
    set_baseline_code(false);
    double diff = 0.0, scale = 0.0;
    for (std::size_t i = 0; i < z.size(); ++i) {
      diff = std::max(diff, std::abs(best[i] - baseline[i]));
      scale = std::max(scale, std::abs(baseline[i]));
    }
    EXPECT_LE(diff, 1e-12 * scale) << (use_avx2() ? "AVX2" : "baseline") << " code as the best";
    // The residual of column c in A's own order: row perm[k] of y is y_k.
    for (int c = 0; c < columns; ++c) {
      Eigen::VectorXd y(n), rhs(n);
      for (int k = 0; k < n; ++k) {
        const auto at = static_cast<std::size_t>(k) * static_cast<std::size_t>(columns) +
                        static_cast<std::size_t>(c);
        y[perm[k]] = best[at];
        rhs[perm[k]] = z[at];
      }
      EXPECT_LE((full * y - rhs).norm(), 1e-9 * rhs.norm()) << "column " << c;
    }
  }
}

} // namespace
} // namespace remora
#endif
