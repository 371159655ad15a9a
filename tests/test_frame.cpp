// One frame of the editor (multires/frame.h): the blend of the basis functions against the dense
// product, the normals of a region against vertex_normals() of the whole mesh, the decode
// against decode_phong(), bit for bit; and the frame exported for a client (frame_export.h),
// replayed here and by the library's client replay (frame_replay.h, the page's kernel.wasm).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "remora/common/error.h"
#include "remora/geometry/selection.h"
#include "remora/mesh/primitives.h"
#include "remora/multires/editor.h"
#include "remora/multires/frame.h"
#include "remora/multires/frame_export.h"
#include "remora/multires/frame_replay.h"
#include "remora/multires/motion_blend.h"
#include "remora/multires/phong_decode.h"

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
  update_normals(plan, frame, scratch, 2);
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
  const FrameDetails records = frame_details(topology, details, outputs, true);
  // In the order of their faces' first corners, each with its face's corners.
  for (std::size_t i = 0; i < records.records.size(); ++i) {
    const FrameDetails::Record& r = records.records[i];
    EXPECT_EQ(r.corners, topology.faces[static_cast<std::size_t>(r.face)]) << i;
    if (i > 0) {
      EXPECT_LE(records.records[i - 1].corners[0], r.corners[0]) << i;
    }
  }
  decode_details(frame, records, out, 2);
  std::vector<Eigen::Vector3d> added;
  for (std::size_t i = 0; i < details.size(); ++i)
    added.emplace_back(0.001 * double(i), 1.0, -0.002 * double(i));
  Eigen::MatrixXd feet = out;
  decode_details(frame, frame_details(topology, details, outputs, false, added), feet, 2);
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

// The region's frame as a client evaluates it (frame_export.h), replayed here from the exported
// single-precision data with the library's own Phong point: the editor's positions within the
// round-off of single precision, every movable vertex written once.
Eigen::MatrixXd replay_export(const FrameExport& f, const std::vector<Transform>& transforms,
                              std::size_t movable) {
  const std::size_t local = f.rest.size() / 6, columns = 3 + 4 * std::size_t(f.handles);
  Eigen::MatrixXd x(local, 3), n(local, 3);
  for (std::size_t v = 0; v < local; ++v)
    for (int c = 0; c < 3; ++c) {
      x(v, c) = f.rest[6 * v + c];
      n(v, c) = f.rest[6 * v + 3 + c];
    }
  Eigen::MatrixXd coefficients(columns, 3);
  coefficients.topRows<3>().setIdentity();
  for (int j = 0; j < f.handles; ++j)
    coefficients.block<4, 3>(3 + 4 * j, 0) = transforms[std::size_t(j)].transpose();
  // Blended motions: pivots at the handles' rest centroids, weights in the basis's "1" columns.
  std::vector<Eigen::Vector3d> pivots(std::size_t(f.handles), Eigen::Vector3d::Zero());
  for (int j = 0; j < f.handles; ++j) {
    const std::uint32_t b = f.handle_begin[std::size_t(j)], e = f.handle_begin[std::size_t(j) + 1];
    for (std::uint32_t i = b; i < e; ++i)
      pivots[std::size_t(j)] += x.row(f.handle_local[i]).transpose() / double(e - b);
  }
  const HandleMotions motions = handle_motions(transforms, pivots);
  for (std::size_t i = 0; i < f.free_local.size(); ++i) {
    Eigen::RowVectorXd row(columns);
    for (std::size_t c = 0; c < columns; ++c) row[Eigen::Index(c)] = f.basis[i * columns + c];
    if (!f.blended) {
      x.row(f.free_local[i]) = row * coefficients;
      continue;
    }
    const Eigen::Vector3d p = x.row(f.free_local[i]).transpose();
    ScrewTwist sum;
    Eigen::Vector3d y = p;
    for (int j = 0; j < f.handles; ++j) {
      const double w = row[3 + 4 * j + 3];
      sum.omega += w * motions.twist[std::size_t(j)].omega;
      sum.v += w * motions.twist[std::size_t(j)].v;
      y += w * ((motions.stretch[std::size_t(j)] - Eigen::Matrix3d::Identity()) *
                (p - motions.pivot[std::size_t(j)]));
    }
    x.row(f.free_local[i]) = screw_apply(sum, y).transpose();
  }
  for (int j = 0; j < f.handles; ++j)
    for (std::uint32_t i = f.handle_begin[std::size_t(j)]; i < f.handle_begin[std::size_t(j) + 1];
         ++i) {
      const std::uint32_t v = f.handle_local[i];
      const Transform& t = transforms[std::size_t(j)];
      x.row(v) = (t.leftCols<3>() * x.row(v).transpose() + t.col(3)).transpose();
    }
  const auto corner = [&](std::uint32_t face, int k) { return f.faces[3 * face + std::size_t(k)]; };
  for (std::size_t i = 0; i < f.normal_vertices.size(); ++i) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::uint32_t r = f.ring_begin[i]; r < f.ring_begin[i + 1]; ++r) {
      const Eigen::Vector3d p0 = x.row(corner(f.ring[r], 0)).transpose(),
                            p1 = x.row(corner(f.ring[r], 1)).transpose(),
                            p2 = x.row(corner(f.ring[r], 2)).transpose();
      sum += (p1 - p0).cross(p2 - p0);
    }
    n.row(f.normal_vertices[i]) =
        sum.norm() > 0 ? Eigen::Vector3d(sum.normalized()) : Eigen::Vector3d::Zero();
  }
  Eigen::MatrixXd out = Eigen::MatrixXd::Constant(Eigen::Index(movable), 3, std::nan(""));
  for (std::size_t r = 0; r < f.record_face.size(); ++r) {
    Eigen::Vector3d xs[3], ns[3];
    for (int k = 0; k < 3; ++k) {
      xs[k] = x.row(corner(f.record_face[r], k)).transpose();
      ns[k] = n.row(corner(f.record_face[r], k)).transpose();
    }
    const std::array<double, 3> bary = {f.record_bary[3 * r], f.record_bary[3 * r + 1],
                                        f.record_bary[3 * r + 2]};
    std::array<double, 3> residual{};
    const std::int32_t q = f.record_residual[r];
    if (q >= 0)
      residual = {f.residuals[3 * std::size_t(q)], f.residuals[3 * std::size_t(q) + 1],
                  f.residuals[3 * std::size_t(q) + 2]};
    Eigen::Vector3d p =
        phong_detail::phong_point(xs, ns, bary, f.record_offset[r], q >= 0 ? &residual : nullptr);
    if (!f.offsets.empty())
      p += Eigen::Vector3d(f.offsets[3 * r], f.offsets[3 * r + 1], f.offsets[3 * r + 2]);
    EXPECT_TRUE(std::isnan(out(f.record_slot[r], 0))) << "slot " << f.record_slot[r] << " twice";
    out.row(f.record_slot[r]) = p.transpose();
  }
  return out;
}

// A bumpy sphere with two handles, one turned and stretched, one moved: the editor of each detail
// mode, its transforms set, passed to check(editor, transforms, mode).
template <typename Check>
void for_each_export_case(const Check& check) {
  Mesh mesh = make_icosphere(4, 1.0);
  for (const VertexHandle v : mesh.vertices()) {
    const Vec3 p = mesh.point(v);
    mesh.set_point(v, p * (1.0 + 0.03 * std::sin(9 * p[0]) * std::sin(9 * p[1])));
  }
  const std::vector<int> support = select_sphere(mesh, Vec3(0, 0, 1), 1.2);
  const std::vector<std::vector<int>> handles = {select_sphere(mesh, Vec3(0, 0, 1), 0.3),
                                                 select_sphere(mesh, Vec3(0.707, 0, 0.707), 0.2)};
  const std::vector<Transform> transforms = {
      compose(rotation({1, 2, 0.5}, 0.8, {0, 0, 1}), scaling({1.3, 0.8, 1.1}, {0, 0, 1})),
      translation({0.1, 0.3, -0.2})};
  for (const DetailMode mode : {DetailMode::Normal, DetailMode::Displacement}) {
    EditorOptions options;
    options.details = mode;
    Editor editor(mesh, options);
    editor.set_region(support, handles);
    for (int j = 0; j < 2; ++j) editor.set_transform(j, transforms[std::size_t(j)]);
    check(editor, transforms, mode);
  }
}

TEST(FrameExport, ReplayedInSinglePrecisionGivesTheEditorsPositions) {
  for_each_export_case([](Editor& editor, const std::vector<Transform>& transforms,
                          DetailMode mode) {
    const FrameExport f = frame_export(editor);
    EXPECT_EQ(f.offsets.empty(), mode == DetailMode::Normal);
    const std::vector<int>& movable = editor.movable_vertices();
    const Eigen::MatrixXd replayed = replay_export(f, transforms, movable.size());
    const Eigen::MatrixXd& p = editor.positions();
    double worst = 0.0;
    for (std::size_t i = 0; i < movable.size(); ++i)
      worst = std::max(worst, (replayed.row(Eigen::Index(i)) - p.row(movable[i])).norm());
    EXPECT_LT(worst, 1e-5) << "detail mode " << int(mode); // the sphere's diagonal is 3.5
    EXPECT_GT(worst, 0.0);                                 // single precision is not double
    // The iterating energies' frames are exported as the linear one plus the server's offsets
    // (the test below); blended motions as a blend of motions.
    editor.set_method(EditMethod::Nonlinear);
    const FrameExport corrected = frame_export(editor);
    EXPECT_TRUE(corrected.corrected && !corrected.blended);
    EXPECT_EQ(corrected.basis, f.basis);
    editor.set_nonlinear_energy(NonlinearEnergy::BlendedMotions);
    const FrameExport blended = frame_export(editor);
    EXPECT_TRUE(blended.blended);
    const Eigen::MatrixXd replayed_blend = replay_export(blended, transforms, movable.size());
    const Eigen::MatrixXd& q = editor.positions();
    double worst_blend = 0.0, apart = 0.0;
    for (std::size_t i = 0; i < movable.size(); ++i) {
      worst_blend =
          std::max(worst_blend, (replayed_blend.row(Eigen::Index(i)) - q.row(movable[i])).norm());
      apart = std::max(apart, (replayed.row(Eigen::Index(i)) - q.row(movable[i])).norm());
    }
    EXPECT_LT(worst_blend, 1e-5) << "detail mode " << int(mode);
    EXPECT_GT(apart, 1e-3); // blended motions are not the linear frame
  });
}

// The library's client replay (frame_replay.h), which the page runs as WebAssembly, over an
// export: a linear frame, x, y, z per movable vertex in single precision (NaN where no record
// wrote). With `parts` > 1 each step runs over that many ranges, one after the other, as the
// page's threads split it.
std::vector<float> replay_with_library(const FrameExport& f,
                                       const std::vector<Transform>& transforms,
                                       std::size_t movable, std::uint32_t parts = 1,
                                       const std::vector<float>* row_offsets = nullptr) {
  FrameReplay r;
  r.handles = std::uint32_t(f.handles);
  r.rows = std::uint32_t(f.free_local.size());
  r.columns = 3 + 4 * r.handles;
  r.normal_count = std::uint32_t(f.normal_vertices.size());
  r.record_count = std::uint32_t(f.record_face.size());
  for (const std::uint32_t t : f.ring) r.ring_faces = std::max(r.ring_faces, t + 1);
  r.rest = f.rest.data();
  r.free_local = f.free_local.data();
  r.basis = f.basis.data();
  r.handle_begin = f.handle_begin.data();
  r.handle_local = f.handle_local.data();
  r.faces = f.faces.data();
  r.normal_vertices = f.normal_vertices.data();
  r.ring_begin = f.ring_begin.data();
  r.ring = f.ring.data();
  r.record_face = f.record_face.data();
  r.record_slot = f.record_slot.data();
  r.record_bary = f.record_bary.data();
  r.record_offset = f.record_offset.data();
  r.record_residual = f.record_residual.data();
  r.residuals = f.residuals.data();
  r.offsets = f.offsets.empty() ? nullptr : f.offsets.data();
  r.row_offsets = row_offsets ? row_offsets->data() : nullptr;
  std::vector<double> x(f.rest.begin(), f.rest.end()), cross(3 * std::size_t(r.ring_faces));
  r.x = x.data();
  r.cross = cross.data();
  std::vector<double> maps;
  for (const Transform& t : transforms)
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 4; ++col) maps.push_back(t(row, col));
  std::vector<float> out(3 * movable, std::nanf(""));
  if (parts == 1) {
    replay_blend(r, maps.data());
    replay_move_handles(r, maps.data());
    replay_normals(r);
    replay_decode(r, out.data());
    return out;
  }
  const auto split = [parts](std::uint32_t n, std::uint32_t p) {
    return std::pair{std::uint32_t(std::uint64_t(n) * p / parts),
                     std::uint32_t(std::uint64_t(n) * (p + 1) / parts)};
  };
  for (std::uint32_t p = 0; p < parts; ++p) {
    const auto [b, e] = split(r.rows, p);
    replay_blend_rows(r, maps.data(), b, e);
  }
  replay_move_handles(r, maps.data());
  for (std::uint32_t p = 0; p < parts; ++p) {
    const auto [b, e] = split(r.ring_faces, p);
    replay_face_crosses(r, b, e);
  }
  for (std::uint32_t p = 0; p < parts; ++p) {
    const auto [b, e] = split(r.normal_count, p);
    replay_vertex_normals(r, b, e);
  }
  for (std::uint32_t p = 0; p < parts; ++p) {
    const auto [b, e] = split(r.record_count, p);
    replay_decode_records(r, out.data(), b, e);
  }
  return out;
}

TEST(FrameReplay, TheLibrarysReplayGivesTheEditorsPositionsAndTheTestsReplay) {
  for_each_export_case([](Editor& editor, const std::vector<Transform>& transforms,
                          DetailMode mode) {
    const FrameExport f = frame_export(editor);
    const std::vector<int>& movable = editor.movable_vertices();
    const std::vector<float> library = replay_with_library(f, transforms, movable.size());
    const Eigen::MatrixXd tests = replay_export(f, transforms, movable.size());
    const Eigen::MatrixXd& p = editor.positions();
    double to_editor = 0.0, to_test = 0.0;
    for (std::size_t i = 0; i < movable.size(); ++i)
      for (int c = 0; c < 3; ++c) {
        const double q = library[3 * i + std::size_t(c)];
        ASSERT_TRUE(std::isfinite(q)) << "movable vertex " << i << " not written";
        to_editor = std::max(to_editor, std::abs(q - p(movable[i], c)));
        to_test = std::max(to_test, std::abs(q - tests(Eigen::Index(i), c)));
      }
    EXPECT_LT(to_editor, 1e-5) << "detail mode " << int(mode); // the sphere's diagonal is 3.5
    // The same arithmetic in double precision, rounded to single once at the end.
    EXPECT_LT(to_test, 1e-6) << "detail mode " << int(mode);
    // Split over ranges (the page's two threads, or three), the same bits.
    for (const std::uint32_t parts : {2u, 3u}) {
      const std::vector<float> split = replay_with_library(f, transforms, movable.size(), parts);
      EXPECT_EQ(std::memcmp(split.data(), library.data(), split.size() * sizeof(float)), 0)
          << parts << " parts";
    }
    // A map that the replay does not apply is seen: the identity's frame is far from it.
    const std::vector<float> rest =
        replay_with_library(f, {Transform::Identity(), Transform::Identity()}, movable.size());
    double apart = 0.0;
    for (std::size_t i = 0; i < rest.size(); ++i)
      apart = std::max(apart, std::abs(double(rest[i]) - double(library[i])));
    EXPECT_GT(apart, 0.1);
  });
}

// The largest coordinate difference between a replay and the editor's positions.
double replay_error(const std::vector<float>& replay, const Eigen::MatrixXd& p,
                    const std::vector<int>& movable) {
  double worst = 0.0;
  for (std::size_t i = 0; i < movable.size(); ++i)
    for (int c = 0; c < 3; ++c)
      worst = std::max(worst, std::abs(double(replay[3 * i + std::size_t(c)]) - p(movable[i], c)));
  return worst;
}

// Method nonlinear (rotated-laplacian): the linear replay plus the row offsets of the server's
// last frame is that frame, to single precision; under a handle turned 2° further it is far
// closer to the converged frame there than the linear frame is (its error grows with the change,
// not with the whole turn); linear's offsets vanish to round-off; stale offsets and blended
// motions are refused.
TEST(FrameExport, TheServersRowOffsetsMakeTheLinearReplayTheNonlinearFrame) {
  for_each_export_case(
      [](Editor& editor, const std::vector<Transform>& transforms, DetailMode mode) {
        const std::vector<int>& movable = editor.movable_vertices();
        editor.positions();
        double linear_offset = 0.0;
        for (const float d : frame_base_offsets(editor))
          linear_offset = std::max(linear_offset, double(std::abs(d)));
        EXPECT_LT(linear_offset, 1e-6) << "detail mode " << int(mode);
        editor.set_method(EditMethod::Nonlinear);
        const Eigen::MatrixXd p = editor.positions();
        ASSERT_TRUE(editor.converged());
        const FrameExport f = frame_export(editor);
        const std::vector<float> d = frame_base_offsets(editor);
        ASSERT_EQ(d.size(), 3 * f.free_local.size());
        const double corrected =
            replay_error(replay_with_library(f, transforms, movable.size(), 1, &d), p, movable);
        const double linear =
            replay_error(replay_with_library(f, transforms, movable.size()), p, movable);
        EXPECT_LT(corrected, 1e-6) << "detail mode " << int(mode); // the sphere's diagonal is 3.5
        EXPECT_GT(linear, 1e-2) << "detail mode " << int(mode);
        // Split over two threads as the page does: the same bits.
        EXPECT_EQ(replay_with_library(f, transforms, movable.size(), 2, &d),
                  replay_with_library(f, transforms, movable.size(), 1, &d));

        std::vector<Transform> turned = transforms;
        turned[0] = compose(rotation({0, 1, 0}, 2.0 * M_PI / 180.0, {0, 0, 1}), transforms[0]);
        editor.set_transform(0, turned[0]);
        EXPECT_THROW(frame_base_offsets(editor), InvalidArgument); // a transform after the frame
        const Eigen::MatrixXd q = editor.positions();
        const double predicted =
            replay_error(replay_with_library(f, turned, movable.size(), 1, &d), q, movable);
        const double linear_there =
            replay_error(replay_with_library(f, turned, movable.size()), q, movable);
        EXPECT_LT(predicted, 0.1 * linear_there)
            << "detail mode " << int(mode) << ": " << predicted << " against " << linear_there;

        editor.set_nonlinear_energy(NonlinearEnergy::BlendedMotions);
        editor.positions();
        EXPECT_THROW(frame_base_offsets(editor), InvalidArgument);
      });
}

} // namespace
} // namespace remora
