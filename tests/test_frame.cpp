// One frame of the editor (multires/frame.h): the blend of the basis functions against the dense
// product, the normals of a region against vertex_normals() of the whole mesh, and the decode
// against decode_phong(), bit for bit.
#include <algorithm>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "remora/mesh/primitives.h"
#include "remora/multires/frame.h"

namespace remora {
namespace {

TEST(Frame, BlendIsTheProductOfTheBasisAndTheCoefficientsOnTheFreeRows) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = 5000, free = 3000, m = 3 + 4 * 2; // two handles
  BasisRows basis(free, m);
  for (Eigen::Index i = 0; i < basis.size(); ++i) basis.data()[i] = u(rng);
  Eigen::MatrixXd coefficients(m, 3);
  for (Eigen::Index i = 0; i < coefficients.size(); ++i) coefficients.data()[i] = u(rng);
  std::vector<int> rows(n);
  for (int v = 0; v < n; ++v) rows[static_cast<std::size_t>(v)] = v;
  std::shuffle(rows.begin(), rows.end(), rng);
  rows.resize(free);
  FrameRows positions = FrameRows::Constant(n, 6, 42.0);
  blend_basis(basis, coefficients, rows, positions, 2);
  const Eigen::MatrixXd expected = Eigen::MatrixXd(basis) * coefficients;
  std::vector<char> written(n, 0);
  for (int i = 0; i < free; ++i) {
    const int v = rows[static_cast<std::size_t>(i)];
    written[static_cast<std::size_t>(v)] = 1;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(positions(v, c), expected(i, c), 1e-13) << v;
    for (int c = 3; c < 6; ++c) EXPECT_EQ(positions(v, c), 42.0) << v; // normals untouched
  }
  for (int v = 0; v < n; ++v)
    if (!written[static_cast<std::size_t>(v)]) {
      EXPECT_EQ((positions.row(v).array() != 42.0).count(), 0) << v;
    }
}

TEST(Frame, RegionNormalsAreTheWholeMeshsBitForBitAndNothingElseIsWritten) {
  const Mesh mesh = make_icosphere(4, 1.0);
  const TriangleTopology topology = triangle_topology(mesh);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.02);
  Eigen::MatrixXd positions(mesh.n_vertices(), 3);
  for (const VertexHandle v : mesh.vertices())
    for (int c = 0; c < 3; ++c) positions(v.idx(), c) = mesh.point(v)[c] + noise(rng);
  // A cap: the vertices above z = 0.5.
  std::vector<int> cap;
  for (const VertexHandle v : mesh.vertices())
    if (positions(v.idx(), 2) > 0.5) cap.push_back(v.idx());
  ASSERT_GT(cap.size(), 100u);
  const NormalPlan plan = plan_normals(topology, cap);
  // Every face around the cap, each once.
  std::set<int> around;
  for (const int v : cap)
    for (int k = topology.vertex_offsets[static_cast<std::size_t>(v)];
         k < topology.vertex_offsets[static_cast<std::size_t>(v) + 1]; ++k)
      around.insert(topology.vertex_faces[static_cast<std::size_t>(k)]);
  EXPECT_EQ(std::set<int>(plan.faces.begin(), plan.faces.end()), around);
  EXPECT_EQ(plan.faces.size(), around.size());

  FrameRows frame = frame_rows(positions, Eigen::MatrixXd::Constant(positions.rows(), 3, 7.0));
  std::vector<double> scratch;
  update_normals(topology, plan, frame, scratch, 2);
  const Eigen::MatrixXd all = vertex_normals(topology, positions);
  EXPECT_EQ(Eigen::MatrixXd(frame.leftCols<3>()), positions); // positions untouched
  std::vector<char> in_cap(positions.rows(), 0);
  for (const int v : cap) {
    in_cap[static_cast<std::size_t>(v)] = 1;
    EXPECT_EQ(Eigen::RowVector3d(frame.row(v).tail<3>()), Eigen::RowVector3d(all.row(v))) << v;
  }
  for (Eigen::Index v = 0; v < positions.rows(); ++v)
    if (!in_cap[static_cast<std::size_t>(v)]) {
      EXPECT_EQ(Eigen::RowVector3d(frame.row(v).tail<3>()), Eigen::RowVector3d::Constant(7.0));
    }
}

// The frame's decode gives decode_phong()'s doubles, residuals included, into the rows asked;
// without offsets it gives the base points, and added offsets are added.
TEST(Frame, TheFramesDecodeIsDecodePhongsBitForBit) {
  const Mesh mesh = make_icosphere(3, 1.0);
  const TriangleTopology topology = triangle_topology(mesh);
  Eigen::MatrixXd positions(mesh.n_vertices(), 3);
  for (const VertexHandle v : mesh.vertices())
    for (int c = 0; c < 3; ++c) positions(v.idx(), c) = mesh.point(v)[c];
  const Eigen::MatrixXd normals = vertex_normals(topology, positions);
  // Points off the sphere, each started at face 0; every third given a residual by hand (the
  // fallback's form).
  const Eigen::MatrixXd points = 1.05 * positions.topRows(60);
  const std::vector<int> starts(60, 0);
  auto details = encode_phong(topology, positions, normals, points, starts);
  for (std::size_t i = 0; i < details.size(); i += 3) {
    details[i].residual = true;
    details[i].frame = {0.01, -0.02, 0.03};
  }
  std::vector<int> outputs(details.size());
  for (std::size_t i = 0; i < outputs.size(); ++i) outputs[i] = static_cast<int>(2 * i + 1);
  const FrameRows frame = frame_rows(positions, normals);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(2 * static_cast<Eigen::Index>(details.size()) + 1, 3);
  decode_details(topology, frame, frame_details(details, outputs, true), out, 2);
  std::vector<Eigen::Vector3d> added(details.size(), Eigen::Vector3d(1.0, 2.0, 3.0));
  Eigen::MatrixXd feet = out;
  decode_details(topology, frame, frame_details(details, outputs, false, added), feet, 2);
  for (std::size_t i = 0; i < details.size(); ++i) {
    const Eigen::Vector3d a = decode_phong(topology, positions, normals, details[i]);
    EXPECT_EQ(Eigen::Vector3d(out.row(outputs[i])), a) << i;
    if (!details[i].residual) {
      EXPECT_LT((a - points.row(static_cast<Eigen::Index>(i)).transpose()).norm(), 1e-9) << i;
    }
    EXPECT_EQ(Eigen::Vector3d(out.row(outputs[i] - 1)), Eigen::Vector3d::Zero()) << i;
    PhongDetail foot = details[i];
    foot.offset = 0.0;
    foot.residual = false;
    EXPECT_EQ(Eigen::Vector3d(feet.row(outputs[i])),
              decode_phong(topology, positions, normals, foot) + added[i])
        << i;
  }
}

} // namespace
} // namespace remora
