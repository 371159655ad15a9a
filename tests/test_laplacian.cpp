// The cotangent Laplacian of Eq. 1 against what is known exactly: hand-computed weights on a
// right-isosceles grid, symmetry and W 1 = 0, linear precision on flat meshes, Delta (x^2 + y^2) =
// 4 on equilateral and square lattices, the mean curvature normal of a sphere; zero-area faces;
// the symmetry defect against explicitly formed matrices and on meshes with equal vertex areas.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "remora/common/error.h"
#include "remora/geometry/laplacian.h"
#include "remora/geometry/measures.h"
#include "remora/mesh/primitives.h"
#include "support.h"

namespace remora {
namespace {

using testing::random_vector;
using testing::symmetric_unit;

/// Every vertex moved randomly by up to `fraction` of the mean edge length in x, y and z (z only
/// when `flat` is false; boundary vertices stay).
void jitter(Mesh& mesh, double fraction, std::uint32_t seed, bool flat = false) {
  double sum = 0.0;
  for (const EdgeHandle e : mesh.edges()) sum += mesh.calc_edge_length(e);
  const double h = sum / static_cast<double>(mesh.n_edges());
  std::mt19937 rng(seed);
  for (const VertexHandle v : mesh.vertices()) {
    if (mesh.is_boundary(v)) continue;
    Vec3 d = random_vector(rng, fraction * h);
    if (flat) d[2] = 0.0;
    mesh.point(v) += d;
  }
}

/// Delta f at every vertex: (W f)_i / A_i.
Eigen::VectorXd laplacian_of(const Mesh& mesh, const std::function<double(const Vec3&)>& f) {
  Eigen::VectorXd values(static_cast<Eigen::Index>(mesh.n_vertices()));
  for (const VertexHandle v : mesh.vertices()) values[v.idx()] = f(mesh.point(v));
  const Eigen::VectorXd wf = cotan_weights(mesh) * values;
  return wf.cwiseQuotient(vertex_areas_mixed(mesh));
}

/// The regular octahedron with corners on the axes at distance 1 (exact coordinates, outward).
Mesh octahedron() {
  Mesh mesh;
  std::vector<VertexHandle> v;
  for (const Vec3& p : {Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, -1, 0), Vec3(0, 0, 1),
                        Vec3(0, 0, -1)}) {
    v.push_back(mesh.add_vertex(p));
  }
  for (int sx = 0; sx < 2; ++sx) {
    for (int sy = 0; sy < 2; ++sy) {
      for (int sz = 0; sz < 2; ++sz) {
        const VertexHandle x = v[sx];
        const VertexHandle y = v[2 + sy];
        const VertexHandle z = v[4 + sz];
        // (x, y, z) is counter-clockwise seen from outside when an even number of signs is -.
        if ((sx + sy + sz) % 2 == 0) {
          mesh.add_face(x, y, z);
        } else {
          mesh.add_face(x, z, y);
        }
      }
    }
  }
  return mesh;
}

/// The defect from explicitly formed A^-1 W and A_bar^-1 W (with `interior`, both without the
/// rows of boundary vertices, and the mean over the others).
double explicit_symmetry_defect(const Mesh& mesh, bool interior = false) {
  const Eigen::SparseMatrix<double> W = cotan_weights(mesh);
  const Eigen::VectorXd areas = vertex_areas_mixed(mesh);
  const auto counted = [&](VertexHandle v) {
    return !mesh.is_isolated(v) && !(interior && mesh.is_boundary(v));
  };
  double sum = 0.0;
  int count = 0;
  for (const VertexHandle v : mesh.vertices()) {
    if (!counted(v)) continue;
    sum += areas[v.idx()];
    ++count;
  }
  const double mean = sum / count;
  Eigen::VectorXd inverse = Eigen::VectorXd::Zero(areas.size());
  Eigen::VectorXd inverse_mean = Eigen::VectorXd::Zero(areas.size());
  for (const VertexHandle v : mesh.vertices()) {
    const int i = v.idx();
    if (counted(v) && areas[i] > 0.0) {
      inverse[i] = 1.0 / areas[i];
      inverse_mean[i] = 1.0 / mean;
    }
  }
  if (interior) {
    const Eigen::SparseMatrix<double> L = inverse.asDiagonal() * W;
    const Eigen::SparseMatrix<double> L_bar = inverse_mean.asDiagonal() * W;
    return (L - L_bar).norm() / L.norm();
  }
  const Eigen::SparseMatrix<double> L = inverse.asDiagonal() * W;
  const Eigen::SparseMatrix<double> L_bar = W / mean;
  return (L - L_bar).norm() / L.norm();
}

// ---------------------------------------------------------------------------------------------
// The weights

TEST(LaplacianWeights, RightIsoscelesGridHandComputed) {
  // Every triangle has angles 45, 45, 90: the axis-aligned edges face 45-degree corners (cot 1, so
  // 1/2 from each side), the diagonals face right angles (cot 0).
  const int n = 3;
  const Mesh mesh = make_grid(n, n, 3.0, 3.0, GridSplit::Uniform);
  const Eigen::SparseMatrix<double> W = cotan_weights(mesh);
  for (const EdgeHandle e : mesh.edges()) {
    const HalfedgeHandle h = mesh.halfedge_handle(e, 0);
    const int i = mesh.from_vertex_handle(h).idx();
    const int j = mesh.to_vertex_handle(h).idx();
    const Vec3 d = mesh.point(VertexHandle(j)) - mesh.point(VertexHandle(i));
    const bool diagonal = d[0] != 0.0 && d[1] != 0.0;
    const double expected = diagonal ? 0.0 : (mesh.is_boundary(e) ? 0.5 : 1.0);
    EXPECT_NEAR(W.coeff(i, j), expected, 1e-15) << i << " " << j;
    EXPECT_EQ(W.coeff(i, j), W.coeff(j, i));
  }
  // Interior vertex (1, 1) has four axis neighbours of weight 1.
  EXPECT_NEAR(W.coeff(5, 5), -4.0, 1e-14);
  // Entries: both directions of every edge and the diagonal.
  EXPECT_EQ(W.nonZeros(), static_cast<Eigen::Index>(2 * mesh.n_edges() + mesh.n_vertices()));
}

// Unit edge weights give the graph Laplacian: -valence on the diagonal, 1 per edge.
TEST(LaplacianWeights, WeightsMatrixOfUnitWeightsIsTheGraphLaplacian) {
  const Mesh mesh = make_icosphere(2);
  const Eigen::SparseMatrix<double> W =
      weights_matrix(mesh, std::vector<double>(mesh.n_edges(), 1.0));
  for (const VertexHandle v : mesh.vertices()) {
    EXPECT_EQ(W.coeff(v.idx(), v.idx()), -static_cast<double>(mesh.valence(v)));
    for (const VertexHandle w : mesh.vv_range(v)) EXPECT_EQ(W.coeff(v.idx(), w.idx()), 1.0);
  }
  EXPECT_EQ(W.nonZeros(), static_cast<Eigen::Index>(2 * mesh.n_edges() + mesh.n_vertices()));
  EXPECT_THROW(weights_matrix(mesh, std::vector<double>(3, 1.0)), InvalidArgument);
}

TEST(LaplacianWeights, WeightsMatrixIsTheEdgeListsTripletsBitForBit) {
  // weights_matrix() builds its columns in parallel from the vertices' halfedges: the same
  // matrix, bit for bit, as triplets of every edge (both ways) and the diagonals summed in edge
  // order.
  for (const Mesh& mesh :
       {make_icosphere(5, 1.0), make_grid(70, 40, 2.0, 1.0)}) { // > 1024 vertices: parallel
    const std::vector<double> w = cotan_edge_weights(mesh);
    const auto n = static_cast<Eigen::Index>(mesh.n_vertices());
    Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(n);
    std::vector<Eigen::Triplet<double>> triplets;
    for (const EdgeHandle e : mesh.edges()) {
      const int i = mesh.from_vertex_handle(mesh.halfedge_handle(e, 0)).idx();
      const int j = mesh.to_vertex_handle(mesh.halfedge_handle(e, 0)).idx();
      const double x = w[static_cast<std::size_t>(e.idx())];
      triplets.emplace_back(i, j, x);
      triplets.emplace_back(j, i, x);
      diagonal[i] -= x;
      diagonal[j] -= x;
    }
    for (Eigen::Index i = 0; i < n; ++i) triplets.emplace_back(i, i, diagonal[i]);
    Eigen::SparseMatrix<double> expected(n, n);
    expected.setFromTriplets(triplets.begin(), triplets.end());
    const Eigen::SparseMatrix<double> got = weights_matrix(mesh, w);
    ASSERT_TRUE(got.isCompressed());
    ASSERT_EQ(got.nonZeros(), expected.nonZeros());
    for (Eigen::Index k = 0; k <= n; ++k)
      ASSERT_EQ(got.outerIndexPtr()[k], expected.outerIndexPtr()[k]);
    for (Eigen::Index k = 0; k < got.nonZeros(); ++k) {
      ASSERT_EQ(got.innerIndexPtr()[k], expected.innerIndexPtr()[k]);
      ASSERT_EQ(got.valuePtr()[k], expected.valuePtr()[k]);
    }
  }
}

TEST(LaplacianWeights, SymmetricWithZeroRowSums) {
  for (int which = 0; which < 3; ++which) {
    SCOPED_TRACE(which);
    Mesh mesh = which == 0   ? make_grid(10, 7, 1.0, 0.7)
                : which == 1 ? make_icosphere(3)
                             : make_annulus(3, 20, 0.4, 1.0);
    jitter(mesh, 0.3, 73 + static_cast<std::uint32_t>(which));
    const Eigen::SparseMatrix<double> W = cotan_weights(mesh);
    ASSERT_EQ(W.rows(), static_cast<Eigen::Index>(mesh.n_vertices()));
    ASSERT_EQ(W.cols(), W.rows());
    const Eigen::SparseMatrix<double> T = W.transpose();
    EXPECT_EQ((W - T).norm(), 0.0); // exactly symmetric
    const Eigen::VectorXd row_sums = W * Eigen::VectorXd::Ones(W.cols());
    const double largest = W.coeffs().cwiseAbs().maxCoeff();
    EXPECT_TRUE(W.coeffs().allFinite());
    EXPECT_LE(row_sums.cwiseAbs().maxCoeff(), 1e-14 * largest);
  }
}

// The weight of one edge at other points than the mesh's own is the moved mesh's weight, bit for
// bit (what the nonlinear method reads for its rest shape's cells without moving a copy).
TEST(LaplacianWeights, OneEdgeAtOtherPointsIsTheMovedMeshsWeight) {
  const Mesh mesh = make_icosphere(3);
  Mesh moved = mesh;
  jitter(moved, 0.3, 19);
  Eigen::MatrixXd points(static_cast<Eigen::Index>(mesh.n_vertices()), 3);
  for (const VertexHandle v : moved.vertices())
    for (int c = 0; c < 3; ++c) points(v.idx(), c) = moved.point(v)[c];
  const Eigen::SparseMatrix<double> W = cotan_weights(moved);
  for (const EdgeHandle e : mesh.edges()) {
    const HalfedgeHandle h = mesh.halfedge_handle(e, 0);
    const int i = mesh.from_vertex_handle(h).idx(), j = mesh.to_vertex_handle(h).idx();
    ASSERT_EQ(cotan_weight(mesh, points, e), W.coeff(i, j)) << "edge " << e.idx();
    ASSERT_NE(cotan_weight(mesh, e), W.coeff(i, j)) << "edge " << e.idx(); // the points matter
  }
}

TEST(LaplacianWeights, ZeroAreaFacesContributeNothing) {
  // a, m, b collinear (m the midpoint) with the flat face (a, b, m) under the two faces on c:
  // a manifold mesh with a zero-area face, and another zero-area face on two coincident points.
  Mesh mesh;
  const VertexHandle a = mesh.add_vertex(Vec3(0, 0, 0));
  const VertexHandle m = mesh.add_vertex(Vec3(1, 0, 0));
  const VertexHandle b = mesh.add_vertex(Vec3(2, 0, 0));
  const VertexHandle c = mesh.add_vertex(Vec3(1, 1, 0));
  const VertexHandle d = mesh.add_vertex(Vec3(1, 1, 0)); // on c
  const VertexHandle e = mesh.add_vertex(Vec3(1, 2, 0));
  mesh.add_face(a, m, c);
  mesh.add_face(m, b, c);
  mesh.add_face(a, b, m);
  mesh.add_face(c, d, e);
  ASSERT_EQ(mesh.n_faces(), 4u);
  const Eigen::SparseMatrix<double> W = cotan_weights(mesh);
  EXPECT_TRUE(W.coeffs().allFinite());
  EXPECT_EQ(W.coeff(a.idx(), b.idx()), 0.0);          // only the flat face
  EXPECT_NEAR(W.coeff(a.idx(), m.idx()), 0.5, 1e-15); // 45 degrees at c, 0 from the flat face
  EXPECT_NEAR(W.coeff(m.idx(), c.idx()), 1.0, 1e-15); // 45 at a and 45 at b: (1 + 1) / 2
  EXPECT_EQ(W.coeff(c.idx(), d.idx()), 0.0);
  EXPECT_EQ(W.coeff(d.idx(), e.idx()), 0.0);
  EXPECT_EQ(W.coeff(d.idx(), d.idx()), 0.0);
  EXPECT_TRUE(std::isfinite(laplacian_symmetry_defect(mesh)));
}

TEST(LaplacianWeights, NeedlesStayFinite) {
  Mesh mesh = make_grid(4, 4, 1.0, 1.0);
  // Squash column 1 onto column 0 up to 1e-13 and 1e-300: needles of every thinness.
  for (const VertexHandle v : mesh.vertices()) {
    Vec3& p = mesh.point(v);
    if (std::abs(p[0] - 0.25) < 1e-12) p[0] = v.idx() % 2 == 0 ? 1e-13 : 1e-300;
  }
  const Eigen::SparseMatrix<double> W = cotan_weights(mesh);
  EXPECT_TRUE(W.coeffs().allFinite());
  EXPECT_LE(W.coeffs().cwiseAbs().maxCoeff(), 1e13);
  const Eigen::VectorXd row_sums = W * Eigen::VectorXd::Ones(W.cols());
  EXPECT_LE(row_sums.cwiseAbs().maxCoeff(), 1e-14 * W.coeffs().cwiseAbs().maxCoeff());
}

TEST(LaplacianWeights, DeletedAndIsolatedVerticesHaveEmptyRows) {
  Mesh mesh = make_grid(2, 2, 1.0, 1.0, GridSplit::Uniform);
  const VertexHandle isolated = mesh.add_vertex(Vec3(5, 5, 5));
  // Deleting both faces at the corner vertex 0 leaves it isolated, and delete_face deletes it.
  std::vector<FaceHandle> at_origin;
  for (const FaceHandle f : mesh.vf_range(VertexHandle(0))) at_origin.push_back(f);
  for (const FaceHandle f : at_origin) mesh.delete_face(f, true);
  ASSERT_TRUE(mesh.status(VertexHandle(0)).deleted());
  const Eigen::SparseMatrix<double> W = cotan_weights(mesh);
  ASSERT_EQ(W.rows(), static_cast<Eigen::Index>(mesh.n_vertices()));
  const Eigen::SparseMatrix<double> T = W.transpose(); // rows as columns
  EXPECT_EQ(T.col(0).nonZeros(), 0);
  EXPECT_EQ(T.col(isolated.idx()).nonZeros(), 0);
  EXPECT_GT(T.col(4).nonZeros(), 0);
  const Eigen::VectorXd row_sums = W * Eigen::VectorXd::Ones(W.cols());
  EXPECT_LE(row_sums.cwiseAbs().maxCoeff(), 1e-14);
}

// ---------------------------------------------------------------------------------------------
// The operator: Delta f = A^-1 W f

TEST(LaplacianFlat, EquilateralGridLinearPrecisionAndQuadratic) {
  const int n = 9;
  const Mesh mesh = make_equilateral_grid(n, n, 0.3);
  const Eigen::VectorXd linear =
      laplacian_of(mesh, [](const Vec3& p) { return 3.0 * p[0] - 2.0 * p[1] + 1.0; });
  const Eigen::VectorXd quadratic =
      laplacian_of(mesh, [](const Vec3& p) { return p[0] * p[0] + p[1] * p[1]; });
  int interior = 0;
  for (const VertexHandle v : mesh.vertices()) {
    if (mesh.is_boundary(v)) continue;
    ++interior;
    EXPECT_NEAR(linear[v.idx()], 0.0, 1e-12) << v.idx();
    EXPECT_NEAR(quadratic[v.idx()], 4.0, 1e-12) << v.idx();
  }
  EXPECT_EQ(interior, (n - 1) * (n - 1));
}

TEST(LaplacianFlat, SquareGridQuadratic) {
  // Right-isosceles triangles: the mixed area of an interior vertex is one cell, h^2, and
  // sum_j W_ij |p_j - p_i|^2 = 4 h^2.
  const Mesh mesh = make_grid(6, 6, 1.5, 1.5, GridSplit::Uniform);
  const Eigen::VectorXd quadratic =
      laplacian_of(mesh, [](const Vec3& p) { return p[0] * p[0] + p[1] * p[1]; });
  for (const VertexHandle v : mesh.vertices()) {
    if (mesh.is_boundary(v)) continue;
    EXPECT_NEAR(quadratic[v.idx()], 4.0, 1e-12) << v.idx();
  }
}

TEST(LaplacianFlat, LinearPrecisionOnAnIrregularPlanarMesh) {
  // Any planar triangulation: sum_j W_ij (p_j - p_i) = 0 at interior vertices.
  Mesh mesh = make_grid(12, 12, 1.0, 1.0, GridSplit::Alternating);
  jitter(mesh, 0.3, 79, true);
  const Eigen::VectorXd linear =
      laplacian_of(mesh, [](const Vec3& p) { return 3.0 * p[0] - 2.0 * p[1] + 1.0; });
  for (const VertexHandle v : mesh.vertices()) {
    if (mesh.is_boundary(v)) continue;
    EXPECT_NEAR(linear[v.idx()], 0.0, 1e-10) << v.idx();
  }
}

TEST(LaplacianSphere, MeanCurvatureNormal) {
  // On a sphere of radius r, Delta x = -2 H n = -2 x / r^2 (H = 1 / r).
  const double r = 2.0;
  const Mesh mesh = make_icosphere(4, r);
  Eigen::MatrixX3d X(static_cast<Eigen::Index>(mesh.n_vertices()), 3);
  for (const VertexHandle v : mesh.vertices()) {
    for (int k = 0; k < 3; ++k) X(v.idx(), k) = mesh.point(v)[k];
  }
  const Eigen::MatrixX3d WX = cotan_weights(mesh) * X;
  const Eigen::VectorXd areas = vertex_areas_mixed(mesh);
  double worst = 0.0;
  for (const VertexHandle v : mesh.vertices()) {
    const Eigen::RowVector3d delta = WX.row(v.idx()) / areas[v.idx()];
    const Eigen::RowVector3d expected = -2.0 * X.row(v.idx()) / (r * r);
    worst = std::max(worst, (delta - expected).norm() / expected.norm());
  }
  EXPECT_LT(worst, 0.005); // 0.0167, 0.0083, 0.0042 at subdivisions 2, 3, 4: first order
}

// ---------------------------------------------------------------------------------------------
// Symmetry defect

TEST(LaplacianSymmetryDefect, MatchesExplicitMatrices) {
  for (int which = 0; which < 2; ++which) {
    SCOPED_TRACE(which);
    Mesh mesh = which == 0 ? make_icosphere(3) : make_disc(6, 6, 1.0);
    jitter(mesh, 0.25, 83 + static_cast<std::uint32_t>(which));
    const double defect = laplacian_symmetry_defect(mesh);
    EXPECT_GT(defect, 0.01);
    EXPECT_NEAR(defect, explicit_symmetry_defect(mesh), 1e-12 * defect);
  }
}

TEST(LaplacianSymmetryDefect, InteriorRowsMatchExplicitMatricesAndLeaveOutTheBoundary) {
  Mesh disc = make_disc(6, 6, 1.0);
  jitter(disc, 0.25, 101);
  const double interior = laplacian_symmetry_defect(disc, SymmetryRows::Interior);
  EXPECT_GT(interior, 0.01);
  EXPECT_NEAR(interior, explicit_symmetry_defect(disc, true), 1e-12 * interior);
  // A grid's pattern is the same around every interior vertex, so their areas are equal; its
  // boundary vertices have half of that (corners a quarter or so): only they make a defect.
  const Mesh grid = make_grid(12, 12, 1.0, 1.0, GridSplit::Uniform);
  EXPECT_GT(laplacian_symmetry_defect(grid), 0.1);
  EXPECT_LT(laplacian_symmetry_defect(grid, SymmetryRows::Interior), 1e-12);
  // Closed: nothing to leave out.
  Mesh sphere = make_icosphere(2);
  jitter(sphere, 0.3, 103);
  EXPECT_EQ(laplacian_symmetry_defect(sphere, SymmetryRows::Interior),
            laplacian_symmetry_defect(sphere));
}

TEST(LaplacianSymmetryDefect, ZeroWhenAllAreasAreEqual) {
  // Regular polyhedra: every vertex area is the same (to round-off for the icosahedron's
  // irrational coordinates).
  EXPECT_LT(laplacian_symmetry_defect(octahedron()), 1e-15);
  EXPECT_LT(laplacian_symmetry_defect(make_icosphere(0)), 1e-14);
  // An icosphere's areas vary a little, a jittered one's much more.
  Mesh sphere = make_icosphere(3);
  const double regular = laplacian_symmetry_defect(sphere);
  EXPECT_GT(regular, 1e-3);
  jitter(sphere, 0.3, 89);
  EXPECT_GT(laplacian_symmetry_defect(sphere), 2.0 * regular);
}

TEST(LaplacianSymmetryDefect, ScaleInvariantAndIgnoresIsolatedVertices) {
  Mesh mesh = make_icosphere(2);
  jitter(mesh, 0.3, 97);
  const double defect = laplacian_symmetry_defect(mesh);
  Mesh scaled = mesh;
  for (const VertexHandle v : scaled.vertices()) scaled.point(v) *= 37.0;
  EXPECT_NEAR(laplacian_symmetry_defect(scaled), defect, 1e-13 * defect);
  mesh.add_vertex(Vec3(9, 9, 9));
  EXPECT_EQ(laplacian_symmetry_defect(mesh), defect);
  EXPECT_EQ(laplacian_symmetry_defect(Mesh()), 0.0);
}

} // namespace
} // namespace remora
