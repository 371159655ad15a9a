// Checks and small helpers shared by the test files (one definition each, so that test files
// compiled together in a unity group do not define a name twice).
#pragma once

#include <cstdint>
#include <numbers>
#include <random>
#include <sstream>
#include <vector>

#include <Eigen/Core>

#include <OpenMesh/Tools/Utils/MeshCheckerT.hh>
#include <gtest/gtest.h>

#include "remora/mesh/mesh.h"

namespace remora::testing {

inline constexpr double kPi = std::numbers::pi;

/// Uniform in [-1, 1).
inline double symmetric_unit(std::mt19937& rng) {
  return 2.0 * static_cast<double>(rng()) / 4294967296.0 - 1.0;
}

/// Each coordinate uniform in [-scale, scale).
inline Vec3 random_vector(std::mt19937& rng, double scale) {
  return Vec3(symmetric_unit(rng), symmetric_unit(rng), symmetric_unit(rng)) * scale;
}

/// Uniform in [0, 1).
inline double unit(std::mt19937& rng) {
  return static_cast<double>(rng()) / 4294967296.0;
}

/// A random direction times a length uniform in [0, max_length).
inline Vec3 random_offset(std::mt19937& rng, double max_length) {
  Vec3 d;
  do {
    d = random_vector(rng, 1.0);
  } while (d.sqrnorm() > 1.0 || d.sqrnorm() < 1e-6);
  return d.normalized() * (max_length * unit(rng));
}

/// The largest distance between corresponding rows of two n×3 matrices.
/// Adds `other`'s vertices (moved by `offset`) and faces to `mesh`: a second component.
inline void append_component(Mesh& mesh, const Mesh& other, const Vec3& offset) {
  std::vector<VertexHandle> added;
  for (const VertexHandle v : other.vertices())
    added.push_back(mesh.add_vertex(other.point(v) + offset));
  for (const FaceHandle f : other.faces()) {
    std::vector<VertexHandle> corners;
    for (const VertexHandle v : other.fv_range(f))
      corners.push_back(added[static_cast<std::size_t>(v.idx())]);
    mesh.add_face(corners);
  }
}

inline double max_row_distance(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).rowwise().norm().maxCoeff();
}

/// Signed volume enclosed by the faces (positive for a closed surface facing outward).
inline double signed_volume(const Mesh& m) {
  double v = 0;
  for (auto f : m.faces()) {
    auto h = m.halfedge_handle(f);
    const Vec3& a = m.point(m.from_vertex_handle(h));
    const Vec3& b = m.point(m.to_vertex_handle(h));
    const Vec3& c = m.point(m.to_vertex_handle(m.next_halfedge_handle(h)));
    v += OpenMesh::dot(a, OpenMesh::cross(b, c)) / 6.0;
  }
  return v;
}

/// OpenMesh's full consistency check of the half-edge structure, and every vertex manifold.
inline void expect_valid_halfedge_mesh(const Mesh& mesh) {
  std::ostringstream problems;
  EXPECT_TRUE(OpenMesh::Utils::MeshCheckerT<Mesh>(mesh).check(
      OpenMesh::Utils::MeshCheckerT<Mesh>::CHECK_ALL, problems))
      << problems.str();
  for (auto v : mesh.vertices()) EXPECT_TRUE(mesh.is_manifold(v)) << "vertex " << v.idx();
}

} // namespace remora::testing
