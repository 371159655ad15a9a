// Procedural meshes for tests, demos and benchmarks. Deterministic: the same arguments give the
// same mesh, bit for bit. Flat meshes lie in the plane z = 0 with every face counter-clockwise seen
// from +z (normals +z); closed meshes are oriented outward (normals away from the inside).
// Throws InvalidArgument for counts below the stated minimum, lengths that are not finite and
// positive, and meshes too large for OpenMesh's int handles (more than 2^28 faces or vertices).
#pragma once

#include "remora/mesh/mesh.h"

namespace remora {

/// How make_grid splits each quad into two triangles.
enum class GridSplit {
  /// Every quad along its diagonal from (x_i, y_j) to (x_i+1, y_j+1): interior valence 6.
  Uniform,
  /// Checkerboard: that diagonal when i + j is even, the other one when odd; no directional bias,
  /// interior valences 8 (i + j even) and 4 (odd).
  Alternating,
};

/// [0, width] x [0, height] in z = 0, split into nx x ny equal quads, each into two triangles.
/// Vertex (i, j), 0 <= i <= nx, 0 <= j <= ny, is at (width i / nx, height j / ny, 0) and has index
/// j (nx + 1) + i. V = (nx + 1)(ny + 1), F = 2 nx ny. nx, ny >= 1.
Mesh make_grid(int nx, int ny, double width, double height,
               GridSplit split = GridSplit::Alternating);

/// A flat lattice of equilateral triangles with edge length `edge`: ny + 1 rows of nx + 1
/// vertices, row j at y = j edge sqrt(3)/2, vertex (i, j) at x = (i + (j odd ? 1/2 : 0)) edge,
/// index j (nx + 1) + i. Every angle is 60 degrees; the (nx - 1)(ny - 1) vertices with
/// 0 < i < nx and 0 < j < ny are interior, all of valence 6. V = (nx + 1)(ny + 1), F = 2 nx ny.
/// nx, ny >= 1.
Mesh make_equilateral_grid(int nx, int ny, double edge);

/// A flat disc of radius `radius` centred at the origin: a centre vertex (index 0) and `rings`
/// concentric rings; ring k = 1..rings has radius k radius / rings and k segments vertices at
/// angles 2 pi m / (k segments), so the density is uniform (segments = 6 gives near-equilateral
/// triangles, all interior valences 6). Neighbouring rings are stitched by angle.
/// V = 1 + segments rings (rings + 1) / 2, F = segments rings^2, one boundary loop (the outer
/// ring). rings >= 1, segments >= 3.
Mesh make_disc(int rings, int segments, double radius);

/// A flat annulus centred at the origin: rings + 1 circles of `segments` vertices each, radii
/// evenly spaced from inner_radius to outer_radius, vertex (k, s) at angle 2 pi s / segments
/// with index k segments + s; each quad split into two triangles. V = (rings + 1) segments,
/// F = 2 rings segments, two boundary loops, Euler characteristic 0.
/// rings >= 1, segments >= 3, 0 < inner_radius < outer_radius.
Mesh make_annulus(int rings, int segments, double inner_radius, double outer_radius);

/// An icosahedron inscribed in the sphere of `radius` about the origin, refined `subdivisions`
/// times 1:4 with every new edge midpoint projected onto the sphere. Every vertex lies on the
/// sphere. V = 10 4^s + 2, F = 20 4^s; 12 vertices of valence 5, the others 6. 0 <= s <= 12.
Mesh make_icosphere(int subdivisions, double radius = 1.0);

/// The surface of the cube [-size/2, size/2]^3, each side split into n x n squares and each square
/// into two right isosceles triangles (angles 45, 45, 90 degrees); vertices along the cube's edges
/// and corners are shared. V = 6 n^2 + 2, F = 12 n^2, closed, genus 0. n >= 1.
Mesh make_cube(int n, double size);

/// A torus about the z axis: the tube's centre circle has radius `major_radius` in z = 0, the tube
/// has radius `minor_radius`. Vertex (i, j), 0 <= i < around, 0 <= j < tube, index i tube + j, is
/// at angle u = 2 pi i / around about z and v = 2 pi j / tube about the tube's centre, at
/// ((R + r cos v) cos u, (R + r cos v) sin u, r sin v); each quad is split into two triangles.
/// V = around tube, F = 2 around tube, closed, genus 1, oriented outward (away from the tube's
/// centre). around, tube >= 3, 0 < minor_radius < major_radius.
Mesh make_torus(int around, int tube, double major_radius, double minor_radius);

/// An open cylinder about the z axis from z = 0 to z = height: rings + 1 circles of `segments`
/// vertices; circle k lies at z = k height / rings, and its vertex s at the angle
/// 2 pi (s + (k odd ? 1/2 : 0)) / segments, index k segments + s. Neighbouring circles are joined
/// by a strip of 2 segments triangles (a triangular lattice: with height / rings = sqrt(3)/2 times
/// the chord 2 pi radius / segments every triangle is near equilateral). V = (rings + 1)
/// segments, F = 2 rings segments, two boundary loops (the circles k = 0 and k = rings), oriented
/// outward. rings >= 1, segments >= 3.
Mesh make_cylinder(int rings, int segments, double radius, double height);

} // namespace remora
