#include "remora/multires/frame.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstddef>

#include <Eigen/Geometry>
#include <fmt/format.h>

#include "remora/common/error.h"
#include "remora/common/parallel.h"
#include "remora/multires/phong_decode.h"

namespace remora {

namespace {
// How far ahead decode_details() and update_normals() prefetch a face's rows.
constexpr std::size_t kRowPrefetch = 8;

// The rows of a face's corners (48 bytes each, across two cache lines for some).
void prefetch_rows(const FrameRows& frame, const std::array<int, 3>& face) {
  for (const int c : face) {
    const double* row = frame.data() + 6 * static_cast<Eigen::Index>(c);
    __builtin_prefetch(row);
    __builtin_prefetch(row + 5);
  }
}
} // namespace

FrameRows frame_rows(const Eigen::MatrixXd& positions, const Eigen::MatrixXd& normals) {
  if (positions.cols() != 3 || normals.cols() != 3 || positions.rows() != normals.rows())
    throw InvalidArgument(fmt::format("frame_rows: positions are {}×{} and normals {}×{}; give "
                                      "two n×3 matrices",
                                      positions.rows(), positions.cols(), normals.rows(),
                                      normals.cols()));
  FrameRows frame(positions.rows(), 6);
  frame.leftCols<3>() = positions;
  frame.rightCols<3>() = normals;
  return frame;
}

void blend_basis(const BasisRows& basis, const Eigen::MatrixXd& coefficients,
                 const std::vector<int>& free_vertices, FrameRows& frame, int threads) {
  assert(basis.rows() == static_cast<Eigen::Index>(free_vertices.size()));
  assert(basis.cols() == coefficients.rows() && coefficients.cols() == 3);
  const Eigen::Index m = basis.cols();
  parallel_for_static(free_vertices.size(), threads, [&](std::size_t row) {
    const double* b = basis.data() + static_cast<Eigen::Index>(row) * m;
    double x = 0.0, y = 0.0, z = 0.0;
    for (Eigen::Index k = 0; k < m; ++k) {
      x += b[k] * coefficients(k, 0);
      y += b[k] * coefficients(k, 1);
      z += b[k] * coefficients(k, 2);
    }
    double* out = frame.data() + 6 * static_cast<Eigen::Index>(free_vertices[row]);
    out[0] = x;
    out[1] = y;
    out[2] = z;
  });
}

NormalPlan plan_normals(const TriangleTopology& topology, const std::vector<int>& vertices) {
  NormalPlan plan;
  plan.vertices = vertices;
  std::vector<int> slot(topology.faces.size(), -1);
  plan.ring_begin.reserve(vertices.size() + 1);
  plan.ring_begin.push_back(0);
  for (const int v : vertices) {
    const auto i = static_cast<std::size_t>(v);
    for (int k = topology.vertex_offsets[i]; k < topology.vertex_offsets[i + 1]; ++k) {
      const int f = topology.vertex_faces[static_cast<std::size_t>(k)];
      int& s = slot[static_cast<std::size_t>(f)];
      if (s < 0) {
        s = static_cast<int>(plan.faces.size());
        plan.faces.push_back(f);
        plan.corners.push_back(topology.faces[static_cast<std::size_t>(f)]);
      }
      plan.ring.push_back(s);
    }
    plan.ring_begin.push_back(static_cast<int>(plan.ring.size()));
  }
  return plan;
}

void update_normals(const NormalPlan& plan, FrameRows& frame, std::vector<double>& scratch,
                    int threads) {
  scratch.resize(3 * plan.faces.size());
  const auto position = [&](int v) {
    const double* p = frame.data() + 6 * static_cast<Eigen::Index>(v);
    return Eigen::Vector3d(p[0], p[1], p[2]);
  };
  const std::size_t faces = plan.faces.size();
  parallel_for_static(faces, threads, [&](std::size_t i) {
    if (i + kRowPrefetch < faces) prefetch_rows(frame, plan.corners[i + kRowPrefetch]);
    const auto& f = plan.corners[i];
    const Eigen::Vector3d p0 = position(f[0]);
    const Eigen::Vector3d n = (position(f[1]) - p0).cross(position(f[2]) - p0);
    scratch[3 * i] = n[0];
    scratch[3 * i + 1] = n[1];
    scratch[3 * i + 2] = n[2];
  });
  parallel_for_static(plan.vertices.size(), threads, [&](std::size_t i) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int k = plan.ring_begin[i]; k < plan.ring_begin[i + 1]; ++k) {
      const auto s = 3 * static_cast<std::size_t>(plan.ring[static_cast<std::size_t>(k)]);
      sum += Eigen::Vector3d(scratch[s], scratch[s + 1], scratch[s + 2]);
    }
    const double len = sum.norm();
    const Eigen::Vector3d n = len > 0.0 ? Eigen::Vector3d(sum / len) : Eigen::Vector3d::Zero();
    double* out = frame.data() + 6 * static_cast<Eigen::Index>(plan.vertices[i]) + 3;
    out[0] = n[0];
    out[1] = n[1];
    out[2] = n[2];
  });
}

FrameDetails frame_details(const TriangleTopology& topology,
                           const std::vector<PhongDetail>& details, const std::vector<int>& outputs,
                           bool keep_offsets, const std::vector<Eigen::Vector3d>& added) {
  if (outputs.size() != details.size() || (!added.empty() && added.size() != details.size()))
    throw InvalidArgument(fmt::format("frame_details: {} details, {} outputs, {} added offsets",
                                      details.size(), outputs.size(), added.size()));
  // The details by their faces' first corners, in their own order among equals: counted.
  const auto first_corner = [&](std::size_t i) {
    return static_cast<std::size_t>(
        topology.faces[static_cast<std::size_t>(details[i].base.face.idx())][0]);
  };
  std::size_t corners = 0;
  for (std::size_t i = 0; i < details.size(); ++i) corners = std::max(corners, first_corner(i) + 1);
  std::vector<std::size_t> start(corners + 1, 0), order(details.size());
  for (std::size_t i = 0; i < details.size(); ++i) ++start[first_corner(i) + 1];
  for (std::size_t v = 1; v < start.size(); ++v) start[v] += start[v - 1];
  for (std::size_t i = 0; i < details.size(); ++i) order[start[first_corner(i)]++] = i;
  FrameDetails out;
  out.records.reserve(details.size());
  out.outputs.reserve(details.size());
  out.offsets.reserve(added.size());
  for (const std::size_t i : order) {
    const PhongDetail& d = details[i];
    const int face = d.base.face.idx();
    FrameDetails::Record r{d.base.bary, keep_offsets ? d.offset : 0.0, face, -1,
                           topology.faces[static_cast<std::size_t>(face)]};
    if (keep_offsets && d.residual) {
      r.residual = static_cast<int>(out.residuals.size());
      out.residuals.push_back(d.frame);
    }
    out.records.push_back(r);
    out.outputs.push_back(outputs[i]);
    if (!added.empty()) out.offsets.push_back(added[i]);
  }
  return out;
}

void decode_details(const FrameRows& frame, const FrameDetails& details, Eigen::MatrixXd& positions,
                    int threads) {
  const std::size_t count = details.records.size();
  parallel_for_static(count, threads, [&](std::size_t i) {
    // The gathers wait on memory: ask for the rows of a later record's face.
    if (i + kRowPrefetch < count) prefetch_rows(frame, details.records[i + kRowPrefetch].corners);
    const FrameDetails::Record& r = details.records[i];
    Eigen::Vector3d x[3], n[3];
    const auto& f = r.corners;
    for (int k = 0; k < 3; ++k) {
      const double* row =
          frame.data() + 6 * static_cast<Eigen::Index>(f[static_cast<std::size_t>(k)]);
      x[k] = Eigen::Vector3d(row[0], row[1], row[2]);
      n[k] = Eigen::Vector3d(row[3], row[4], row[5]);
    }
    Eigen::Vector3d p = phong_detail::phong_point(
        x, n, r.bary, r.offset,
        r.residual >= 0 ? &details.residuals[static_cast<std::size_t>(r.residual)] : nullptr);
    if (!details.offsets.empty()) p += details.offsets[i];
    const int v = details.outputs[i];
    positions(v, 0) = p[0];
    positions(v, 1) = p[1];
    positions(v, 2) = p[2];
  });
}

} // namespace remora
