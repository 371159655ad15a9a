#include "remora/multires/frame.h"

#include <cassert>
#include <cmath>
#include <cstddef>

#include <Eigen/Geometry>

#include "remora/common/parallel.h"

namespace remora {

void blend_basis(const BasisRows& basis, const Eigen::MatrixXd& coefficients,
                 const std::vector<int>& free_vertices, RowPoints& positions, int threads) {
  assert(basis.rows() == static_cast<Eigen::Index>(free_vertices.size()));
  assert(basis.cols() == coefficients.rows() && coefficients.cols() == 3);
  const Eigen::Index m = basis.cols();
  parallel_for(free_vertices.size(), threads, [&](std::size_t row) {
    const double* b = basis.data() + static_cast<Eigen::Index>(row) * m;
    double x = 0.0, y = 0.0, z = 0.0;
    for (Eigen::Index k = 0; k < m; ++k) {
      x += b[k] * coefficients(k, 0);
      y += b[k] * coefficients(k, 1);
      z += b[k] * coefficients(k, 2);
    }
    const int v = free_vertices[row];
    positions(v, 0) = x;
    positions(v, 1) = y;
    positions(v, 2) = z;
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
      }
      plan.ring.push_back(s);
    }
    plan.ring_begin.push_back(static_cast<int>(plan.ring.size()));
  }
  return plan;
}

void update_normals(const TriangleTopology& topology, const RowPoints& positions,
                    const NormalPlan& plan, RowPoints& normals, std::vector<double>& scratch,
                    int threads) {
  scratch.resize(3 * plan.faces.size());
  parallel_for(plan.faces.size(), threads, [&](std::size_t i) {
    const auto& f = topology.faces[static_cast<std::size_t>(plan.faces[i])];
    const Eigen::Vector3d p0 = positions.row(f[0]);
    const Eigen::Vector3d p1 = positions.row(f[1]);
    const Eigen::Vector3d p2 = positions.row(f[2]);
    const Eigen::Vector3d n = (p1 - p0).cross(p2 - p0);
    scratch[3 * i] = n[0];
    scratch[3 * i + 1] = n[1];
    scratch[3 * i + 2] = n[2];
  });
  parallel_for(plan.vertices.size(), threads, [&](std::size_t i) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int k = plan.ring_begin[i]; k < plan.ring_begin[i + 1]; ++k) {
      const auto s = 3 * static_cast<std::size_t>(plan.ring[static_cast<std::size_t>(k)]);
      sum += Eigen::Vector3d(scratch[s], scratch[s + 1], scratch[s + 2]);
    }
    const double len = sum.norm();
    normals.row(plan.vertices[i]) =
        len > 0.0 ? Eigen::RowVector3d((sum / len).transpose()) : Eigen::RowVector3d::Zero();
  });
}

} // namespace remora
