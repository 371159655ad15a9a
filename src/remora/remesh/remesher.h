// The remesher's working state, shared by its steps; internal to src/remora/remesh/.
//
// remesh() (remesh.cpp) copies the input into a Remesher and runs the paper's recipe (§4) on it,
// one file a step:
//   split.cpp             split edges longer than 4/3 l, the longest first
//   collapse.cpp          collapse edges shorter than 4/5 l, and the rules every collapse obeys
//   flip.cpp              valence flips (6 inside, 4 on the boundary); the fine-tuning's Delaunay
//                         flips
//   smooth.cpp            tangential smoothing, and the data-parallel vertex moves of every step
//   equalize.cpp          the area-equalizing fine-tuning (the paper's gravity update, or Newton)
//   curves.cpp            boundary and feature lines, their corners, the boundary spacing
//   repair_triangles.cpp  flips, collapses and moves that remove triangles below an angle
//   correspondence.cpp    the mutual parameterization: output -> input (every vertex's location
//                         on the input, projection by walks) and input -> output (tracked points)
//   order.cpp             compaction and spatial (Z-order) renumbering of the working mesh
//   report.cpp            the report's figures and its JSON form
// Every function here works on the working mesh `rm.mesh`; none throws except where it says so.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string_view>
#include <vector>

#include "remora/mesh/mesh.h"
#include "remora/mesh/surface_point.h"
#include "remora/remesh/remesh.h"

namespace remora::remesh_detail {

/// Above this many faces a mesh no longer stays in cache: the input and the working mesh are
/// renumbered spatially (order.cpp).
constexpr std::size_t kSpatialOrderFaces = 32768;

/// What an output vertex is allowed to do.
enum class Kind : std::uint8_t {
  Interior, ///< moves tangentially, projected onto the input surface
  Curve,    ///< slides along an input curve: the boundary or a feature line
  Corner,   ///< never moves (a sharp turn of a curve, or where feature lines meet or end)
};

/// Per output vertex: where it lies on the input, and for a curve vertex the input curve
/// halfedge it lies on (the start of its walks along the curve).
struct VertexState {
  SurfacePoint loc;
  HalfedgeHandle curve_loc;
  int origin = -1; ///< a patch's locked vertex: its index in the patch given (patch.cpp)
  Kind kind = Kind::Interior;
};

/// Per output face: the first input vertex located on it, the head of a list through
/// Remesher::next (correspondence.cpp).
struct PointList {
  int head = -1;
};

/// The working mesh with its per-element state (OpenMesh properties, so that split, collapse,
/// flip and garbage collection carry them), the input's curves, the tracked input vertices and
/// the lengths derived from the target length l. The constructor adds the properties,
/// adopt_renumbered() carries them into a renumbered copy and take_mesh() removes them: nowhere
/// else are they added or removed.
class Remesher {
public:
  /// Copies `input`; l from options (target_length, or length_factor × length_scale()).
  /// Throws InvalidArgument when l is not positive and finite.
  Remesher(const Mesh& input, const RemeshOptions& options);
  /// A patch (patch.cpp): `working` is the starting working mesh, `input` the surface its
  /// vertices lie on; the locations and kinds are the caller's to set.
  Remesher(const Mesh& input, const Mesh& working, const RemeshOptions& options);

  /// Replaces the working mesh by `renumbered`, a copy made by copy_in_order() (order.cpp), and
  /// carries every element's state along `order` (new index -> old index).
  void adopt_renumbered(Mesh&& renumbered, const struct MeshOrder& order);
  /// Hands the working mesh, without the working properties, to `out`; the Remesher is spent.
  /// OpenMesh's meshes have no move: every assignment copies, so there is one here and one in
  /// adopt_renumbered, and none elsewhere. The passes' buffers are their own locals: kept here
  /// between calls, they raised the peak resident memory of a million-triangle remesh.
  void take_mesh(Mesh& out);

  const Mesh& input;
  const RemeshOptions& options;
  Mesh mesh;

  SurfacePoint& loc(VertexHandle v) { return mesh.property(vertex_state_, v).loc; }
  const SurfacePoint& loc(VertexHandle v) const { return mesh.property(vertex_state_, v).loc; }
  HalfedgeHandle& curve_loc(VertexHandle v) { return mesh.property(vertex_state_, v).curve_loc; }
  HalfedgeHandle curve_loc(VertexHandle v) const {
    return mesh.property(vertex_state_, v).curve_loc;
  }
  Kind& kind(VertexHandle v) { return mesh.property(vertex_state_, v).kind; }
  Kind kind(VertexHandle v) const { return mesh.property(vertex_state_, v).kind; }
  int& origin(VertexHandle v) { return mesh.property(vertex_state_, v).origin; }
  int origin(VertexHandle v) const { return mesh.property(vertex_state_, v).origin; }
  /// Does the edge lie on a feature line of the input?
  char& feature(EdgeHandle e) { return mesh.property(feature_, e); }
  char feature(EdgeHandle e) const { return mesh.property(feature_, e); }
  PointList& points(FaceHandle f) { return mesh.property(points_, f); }
  /// Edges that flips leave alone and collapses keep on their curve.
  bool on_curve(EdgeHandle e) const { return mesh.is_boundary(e) || feature(e); }

  void progress(std::string_view phase, int step, int steps) const {
    if (options.progress) options.progress(phase, step, steps);
  }

  // Lengths: l, (4/5 l)², 4/3 l, (4/3 l)²; |cross| of a face at or below flat_cross is flat.
  double length = 0, lo2 = 0, hi = 0, hi2 = 0, flat_cross = 0;
  bool length_from_area = false;       ///< l came from the area per vertex (a needle-ridden input)
  double guard_rad = 0, cos_guard = 1; ///< equalize_guard_deg in radians, and its cosine
  std::size_t max_faces = 0;           ///< splitting stops here: bounded work
  std::size_t live_faces = 0;          ///< faces not deleted (compacted only between phases)

  // The input's curves (curves.cpp).
  std::vector<char> input_curve; ///< per input edge: on the boundary or a feature line
  std::size_t feature_count = 0; ///< feature edges of the input
  bool has_boundary = false;

  // Input -> output (correspondence.cpp): per input vertex its location on the working mesh
  // and its neighbours in its face's list.
  std::vector<SurfacePoint> track;
  std::vector<int> next, prev;

  // The fine-tuning (equalize.cpp).
  std::vector<Vec3> previous_points; ///< positions at the start of the last iteration (momentum)
  std::size_t guarded = 0;           ///< moves the guard halved or dropped

  // A patch (patch.cpp): its boundary stays as it is (no boundary edge is split); its locked
  // vertices' mixed area and valence outside the patch, by origin(); the mean area the
  // fine-tuning aims at (0: the mean of the interior vertices' areas).
  bool locked_boundary = false;
  std::vector<double> outside_area;
  std::vector<int> valence_target;
  double target_area = 0;

private:
  void add_properties();
  void set_lengths();
  OpenMesh::VPropHandleT<VertexState> vertex_state_;
  OpenMesh::EPropHandleT<char> feature_;
  OpenMesh::FPropHandleT<PointList> points_;
};

// --- remesh.cpp --------------------------------------------------------------------------------

/// Throws InvalidArgument for an empty input or an option outside its range (remesh.h).
void check_options(const Mesh& input, const RemeshOptions& options);
/// §4 on a set-up Remesher (curves, kinds, locations and tracked points in place): the cycles,
/// the repair, the fine-tuning and the final compaction, with the report's figures when asked.
void run_steps(Remesher& rm, RemeshReport& report);
/// The correspondence at the end: every output vertex's location on the input, and every
/// tracked input vertex's closest point on the output.
void finish_correspondence(Remesher& rm, std::vector<SurfacePoint>& output_on_input,
                           std::vector<SurfacePoint>& input_on_output, RemeshReport& report);

// --- curves.cpp: boundary and feature lines, corners, boundary spacing -------------------------

/// The input's curves: its boundary edges and, with feature_angle_deg, its feature lines (those
/// shorter than l dropped); marks the working mesh's feature edges and counts them.
void find_curves(Remesher& rm);
/// Marks the corners: sharp turns of each curve at the scale of l, and where lines end or meet.
void mark_corners(Remesher& rm);
/// The boundary halfedge leaving v (invalid for an interior vertex).
HalfedgeHandle boundary_out(const Mesh& mesh, VertexHandle v);
/// The input curve halfedge leaving corner c's input vertex whose segment is closest to p.
HalfedgeHandle curve_start(const Remesher& rm, VertexHandle c, const Vec3& p);
/// Would the triangle (v, c, d) hold both of v's feature edges, v a vertex inside a line?
bool spans_line(const Remesher& rm, VertexHandle v, VertexHandle c, VertexHandle d);
/// Collapses boundary vertices spaced closer than boundary_spacing × l and spaces the rest
/// evenly between corners; returns the number of collapses.
std::size_t resample_boundary(Remesher& rm);

// --- split.cpp ---------------------------------------------------------------------------------

/// §4 step 1: splits every edge longer than 4/3 l at its midpoint; returns the number of splits.
std::size_t split_long_edges(Remesher& rm);

// --- collapse.cpp ------------------------------------------------------------------------------

/// Why an edge is collapsed; repairs may leave longer edges than the cycles' collapses.
/// Flat: a sliver between two curves, which may merge two of their vertices. Degenerate: a
/// zero-area face, which may leave edges up to 8/3 l.
enum class Collapse { Short, Repair, Boundary, Flat, Degenerate };
/// §4 step 2: collapses every edge shorter than 4/5 l that the rules allow; returns the count.
std::size_t collapse_short_edges(Remesher& rm);
/// Collapses e if the rules for `purpose` allow it; the input vertices on its faces move to the
/// survivor's faces.
bool try_collapse(Remesher& rm, EdgeHandle e, Collapse purpose);

// --- flip.cpp ----------------------------------------------------------------------------------

/// §4 step 3: one pass of flips towards valence 6 (4 on the boundary); returns the count.
std::size_t equalize_valences(Remesher& rm);
/// Flips every interior edge whose opposite angles sum to more than π where the rules allow.
std::size_t delaunay_flips(Remesher& rm);
/// May the edge between a and b, with faces (b, a, c) and (a, b, d), become (a, c, d), (c, b, d)?
bool flip_keeps_orientation(const Remesher& rm, VertexHandle a, VertexHandle b, VertexHandle c,
                            VertexHandle d);

// --- smooth.cpp --------------------------------------------------------------------------------

/// What a placing target did with its vertex.
enum class Placed : char { No, Moved, Shortened, Dropped };
/// §4 step 4: every vertex towards its one-ring centroid in its tangent plane (curve vertices
/// along their curve), then onto the input.
void tangential_smoothing(Remesher& rm);
/// Moves every vertex for which target(v, goal) is true to its goal (curve vertices along their
/// curve), placed on the input; all targets read the positions before any move.
void move_vertices(Remesher& rm, const std::function<bool(VertexHandle, Vec3&)>& target);
/// The same for targets that place their vertex on the input themselves (`out`).
void move_vertices_placing(Remesher& rm, const std::function<Placed(VertexHandle, Vec3&)>& place);
/// Would moving v to q keep each face around it from going flat or turning over?
bool ring_keeps_faces(const Remesher& rm, VertexHandle v, const Vec3& q);
/// v's one-ring centroid, the move projected into v's tangent plane; false if v is isolated.
bool centroid_target(const Remesher& rm, VertexHandle v, Vec3& goal);
/// Area-weighted vertex normal (zero where every face around v has zero area).
Vec3 vertex_normal(const Remesher& rm, VertexHandle v);

// --- equalize.cpp ------------------------------------------------------------------------------

/// §4's fine-tuning, one iteration: moves the interior vertices to equalize their mixed Voronoi
/// areas (options.equalization), then Delaunay flips; returns the number of flips.
std::size_t equalize_areas(Remesher& rm);

// --- repair_triangles.cpp ----------------------------------------------------------------------

/// Flips, collapses or moves until no triangle has an angle below min_deg where the rules allow;
/// returns the number of repairs.
std::size_t repair_bad_triangles(Remesher& rm, double min_deg);

// --- correspondence.cpp ------------------------------------------------------------------------

/// Every output vertex starts as its input vertex (kinds: curve vertices on their curve).
void init_locations(Remesher& rm);
/// Finds where p lies on the input, starting from the location of `near`, stores it as v's
/// location and returns the point to place v at (the projection when options.project).
Vec3 relocate(Remesher& rm, VertexHandle v, const Vec3& p, VertexHandle near);
/// Every input vertex starts on a face of its own output vertex.
void init_points(Remesher& rm);
/// Input vertex i starts at located[i] on the working mesh (not tracked: an invalid face).
void init_points(Remesher& rm, const std::vector<SurfacePoint>& located);
/// Takes every input vertex off face f and appends it to `out`.
void take_points(Remesher& rm, FaceHandle f, std::vector<int>& out);
/// Puts each input vertex of `taken` on the closest face around v; clears `taken`.
void place_points_around(Remesher& rm, VertexHandle v, std::vector<int>& taken);
/// After faces were renumbered: each input vertex takes its face from the list it is on.
void rebind_points(Remesher& rm);
/// Projects every input vertex onto the working mesh again after vertices moved.
void reproject_points(Remesher& rm);
/// Each input vertex's closest point on the output, by a local walk from its tracked face; the
/// report gets how far the walks went.
std::vector<SurfacePoint> closest_input_locations(const Remesher& rm, RemeshReport& report);

// --- order.cpp ---------------------------------------------------------------------------------

/// Where copy_in_order() took each element of the copy from: old index by new index.
struct MeshOrder {
  std::vector<int> vertices, edges, faces;
};
/// A compacted copy of `mesh` (deleted elements left out); with `spatially` the vertices follow a
/// Z-order curve, the faces their smallest vertex and the edges their first face.
Mesh copy_in_order(const Mesh& mesh, bool spatially, MeshOrder& order);
/// Removes deleted elements by a copy (spatially ordered above kSpatialOrderFaces).
void compact(Remesher& rm);
/// Removes the few elements the repairs deleted, in place.
void remove_deleted(Remesher& rm);
/// Maps a result computed on copy_in_order(input) back to the input's own numbering.
void to_input_order(RemeshResult& result, const Mesh& input, const MeshOrder& order);

// --- report.cpp --------------------------------------------------------------------------------

/// The input's figures, after the cycles', and the output's (options.compute_report).
void report_input(const Remesher& rm, RemeshReport& report);
void report_after_cycles(const Remesher& rm, RemeshReport& report);
void report_output(const Remesher& rm, RemeshReport& report);

} // namespace remora::remesh_detail
