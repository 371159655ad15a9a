#include "remora/mesh/primitives.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "remora/common/error.h"

namespace remora {
namespace {

using Triangle = std::array<int, 3>;

constexpr std::int64_t kMaxElements = std::int64_t{1} << 28;

void require_count(const char* function, const char* name, int value, int minimum) {
  if (value < minimum) {
    throw InvalidArgument(std::string(function) + ": " + name + " = " + std::to_string(value) +
                          " is below the minimum " + std::to_string(minimum));
  }
}

void require_length(const char* function, const char* name, double value) {
  if (!std::isfinite(value) || !(value > 0.0)) {
    throw InvalidArgument(std::string(function) + ": " + name + " = " + std::to_string(value) +
                          " must be finite and positive");
  }
}

void require_size(const char* function, std::int64_t vertices, std::int64_t faces) {
  if (vertices > kMaxElements || faces > kMaxElements) {
    throw InvalidArgument(std::string(function) + ": " + std::to_string(vertices) +
                          " vertices and " + std::to_string(faces) +
                          " faces exceed the limit of 2^28; use smaller counts");
  }
}

Mesh build(const std::vector<Vec3>& points, const std::vector<Triangle>& triangles) {
  Mesh mesh;
  mesh.reserve(points.size(), points.size() + triangles.size(), triangles.size());
  for (const Vec3& p : points) mesh.add_vertex(p);
  for (const Triangle& t : triangles) {
    const FaceHandle f = mesh.add_face(VertexHandle(t[0]), VertexHandle(t[1]), VertexHandle(t[2]));
    if (!f.is_valid()) {
      throw Error("primitives: internal error: triangle (" + std::to_string(t[0]) + ", " +
                  std::to_string(t[1]) + ", " + std::to_string(t[2]) + ") is not manifold");
    }
  }
  return mesh;
}

Vec3 on_circle(double radius, double angle) {
  return {radius * std::cos(angle), radius * std::sin(angle), 0.0};
}

} // namespace

Mesh make_grid(int nx, int ny, double width, double height, GridSplit split) {
  require_count("make_grid", "nx", nx, 1);
  require_count("make_grid", "ny", ny, 1);
  require_length("make_grid", "width", width);
  require_length("make_grid", "height", height);
  require_size("make_grid", std::int64_t{nx + 1} * (ny + 1), std::int64_t{2} * nx * ny);

  std::vector<Vec3> points;
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) points.emplace_back(width * i / nx, height * j / ny, 0.0);
  }
  const auto index = [nx](int i, int j) { return j * (nx + 1) + i; };
  std::vector<Triangle> triangles;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const int v00 = index(i, j);
      const int v10 = index(i + 1, j);
      const int v11 = index(i + 1, j + 1);
      const int v01 = index(i, j + 1);
      if (split == GridSplit::Uniform || (i + j) % 2 == 0) {
        triangles.push_back({v00, v10, v11});
        triangles.push_back({v00, v11, v01});
      } else {
        triangles.push_back({v00, v10, v01});
        triangles.push_back({v10, v11, v01});
      }
    }
  }
  return build(points, triangles);
}

Mesh make_equilateral_grid(int nx, int ny, double edge) {
  require_count("make_equilateral_grid", "nx", nx, 1);
  require_count("make_equilateral_grid", "ny", ny, 1);
  require_length("make_equilateral_grid", "edge", edge);
  require_size("make_equilateral_grid", std::int64_t{nx + 1} * (ny + 1), std::int64_t{2} * nx * ny);

  const double row_height = edge * std::sqrt(3.0) / 2.0;
  std::vector<Vec3> points;
  for (int j = 0; j <= ny; ++j) {
    const double shift = j % 2 == 0 ? 0.0 : 0.5;
    for (int i = 0; i <= nx; ++i) points.emplace_back((i + shift) * edge, j * row_height, 0.0);
  }
  const auto index = [nx](int i, int j) { return j * (nx + 1) + i; };
  std::vector<Triangle> triangles;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const int b0 = index(i, j);
      const int b1 = index(i + 1, j);
      const int t0 = index(i, j + 1);
      const int t1 = index(i + 1, j + 1);
      if (j % 2 == 0) { // the upper row is shifted right by half an edge
        triangles.push_back({b0, b1, t0});
        triangles.push_back({b1, t1, t0});
      } else { // the lower row is shifted
        triangles.push_back({b0, t1, t0});
        triangles.push_back({b0, b1, t1});
      }
    }
  }
  return build(points, triangles);
}

Mesh make_disc(int rings, int segments, double radius) {
  require_count("make_disc", "rings", rings, 1);
  require_count("make_disc", "segments", segments, 3);
  require_length("make_disc", "radius", radius);
  const std::int64_t vertices = 1 + std::int64_t{segments} * rings * (rings + 1) / 2;
  require_size("make_disc", vertices, std::int64_t{segments} * rings * rings);

  // first[k]: index of ring k's first vertex; ring k has count(k) vertices.
  const auto count = [segments](int k) { return k == 0 ? 1 : k * segments; };
  std::vector<int> first(static_cast<std::size_t>(rings) + 1, 0);
  std::vector<Vec3> points{Vec3(0.0, 0.0, 0.0)};
  for (int k = 1; k <= rings; ++k) {
    first[static_cast<std::size_t>(k)] = static_cast<int>(points.size());
    const double r = radius * k / rings;
    for (int m = 0; m < count(k); ++m) {
      points.push_back(on_circle(r, 2.0 * std::numbers::pi * m / count(k)));
    }
  }
  std::vector<Triangle> triangles;
  for (int m = 0; m < segments; ++m) triangles.push_back({0, 1 + m, 1 + (m + 1) % segments});
  for (int k = 1; k < rings; ++k) {
    // Stitch ring k (n_in vertices) to ring k + 1 (n_out) by walking both in angle order: advance
    // on the ring whose next vertex comes first, comparing the angles (o + 1) / n_out and
    // (i + 1) / n_in exactly in integers. Every step emits one triangle.
    const int n_in = count(k);
    const int n_out = count(k + 1);
    const auto inner = [&](int i) { return first[static_cast<std::size_t>(k)] + i % n_in; };
    const auto outer = [&](int o) { return first[static_cast<std::size_t>(k) + 1] + o % n_out; };
    int i = 0;
    int o = 0;
    while (i < n_in || o < n_out) {
      const bool advance_outer =
          i == n_in || (o < n_out && std::int64_t{o + 1} * n_in <= std::int64_t{i + 1} * n_out);
      if (advance_outer) {
        triangles.push_back({inner(i), outer(o), outer(o + 1)});
        ++o;
      } else {
        triangles.push_back({inner(i), outer(o), inner(i + 1)});
        ++i;
      }
    }
  }
  return build(points, triangles);
}

Mesh make_annulus(int rings, int segments, double inner_radius, double outer_radius) {
  require_count("make_annulus", "rings", rings, 1);
  require_count("make_annulus", "segments", segments, 3);
  require_length("make_annulus", "inner_radius", inner_radius);
  require_length("make_annulus", "outer_radius", outer_radius);
  if (!(inner_radius < outer_radius)) {
    throw InvalidArgument("make_annulus: inner_radius = " + std::to_string(inner_radius) +
                          " must be below outer_radius = " + std::to_string(outer_radius));
  }
  require_size("make_annulus", std::int64_t{rings + 1} * segments,
               std::int64_t{2} * rings * segments);

  std::vector<Vec3> points;
  for (int k = 0; k <= rings; ++k) {
    const double r = inner_radius + (outer_radius - inner_radius) * k / rings;
    for (int s = 0; s < segments; ++s) {
      points.push_back(on_circle(r, 2.0 * std::numbers::pi * s / segments));
    }
  }
  const auto index = [segments](int k, int s) { return k * segments + s % segments; };
  std::vector<Triangle> triangles;
  for (int k = 0; k < rings; ++k) {
    for (int s = 0; s < segments; ++s) {
      const int a = index(k, s);         // inner, this angle
      const int b = index(k, s + 1);     // inner, next angle
      const int c = index(k + 1, s + 1); // outer, next angle
      const int d = index(k + 1, s);     // outer, this angle
      triangles.push_back({a, d, c});
      triangles.push_back({a, c, b});
    }
  }
  return build(points, triangles);
}

Mesh make_icosphere(int subdivisions, double radius) {
  require_count("make_icosphere", "subdivisions", subdivisions, 0);
  if (subdivisions > 12) {
    throw InvalidArgument("make_icosphere: subdivisions = " + std::to_string(subdivisions) +
                          " exceeds the maximum 12 (20 4^12 faces)");
  }
  require_length("make_icosphere", "radius", radius);

  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> points{{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                           {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                           {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (Vec3& p : points) p /= p.norm();
  std::vector<Triangle> triangles{{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                  {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                  {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                  {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> midpoints;
    const auto midpoint = [&](int a, int b) {
      const std::pair<int, int> key = a < b ? std::pair(a, b) : std::pair(b, a);
      const auto [it, inserted] = midpoints.try_emplace(key, static_cast<int>(points.size()));
      if (inserted) {
        const Vec3 m = points[static_cast<std::size_t>(a)] + points[static_cast<std::size_t>(b)];
        points.push_back(m / m.norm());
      }
      return it->second;
    };
    std::vector<Triangle> refined;
    refined.reserve(4 * triangles.size());
    for (const Triangle& tri : triangles) {
      const int ab = midpoint(tri[0], tri[1]);
      const int bc = midpoint(tri[1], tri[2]);
      const int ca = midpoint(tri[2], tri[0]);
      refined.push_back({tri[0], ab, ca});
      refined.push_back({tri[1], bc, ab});
      refined.push_back({tri[2], ca, bc});
      refined.push_back({ab, bc, ca});
    }
    triangles = std::move(refined);
  }
  for (Vec3& p : points) p *= radius;
  return build(points, triangles);
}

Mesh make_cube(int n, double size) {
  require_count("make_cube", "n", n, 1);
  require_length("make_cube", "size", size);
  require_size("make_cube", std::int64_t{6} * n * n + 2, std::int64_t{12} * n * n);

  // Each side: the fixed axis and its lattice value, and the in-plane axes (u, v) with
  // u x v = the outward normal, so that counter-clockwise in (u, v) is outward.
  struct Side {
    int axis;
    int value;
    int u;
    int v;
  };
  const std::array<Side, 6> sides{
      {{0, n, 1, 2}, {0, 0, 2, 1}, {1, n, 2, 0}, {1, 0, 0, 2}, {2, n, 0, 1}, {2, 0, 1, 0}}};
  std::vector<Vec3> points;
  std::map<std::array<int, 3>, int> lattice_index;
  const auto vertex = [&](const std::array<int, 3>& lattice) {
    const auto [it, inserted] = lattice_index.try_emplace(lattice, static_cast<int>(points.size()));
    if (inserted) {
      Vec3 p(0.0, 0.0, 0.0);
      for (int d = 0; d < 3; ++d) p[d] = size * (static_cast<double>(lattice[d]) / n - 0.5);
      points.push_back(p);
    }
    return it->second;
  };
  std::vector<Triangle> triangles;
  for (const Side& side : sides) {
    const auto at = [&](int a, int b) {
      std::array<int, 3> lattice{};
      lattice[static_cast<std::size_t>(side.axis)] = side.value;
      lattice[static_cast<std::size_t>(side.u)] = a;
      lattice[static_cast<std::size_t>(side.v)] = b;
      return vertex(lattice);
    };
    for (int b = 0; b < n; ++b) {
      for (int a = 0; a < n; ++a) {
        const int v00 = at(a, b);
        const int v10 = at(a + 1, b);
        const int v11 = at(a + 1, b + 1);
        const int v01 = at(a, b + 1);
        triangles.push_back({v00, v10, v11});
        triangles.push_back({v00, v11, v01});
      }
    }
  }
  return build(points, triangles);
}

Mesh make_torus(int around, int tube, double major_radius, double minor_radius) {
  require_count("make_torus", "around", around, 3);
  require_count("make_torus", "tube", tube, 3);
  require_length("make_torus", "major_radius", major_radius);
  require_length("make_torus", "minor_radius", minor_radius);
  if (!(minor_radius < major_radius)) {
    throw InvalidArgument("make_torus: minor_radius = " + std::to_string(minor_radius) +
                          " must be below major_radius = " + std::to_string(major_radius));
  }
  require_size("make_torus", std::int64_t{around} * tube, std::int64_t{2} * around * tube);

  std::vector<Vec3> points;
  for (int i = 0; i < around; ++i) {
    const double u = 2.0 * std::numbers::pi * i / around;
    for (int j = 0; j < tube; ++j) {
      const double v = 2.0 * std::numbers::pi * j / tube;
      const double rho = major_radius + minor_radius * std::cos(v);
      points.emplace_back(rho * std::cos(u), rho * std::sin(u), minor_radius * std::sin(v));
    }
  }
  const auto index = [around, tube](int i, int j) { return (i % around) * tube + j % tube; };
  std::vector<Triangle> triangles;
  for (int i = 0; i < around; ++i) {
    for (int j = 0; j < tube; ++j) {
      // Increasing u then v turns counter-clockwise seen from outside the tube.
      const int a = index(i, j), b = index(i + 1, j), c = index(i + 1, j + 1), d = index(i, j + 1);
      triangles.push_back({a, b, c});
      triangles.push_back({a, c, d});
    }
  }
  return build(points, triangles);
}

Mesh make_cylinder(int rings, int segments, double radius, double height) {
  require_count("make_cylinder", "rings", rings, 1);
  require_count("make_cylinder", "segments", segments, 3);
  require_length("make_cylinder", "radius", radius);
  require_length("make_cylinder", "height", height);
  require_size("make_cylinder", std::int64_t{rings + 1} * segments,
               std::int64_t{2} * rings * segments);
  std::vector<Vec3> points;
  for (int k = 0; k <= rings; ++k) {
    const double z = height * k / rings;
    for (int s = 0; s < segments; ++s) {
      const double phi = 2.0 * std::numbers::pi * (s + (k % 2 ? 0.5 : 0.0)) / segments;
      points.emplace_back(radius * std::cos(phi), radius * std::sin(phi), z);
    }
  }
  const auto index = [segments](int k, int s) { return k * segments + s % segments; };
  std::vector<Triangle> triangles;
  for (int k = 0; k < rings; ++k) {
    for (int s = 0; s < segments; ++s) {
      // Angles increase counter-clockwise seen from +z: (later on the circle, above) turns
      // outward.
      if (k % 2 == 0) {
        triangles.push_back({index(k, s), index(k, s + 1), index(k + 1, s)});
        triangles.push_back({index(k, s + 1), index(k + 1, s + 1), index(k + 1, s)});
      } else {
        triangles.push_back({index(k, s), index(k + 1, s + 1), index(k + 1, s)});
        triangles.push_back({index(k, s), index(k, s + 1), index(k + 1, s + 1)});
      }
    }
  }
  return build(points, triangles);
}

} // namespace remora
