// Checks shared by the test files.
#pragma once

#include <sstream>

#include <OpenMesh/Tools/Utils/MeshCheckerT.hh>
#include <gtest/gtest.h>

#include "remora/mesh/mesh.h"

namespace remora::testing {

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
