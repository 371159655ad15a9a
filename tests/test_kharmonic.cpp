// The k-harmonic systems of paper §3 against what is known exactly: constants in the kernel,
// linear precision on flat meshes, convergence to the radial solutions of Δu = 0 and Δ²u = 0 on an
// annulus, symmetry of the mean-area and area-scaled forms, and the errors that keep a
// factorization from ever meeting a singular matrix.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Dense>

#include "remora/common/error.h"
#include "remora/geometry/laplacian.h"
#include "remora/geometry/measures.h"
#include "remora/linalg/kharmonic.h"
#include "remora/linalg/solver.h"
#include "remora/mesh/primitives.h"

namespace remora {
namespace {

double radius(const Mesh& mesh, VertexHandle v) {
  const Vec3& p = mesh.point(v);
  return std::hypot(p[0], p[1]);
}

/// Solves the system for one scalar function given on the constrained vertices by `value`.
Eigen::VectorXd solve_scalar(const Mesh& mesh, const KHarmonicSystem& system,
                             const std::function<double(VertexHandle)>& value,
                             const std::string& solver = "ldlt") {
  Eigen::MatrixXd c(static_cast<Eigen::Index>(system.constrained_vertices.size()), 1);
  for (std::size_t i = 0; i < system.constrained_vertices.size(); ++i)
    c(static_cast<Eigen::Index>(i), 0) = value(VertexHandle(system.constrained_vertices[i]));
  auto s = make_solver({.name = solver});
  s->compute(system.matrix);
  Eigen::VectorXd x = s->solve(system.rhs(c)).col(0);
  (void)mesh;
  return x;
}

/// A disc of radius 1: handle 0 inside r <= inner, fixed outside r >= outer, free in between.
Region disc_region(const Mesh& mesh, double inner, double outer) {
  Region region = Region::all_fixed(mesh.n_vertices());
  for (auto v : mesh.vertices()) {
    const double r = radius(mesh, v);
    if (r <= inner + 1e-9)
      region.label[static_cast<std::size_t>(v.idx())] = 0;
    else if (r < outer - 1e-9)
      region.label[static_cast<std::size_t>(v.idx())] = Region::kFree;
  }
  return region;
}

TEST(KHarmonic, PositionsGoToAMatrixAndBack) {
  Mesh mesh = make_icosphere(2);
  const Eigen::MatrixXd p = positions_matrix(mesh);
  ASSERT_EQ(p.rows(), static_cast<Eigen::Index>(mesh.n_vertices()));
  const Eigen::MatrixXd moved = 2.0 * p + Eigen::MatrixXd::Ones(p.rows(), 3);
  set_positions(mesh, moved);
  EXPECT_EQ(positions_matrix(mesh), moved);
  EXPECT_THROW(set_positions(mesh, moved.topRows(3)), InvalidArgument);
  EXPECT_THROW(set_positions(mesh, moved.leftCols(2)), InvalidArgument);
}

TEST(KHarmonic, ConstantsAreInTheKernelForEveryKAndWeighting) {
  Mesh mesh = make_icosphere(3);
  Region region = Region::all_fixed(mesh.n_vertices());
  for (auto v : mesh.vertices())
    if (mesh.point(v)[2] > -0.3) region.label[static_cast<std::size_t>(v.idx())] = Region::kFree;
  for (int k = 1; k <= 3; ++k)
    for (AreaWeights w : {AreaWeights::Mixed, AreaWeights::Mean, AreaWeights::MixedSymmetric}) {
      SCOPED_TRACE(::testing::Message() << "k " << k << " " << to_string(w));
      const KHarmonicSystem s = assemble_kharmonic(mesh, region, {.k = k, .areas = w});
      const Eigen::VectorXd ones_f = Eigen::VectorXd::Ones(s.matrix.rows());
      const Eigen::VectorXd ones_c = Eigen::VectorXd::Ones(s.coupling.cols());
      const Eigen::VectorXd residual = s.matrix * ones_f + s.coupling * ones_c;
      EXPECT_LE(residual.cwiseAbs().maxCoeff(),
                1e-10 * s.matrix.cwiseAbs().sum() / static_cast<double>(ones_f.size()));
    }
}

TEST(KHarmonic, LinearFunctionsAreReproducedOnAFlatMesh) {
  // Jittered flat disc; the free region keeps k rings away from the mesh boundary, where the
  // one-sided Laplacian of a linear function is not zero.
  Mesh mesh = make_disc(12, 6, 1.0);
  std::mt19937 rng(3);
  for (auto v : mesh.vertices()) {
    if (radius(mesh, v) > 0.99) continue;
    Vec3 p = mesh.point(v);
    p[0] += 0.02 * (static_cast<double>(rng()) / 4294967296.0 - 0.5);
    p[1] += 0.02 * (static_cast<double>(rng()) / 4294967296.0 - 0.5);
    mesh.set_point(v, p);
  }
  Region region = Region::all_fixed(mesh.n_vertices());
  for (auto v : mesh.vertices())
    if (radius(mesh, v) < 0.5) region.label[static_cast<std::size_t>(v.idx())] = Region::kFree;
  auto linear = [&](VertexHandle v) {
    const Vec3& p = mesh.point(v);
    return 0.3 + 1.7 * p[0] - 0.9 * p[1];
  };
  for (int k = 1; k <= 3; ++k)
    for (AreaWeights w : {AreaWeights::Mixed, AreaWeights::Mean, AreaWeights::MixedSymmetric}) {
      SCOPED_TRACE(::testing::Message() << "k " << k << " " << to_string(w));
      const KHarmonicSystem s = assemble_kharmonic(mesh, region, {.k = k, .areas = w});
      // Mean areas: linear precision needs equal areas, which a jittered mesh has not, except
      // for k = 1, where the areas cancel.
      if (w == AreaWeights::Mean && k > 1) continue;
      const Eigen::VectorXd x = solve_scalar(mesh, s, linear, s.symmetric ? "ldlt" : "lu");
      double worst = 0;
      for (std::size_t r = 0; r < s.free_vertices.size(); ++r)
        worst = std::max(worst, std::abs(x[static_cast<Eigen::Index>(r)] -
                                         linear(VertexHandle(s.free_vertices[r]))));
      EXPECT_LE(worst, 1e-10);
    }
}

/// Radial solutions on the annulus inner < r < outer with u = 1 inside, u = 0 outside:
/// k = 1: a + b ln r; k = 2: a + b r² + c ln r + d r² ln r with u' = 0 at both radii.
double radial_solution(int k, double r, double inner, double outer) {
  if (k == 1) return std::log(r / outer) / std::log(inner / outer);
  Eigen::Matrix4d m;
  Eigen::Vector4d b(1, 0, 0, 0);
  auto row = [](double x) {
    return Eigen::RowVector4d(1, x * x, std::log(x), x * x * std::log(x));
  };
  auto derivative = [](double x) {
    return Eigen::RowVector4d(0, 2 * x, 1 / x, 2 * x * std::log(x) + x);
  };
  m << row(inner), derivative(inner), row(outer), derivative(outer);
  const Eigen::Vector4d c = m.fullPivLu().solve(b);
  return row(r).dot(c);
}

TEST(KHarmonic, ConvergesToTheRadialSolutionsUnderRefinement) {
  const double inner = 0.25, outer = 0.75;
  for (int k = 1; k <= 2; ++k)
    for (AreaWeights w : {AreaWeights::Mean, AreaWeights::MixedSymmetric}) {
      std::vector<double> errors;
      for (int rings : {8, 16, 32}) {
        const Mesh mesh = make_disc(rings, 6, 1.0);
        const Region region = disc_region(mesh, inner, outer);
        const KHarmonicSystem s = assemble_kharmonic(mesh, region, {.k = k, .areas = w});
        const Eigen::VectorXd x = solve_scalar(mesh, s, [&](VertexHandle v) {
          return region.label[static_cast<std::size_t>(v.idx())] == 0 ? 1.0 : 0.0;
        });
        double worst = 0;
        for (std::size_t r = 0; r < s.free_vertices.size(); ++r) {
          const double rad = radius(mesh, VertexHandle(s.free_vertices[r]));
          worst = std::max(worst, std::abs(x[static_cast<Eigen::Index>(r)] -
                                           radial_solution(k, rad, inner, outer)));
        }
        errors.push_back(worst);
      }
      SCOPED_TRACE(::testing::Message() << "k " << k << " " << to_string(w) << " errors "
                                        << errors[0] << " " << errors[1] << " " << errors[2]);
      // k = 1 converges at second order; k = 2 at first order, since the clamped condition
      // u' = 0 comes from the constrained rings.
      const double rate = k == 1 ? 3.0 : 1.6;
      EXPECT_LT(errors[1], errors[0] / rate);
      EXPECT_LT(errors[2], errors[1] / rate);
      EXPECT_LT(errors[2], k == 1 ? 2e-4 : 3e-2);
    }
}

TEST(KHarmonic, SymmetricFormsAreSymmetricAndTheMixedOneIsNot) {
  Mesh mesh = make_disc(10, 6, 1.0);
  std::mt19937 rng(9);
  for (auto v : mesh.vertices()) {
    Vec3 p = mesh.point(v);
    p[2] += 0.1 * (static_cast<double>(rng()) / 4294967296.0);
    p[0] += 0.03 * (static_cast<double>(rng()) / 4294967296.0);
    mesh.set_point(v, p);
  }
  const Region region = disc_region(mesh, 0.2, 0.8);
  for (int k = 1; k <= 3; ++k) {
    const KHarmonicSystem mixed =
        assemble_kharmonic(mesh, region, {.k = k, .areas = AreaWeights::Mixed});
    const KHarmonicSystem mean =
        assemble_kharmonic(mesh, region, {.k = k, .areas = AreaWeights::Mean});
    const KHarmonicSystem scaled =
        assemble_kharmonic(mesh, region, {.k = k, .areas = AreaWeights::MixedSymmetric});
    auto asymmetry = [](const SparseMatrix& a) {
      const SparseMatrix t = a.transpose();
      return (a - t).norm() / a.norm();
    };
    EXPECT_EQ(asymmetry(mean.matrix), 0.0);
    EXPECT_EQ(asymmetry(scaled.matrix), 0.0);
    EXPECT_GT(asymmetry(mixed.matrix), 1e-3) << "k " << k;
    EXPECT_FALSE(mixed.symmetric);
    // The mixed system and the area-scaled one have the same solutions.
    auto lift = [&](VertexHandle v) {
      return region.label[static_cast<std::size_t>(v.idx())] == 0 ? 1.0 : 0.0;
    };
    const Eigen::VectorXd a = solve_scalar(mesh, mixed, lift, "lu");
    const Eigen::VectorXd b = solve_scalar(mesh, scaled, lift, "ldlt");
    EXPECT_LE((a - b).cwiseAbs().maxCoeff(), 1e-10) << "k " << k;
  }
}

// The assembler's rows against the definition, with dense matrices: rows F of
// (−W)(S(−W))^(k−1), S = I (Mean) or A⁻¹ (MixedSymmetric, Mixed), Mixed rows scaled by A⁻¹,
// split into the free and the constrained columns. One assembler serves several regions.
TEST(KHarmonic, TheAssemblerBuildsTheRowsOfTheDefinition) {
  Mesh mesh = make_disc(8, 6, 1.0);
  std::mt19937 rng(5);
  for (auto v : mesh.vertices()) {
    Vec3 p = mesh.point(v);
    p[2] += 0.05 * (static_cast<double>(rng()) / 4294967296.0);
    mesh.set_point(v, p);
  }
  const auto n = static_cast<Eigen::Index>(mesh.n_vertices());
  const Eigen::MatrixXd minus_w = -Eigen::MatrixXd(cotan_weights(mesh));
  const Eigen::VectorXd area = vertex_areas_mixed(mesh);
  const KHarmonicAssembler assembler(mesh);
  for (const auto& [inner, outer] : {std::pair{0.2, 0.8}, std::pair{0.0, 0.5}}) {
    const Region region = disc_region(mesh, inner, outer);
    for (int k = 1; k <= 3; ++k)
      for (AreaWeights w : {AreaWeights::Mixed, AreaWeights::Mean, AreaWeights::MixedSymmetric}) {
        SCOPED_TRACE(::testing::Message() << "k " << k << " " << to_string(w));
        const Eigen::MatrixXd s = w == AreaWeights::Mean
                                      ? Eigen::MatrixXd::Identity(n, n)
                                      : Eigen::MatrixXd(area.cwiseInverse().asDiagonal());
        Eigen::MatrixXd power = minus_w;
        for (int i = 1; i < k; ++i) power = power * s * minus_w;
        if (w == AreaWeights::Mixed) power = s * power;
        const KHarmonicSystem sys = assembler.assemble(region, {.k = k, .areas = w});
        const Eigen::MatrixXd a(sys.matrix), c(sys.coupling);
        const double scale = power.cwiseAbs().maxCoeff();
        for (std::size_t r = 0; r < sys.free_vertices.size(); ++r) {
          const auto i = static_cast<Eigen::Index>(r);
          for (std::size_t q = 0; q < sys.free_vertices.size(); ++q)
            ASSERT_NEAR(a(i, static_cast<Eigen::Index>(q)),
                        power(sys.free_vertices[r], sys.free_vertices[q]), 1e-12 * scale);
          for (std::size_t q = 0; q < sys.constrained_vertices.size(); ++q)
            ASSERT_NEAR(c(i, static_cast<Eigen::Index>(q)),
                        power(sys.free_vertices[r], sys.constrained_vertices[q]), 1e-12 * scale);
        }
        // Every constrained vertex a free row reaches is a column, and only those.
        for (const int v : sys.constrained_vertices) {
          double reach = 0.0;
          for (const int f : sys.free_vertices) reach += std::abs(power(f, v));
          EXPECT_GT(reach, 0.0) << v;
        }
        // Bit for bit symmetric up to k = 2 without the averaging that k = 3 needs.
        if (sys.symmetric) {
          EXPECT_EQ(Eigen::MatrixXd(a.transpose()), a);
        }
      }
  }
}

// keep_rows(): a region's system copied out of the kept rows is the one multiplied out, bit for
// bit, for every k and weighting (rows of several blocks: the multiplied-out rows come in blocks
// of consecutive rows above 4,096); the rows of another k or weighting are multiplied out.
TEST(KHarmonic, KeptRowsGiveTheSameSystemsBitForBit) {
  const Mesh mesh = make_icosphere(5);
  const KHarmonicAssembler plain(mesh);
  KHarmonicAssembler kept(mesh);
  EXPECT_EQ(kept.kept_row_bytes(), 0u);
  Region region{std::vector<int>(mesh.n_vertices(), Region::kFree)};
  for (auto v : mesh.vertices()) {
    const double z = mesh.point(v)[2];
    if (z > 0.6) region.label[static_cast<std::size_t>(v.idx())] = 0;
    if (z < -0.2) region.label[static_cast<std::size_t>(v.idx())] = Region::kFixed;
  }
  const auto same = [](const SparseMatrix& x, const SparseMatrix& y) {
    return x.rows() == y.rows() && x.cols() == y.cols() && x.nonZeros() == y.nonZeros() &&
           std::equal(x.outerIndexPtr(), x.outerIndexPtr() + x.outerSize() + 1,
                      y.outerIndexPtr()) &&
           std::equal(x.innerIndexPtr(), x.innerIndexPtr() + x.nonZeros(), y.innerIndexPtr()) &&
           std::equal(x.valuePtr(), x.valuePtr() + x.nonZeros(), y.valuePtr());
  };
  for (int k = 1; k <= 3; ++k)
    for (AreaWeights w : {AreaWeights::Mixed, AreaWeights::Mean, AreaWeights::MixedSymmetric}) {
      SCOPED_TRACE(::testing::Message() << "k " << k << " " << to_string(w));
      kept.keep_rows({.k = k, .areas = w});
      EXPECT_GT(kept.kept_row_bytes(), 0u);
      for (const int other_k : {1, 2, 3}) { // the kept rows' k, and others multiplied out
        const KHarmonicSystem a = plain.assemble(region, {.k = other_k, .areas = w});
        const KHarmonicSystem b = kept.assemble(region, {.k = other_k, .areas = w});
        EXPECT_TRUE(same(a.matrix, b.matrix)) << "k " << other_k;
        EXPECT_TRUE(same(a.coupling, b.coupling)) << "k " << other_k;
        EXPECT_EQ(a.constrained_vertices, b.constrained_vertices);
        EXPECT_EQ(a.free_vertices, b.free_vertices);
      }
    }
  EXPECT_THROW(kept.keep_rows({.k = 4}), InvalidArgument);
}

TEST(KHarmonic, ClearErrorsInsteadOfSingularSystems) {
  const Mesh mesh = make_disc(6, 6, 1.0);
  const std::size_t n = mesh.n_vertices();
  auto expect_error = [&](const Region& region, int k, const std::string& needle) {
    try {
      assemble_kharmonic(mesh, region, {.k = k});
      ADD_FAILURE() << "no error for: " << needle;
    } catch (const InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  Region all_free{std::vector<int>(n, Region::kFree)};
  expect_error(all_free, 2, "whole connected component");
  expect_error(Region::all_fixed(n), 2, "no vertex is free");
  expect_error(Region{std::vector<int>(n - 1, Region::kFree)}, 2, "labels for a mesh of");
  Region bad_label = disc_region(mesh, 0.2, 0.8);
  bad_label.label[3] = -7;
  expect_error(bad_label, 2, "label -7");
  expect_error(disc_region(mesh, 0.2, 0.8), 4, "k = 4");
  Region gap = disc_region(mesh, 0.2, 0.8);
  for (int& l : gap.label)
    if (l == 0) l = 1; // handle 0 missing
  expect_error(gap, 2, "handle 0 has no vertex");
  Region far = disc_region(mesh, 0.2, 0.8);
  far.label[n - 1] = 1; // a handle on the outer rim, far from every free vertex
  expect_error(far, 2, "handle 1 touches no free vertex");
}

TEST(KHarmonic, AFreeRegionReachingTheMeshBoundaryUsesTheNaturalCondition) {
  // Handle at the centre, the left half of the rim fixed, everything else (the right half of the
  // rim too) free. With the natural condition at the free rim, k = 1 obeys the maximum
  // principle, and the free rim is not pinned to 0 but rises towards the handle.
  const Mesh mesh = make_disc(10, 6, 1.0);
  Region region{std::vector<int>(mesh.n_vertices(), Region::kFree)};
  for (auto v : mesh.vertices()) {
    const Vec3& p = mesh.point(v);
    if (radius(mesh, v) < 0.15) region.label[static_cast<std::size_t>(v.idx())] = 0;
    if (mesh.is_boundary(v) && p[0] < 0)
      region.label[static_cast<std::size_t>(v.idx())] = Region::kFixed;
  }
  const KHarmonicSystem s = assemble_kharmonic(mesh, region, {.k = 1});
  const Eigen::VectorXd x = solve_scalar(mesh, s, [&](VertexHandle v) {
    return region.label[static_cast<std::size_t>(v.idx())] == 0 ? 1.0 : 0.0;
  });
  EXPECT_GE(x.minCoeff(), -1e-12);
  EXPECT_LE(x.maxCoeff(), 1.0 + 1e-12);
  // Free rim vertices on the right are not held at 0: they rise towards the handle.
  double right_rim = 0;
  for (std::size_t r = 0; r < s.free_vertices.size(); ++r) {
    const VertexHandle v(s.free_vertices[r]);
    if (mesh.is_boundary(v) && mesh.point(v)[0] > 0.9) right_rim = x[static_cast<Eigen::Index>(r)];
  }
  EXPECT_GT(right_rim, 0.05);
}

} // namespace
} // namespace remora
