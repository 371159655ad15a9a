// Helpers shared by the remesher's tests (tests/test_remesh*.cpp).
#pragma once

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "remora/geometry/closest_point.h"
#include "remora/geometry/measures.h"
#include "remora/mesh/primitives.h"
#include "remora/remesh/remesh.h"

namespace remora::remesh_testing {

// Fraction of edges with length in [4/5, 4/3] l.
inline double fraction_in_band(const Mesh& m, double l) {
  std::size_t in = 0, all = 0;
  for (auto e : m.edges()) {
    const double len = m.calc_edge_length(e);
    in += (len >= 0.8 * l - 1e-12 && len <= 4.0 / 3.0 * l + 1e-12) ? 1 : 0;
    ++all;
  }
  return static_cast<double>(in) / static_cast<double>(all);
}

inline Vec3 face_normal(const Mesh& m, FaceHandle f) {
  const auto v = face_vertices(m, f);
  return OpenMesh::cross(m.point(v[1]) - m.point(v[0]), m.point(v[2]) - m.point(v[0]));
}

// Brute-force distance from p to the surface of m.
inline double distance_to(const Mesh& m, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (auto f : m.faces()) {
    const auto v = face_vertices(m, f);
    best = std::min(
        best, closest_point_on_triangle(p, m.point(v[0]), m.point(v[1]), m.point(v[2])).distance2);
  }
  return std::sqrt(best);
}

// A flat grid whose columns are squeezed towards x = 0: needles everywhere on the left.
inline Mesh needle_grid() {
  Mesh m = make_grid(40, 20, 4.0, 2.0);
  for (auto v : m.vertices()) {
    Vec3 p = m.point(v);
    p[0] = 4.0 * std::pow(p[0] / 4.0, 3.0);
    m.set_point(v, p);
  }
  return m;
}

inline void expect_sound_output(const RemeshResult& r, const Mesh& input) {
  const Mesh& m = r.mesh;
  ASSERT_GT(m.n_faces(), 0u);
  for (auto v : m.vertices()) {
    const Vec3 p = m.point(v);
    ASSERT_TRUE(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]));
    EXPECT_TRUE(m.is_manifold(v));
  }
  const double diag = bounding_box_diagonal(input);
  for (auto f : m.faces())
    EXPECT_GT(face_area(m, f), 1e-10 * diag * diag) << "degenerate output face " << f.idx();
  ASSERT_EQ(r.output_on_input.size(), m.n_vertices());
  ASSERT_EQ(r.input_on_output.size(), input.n_vertices());
  // Each location evaluates to its point.
  for (auto v : m.vertices())
    EXPECT_LT((evaluate(input, r.output_on_input[v.idx()]) - m.point(v)).norm(), 1e-9 * diag);
  for (auto v : input.vertices()) {
    const SurfacePoint& sp = r.input_on_output[v.idx()];
    ASSERT_TRUE(sp.face.is_valid());
    double sum = 0;
    for (double b : sp.bary) {
      EXPECT_GE(b, -1e-12);
      sum += b;
    }
    EXPECT_NEAR(sum, 1.0, 1e-12);
  }
}

} // namespace remora::remesh_testing
