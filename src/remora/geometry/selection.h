// Vertex selections on a mesh: what a user paints as a support or a handle, given as a sphere, a
// box or a geodesic disc. Each returns vertex indices (idx()) in increasing order, except
// geodesic_order(), which returns them by distance. Deleted vertices are never selected.
#pragma once

#include <cstddef>
#include <limits>
#include <vector>

#include "remora/mesh/mesh.h"

namespace remora {

/// The vertices within `radius` of `center` (inclusive). Throws InvalidArgument for a non-finite
/// center or a negative or non-finite radius.
std::vector<int> select_sphere(const Mesh& mesh, const Vec3& center, double radius);

/// The vertices inside the axis-aligned box [min, max] (inclusive). Throws InvalidArgument for
/// non-finite corners or min > max in some coordinate.
std::vector<int> select_box(const Mesh& mesh, const Vec3& min, const Vec3& max);

/// Vertices by increasing edge-path distance from `seed` (Dijkstra over the edges, lengths in 3D;
/// an upper bound of the geodesic distance that is within a few per cent of it on isotropic
/// meshes), at most `max_count` of them and none farther than `max_distance`. Only the seed's
/// connected component is reached. Throws InvalidArgument for an invalid or deleted seed.
std::vector<int> geodesic_order(const Mesh& mesh, VertexHandle seed,
                                std::size_t max_count = std::numeric_limits<std::size_t>::max(),
                                double max_distance = std::numeric_limits<double>::infinity());

/// The vertex nearest to `point` (the first of equals by index). Throws InvalidArgument for a
/// mesh without vertices or a non-finite point.
VertexHandle nearest_vertex(const Mesh& mesh, const Vec3& point);

/// The vertex nearest to the mean of all vertices: the benchmarks' seed for geodesic supports.
VertexHandle central_vertex(const Mesh& mesh);

/// The vertices within geodesic distance `radius` of `seed` (fast marching through the triangles,
/// geometry/geodesic.h: round on a regular grid, where edge paths give a diamond), sorted by
/// index. Throws InvalidArgument for an invalid seed or a negative or non-finite radius.
std::vector<int> select_geodesic_disc(const Mesh& mesh, VertexHandle seed, double radius);

} // namespace remora
