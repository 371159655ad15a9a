// The area-equalizing isotropic remesher of Botsch & Kobbelt 2004, §4, with the mutual
// parameterization between input and output tracked through every operation.
//
// remesh() returns a new mesh whose edges are close to a target length l, whose vertices have
// valence close to 6, and whose vertex (mixed Voronoi) areas are nearly equal, so that the
// Laplacian of Eq. 1 becomes symmetric once every area is replaced by the mean (§5). The input is
// never modified. Boundaries stay on the input boundary; boundary corners sharper than
// `corner_angle_deg` stay where they are; with `feature_angle_deg`, so do the input's feature
// lines and their corners (docs/remesh.md, "Feature lines"). Deterministic: the same input and
// options give the same output, whatever the number of threads. The steps live in files named
// after them (remesher.h lists them).
#pragma once

#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "remora/geometry/quality.h"
#include "remora/mesh/mesh.h"
#include "remora/mesh/surface_point.h"

namespace remora {

/// How the fine-tuning equalizes vertex areas (docs/remesh.md compares them).
enum class Equalization {
  Gravity, ///< the paper's update: towards the area-weighted centroid of the one-ring
  Newton,  ///< a damped Gauss-Newton step on the area residuals of the one-ring
};

/// The point that the Newton fine-tuning's smoothing term pulls a vertex towards.
enum class SmoothingTarget {
  Centroid, ///< the uniform centroid of the one-ring (the cycles' tangential smoothing)
  Odt,      ///< the one-ring's circumcentres weighted by triangle area (optimal Delaunay
            ///< triangulation, Chen & Xu 2004; Alliez et al. 2005)
};

struct RemeshOptions {
  /// Absolute target edge length l; when <= 0, l = length_factor × the input's mean edge length
  /// (the paper: "slightly less than the average"), or × its area-based length when needles
  /// inflate the mean (length_scale() in geometry/measures.h).
  double target_length = 0.0;
  double length_factor = 0.9;
  /// Cycles of split (> 4/3 l), collapse (< 4/5 l), valence flips, tangential smoothing (§4): at
  /// least `cycles`, then more, up to `max_cycles`, while the last one still split, collapsed or
  /// flipped more than `settle_fraction` × the faces. The paper says about 5; at 7 organic and
  /// open meshes have settled, while CAD parts keep reconnecting around their creases and gain
  /// from a few more (docs/remesh.md, "Design notes").
  int cycles = 7;
  /// The most cycles; values below `cycles` mean `cycles` (no extra cycles).
  int max_cycles = 12;
  /// An extra cycle runs while the last cycle's splits, collapses and valence flips together
  /// exceed this fraction of the faces. In [0, 1]; 1 never adds a cycle (a first cycle on
  /// needles may change more than all the faces).
  double settle_fraction = 0.03;
  /// Iterations of the area-equalizing fine-tuning (§4); 0 skips it. With the momentum below,
  /// the figures swing for a few iterations before they settle (docs/remesh.md, "Momentum").
  int equalize_iterations = 9;
  Equalization equalization = Equalization::Newton;
  /// Damping factor λ of the area-equalizing update (both methods).
  double lambda = 0.8;
  /// Newton only: weight μ of the tangential-smoothing term, relative to the area term.
  double equalize_smoothing = 2.5;
  /// Newton only: where the smoothing term pulls. The ODT point keeps more edges in the band
  /// [4/5 l, 4/3 l] than the centroid and equalizes areas further, for about 0.1° of mean
  /// |θ−60°|; its pull is weaker, hence the default μ = 2.5 (1.5 suits the centroid;
  /// docs/remesh.md, "Design notes").
  SmoothingTarget smoothing_target = SmoothingTarget::Odt;
  /// Newton only: heavy-ball momentum β (Polyak). Each fine-tuning move adds β × the vertex's
  /// previous move (taken into its tangent plane): the damped per-vertex (Jacobi) steps are slow
  /// on area errors that span many rings (the deficit of the boundary cells), and the momentum
  /// carries them further (docs/remesh.md, "Momentum"). 0 turns it off; must be < 1.
  double equalize_momentum = 0.5;
  /// After every fine-tuning iteration, flip the edges whose opposite angles sum to more than π
  /// (intrinsic Delaunay flips): the fine-tuning then costs less triangle shape (docs/remesh.md).
  bool equalize_flips = true;
  /// Newton only: a fine-tuning move that would bring a face around the vertex (after its
  /// placement on the input) below this angle, and below the smallest angle around it now, is
  /// halved, twice at most, then dropped. 5 degrees above repair_angle_deg leaves room for the
  /// neighbours, which move at the same time (docs/remesh.md). 0 turns the guard off.
  double equalize_guard_deg = 30.0;
  /// Newton only: the boundary vertices' areas join the residuals, with the same target Ā, and
  /// the vertices next to the boundary take Newton steps, placed so that no edge of their ring
  /// leaves the band [4/5 l, 4/3 l] (or goes further out of it). A boundary vertex's Voronoi
  /// cell ends at the boundary, so inside the band it cannot reach Ā, but its area grows from
  /// about half of Ā to 0.55–0.6 Ā, which lowers an open mesh's full symmetry defect
  /// (docs/remesh.md). false: the vertices next to the boundary only take tangential
  /// smoothing.
  bool equalize_boundary = true;
  /// Project moved vertices back onto the input surface (true), or only keep updates in the
  /// tangent plane (the paper's cheaper variant).
  bool project = true;
  /// After the cycles and after equalization, triangles with a smaller angle than this get their
  /// longest edge flipped or shortest edge collapsed where the rules allow.
  double repair_angle_deg = 25.0;
  /// A curve vertex (boundary or feature line) where its curve turns by more than this, at the
  /// scale of l (between the chords to its curve's points l/2 away, and again 2 l away: a
  /// scanned rim's zigzag is no corner), is a corner and never moves.
  double corner_angle_deg = 30.0;
  /// Input edges whose faces' normals differ by more than this many degrees are features
  /// (feature_edges() in geometry/measures.h): like the boundary, their lines are kept. Output
  /// vertices on them slide only along them, their edges are never flipped, and where lines end
  /// or meet, or turn by more than corner_angle_deg, a corner stays. 0 turns features off.
  double feature_angle_deg = 0.0;
  /// Spacing of the boundary vertices, in l, set once after the first cycle: where a run of the
  /// boundary between corners has closer vertices, every so many are collapsed and the rest
  /// spaced evenly along it. Longer boundary edges give the boundary vertices larger cells
  /// (their Voronoi cell ends at the boundary; docs/remesh.md, "Boundary spacing"). At most
  /// 4/3 (longer boundary edges are split again); values ≤ 1, or fewer than 2 cycles, leave the
  /// boundary as the cycles make it.
  double boundary_spacing = 1.2;
  /// Fill the quality part of RemeshReport (figures, symmetry defects, distances to the input).
  /// Off, only counts and timings are reported (faster), for callers that need no figures.
  bool compute_report = true;
  /// Worker threads for the data-parallel passes; 0 = all hardware threads.
  int threads = 0;
  /// Called at the start of every phase: (phase name, step, number of steps).
  std::function<void(std::string_view phase, int step, int steps)> progress;
};

struct RemeshReport {
  double target_length = 0.0;
  bool length_from_area = false; ///< l came from the area per vertex (a needle-ridden input)
  std::size_t feature_edges = 0; ///< input edges found sharper than feature_angle_deg
  int cycles = 0;                ///< cycles run (cycles to max_cycles)
  MeshQuality input;
  MeshQuality after_cycles;
  MeshQuality after_equalization;
  /// Percentage of edges within [4/5 l, 4/3 l], after the cycles and after the fine-tuning.
  double edges_in_band_cycles = 0.0, edges_in_band_output = 0.0;
  double symmetry_defect_input = 0.0; ///< laplacian_symmetry_defect() of the input
  double symmetry_defect_cycles = 0.0;
  double symmetry_defect_output = 0.0;
  /// The same without the rows of mesh-boundary vertices (SymmetryRows::Interior); equal to the
  /// above on a closed mesh.
  double symmetry_defect_output_interior = 0.0;
  /// Distances of the output to the input, relative to the input's bounding-box diagonal: of the
  /// output vertices (0 when projecting) and of the output faces' centroids (the chord error).
  double vertex_distance_mean = 0.0, vertex_distance_max = 0.0;
  double centroid_distance_mean = 0.0, centroid_distance_max = 0.0;
  /// The input -> output locations are tracked through every operation and made exact (each
  /// input vertex's closest point on the output) by a short final walk from the tracked face.
  /// How much farther from its input vertex a tracked location was than the final one (mean and
  /// largest, relative to the target length), and the share of tracked faces the walk kept.
  double tracked_excess_mean = 0.0, tracked_excess_max = 0.0;
  double tracked_same_face = 0.0;
  std::size_t splits = 0, collapses = 0, flips = 0; ///< flips: the cycles' valence flips
  std::size_t delaunay_flips = 0; ///< flips between fine-tuning iterations (equalize_flips)
  std::size_t guarded_moves = 0;  ///< fine-tuning moves halved or dropped (equalize_guard_deg)
  std::size_t repairs = 0;        ///< flips and collapses of triangles below repair_angle_deg
  /// Wall time per phase in milliseconds ("split", "collapse", "flip", "smooth", "repair",
  /// "equalize", "reorder", "correspondence", "total"; "report" when compute_report).
  std::map<std::string, double> milliseconds;
};

struct RemeshResult {
  Mesh mesh;
  /// For every output vertex (by index): where it lies on the input.
  std::vector<SurfacePoint> output_on_input;
  /// For every input vertex (by index): where it lies on the output (its closest point there;
  /// invalid face for an isolated input vertex).
  std::vector<SurfacePoint> input_on_output;
  RemeshReport report;
};

/// Remeshes `input` (a repaired, manifold triangle mesh). Throws InvalidArgument for an empty
/// mesh, a non-finite or non-positive target length, negative counts, or an option outside its
/// range (settle_fraction, lambda, equalize_smoothing, equalize_momentum, equalize_guard_deg,
/// corner_angle_deg, boundary_spacing, feature_angle_deg).
RemeshResult remesh(const Mesh& input, const RemeshOptions& options = {});

nlohmann::json to_json(const RemeshReport& report);

/// A patch of an earlier remesh to remesh again where the surface under it changed (the
/// editor's local bake, multires/bake.h), so that it fits back into the hole it came from. Its
/// boundary is locked: boundary vertices never move or go, boundary edges are never split,
/// flipped or collapsed. The locked vertices have faces outside the patch too: their mixed area
/// and valence there make the fine-tuning's residuals and the valence flips those of the whole
/// mesh. The fine-tuning aims at `target_area`, the whole mesh's mean vertex area.
struct RemeshPatch {
  Mesh mesh; ///< the starting triangulation: manifold, with a boundary
  /// Per vertex of `mesh`: where it lies on the reference surface.
  std::vector<SurfacePoint> on_reference;
  /// Per reference vertex: where it lies on `mesh` (tracked through the remesh), or an invalid
  /// face (not tracked).
  std::vector<SurfacePoint> reference_on_mesh;
  /// Per vertex of `mesh`, read for the boundary ones: the mixed area of its faces outside the
  /// patch, and the valence in the patch at which its valence in the whole mesh is the ideal
  /// one (6 inside, 4 on the whole mesh's boundary, less its edges outside the patch).
  std::vector<double> outside_area;
  std::vector<int> valence_target;
  double target_area = 0.0; ///< > 0
};

struct RemeshPatchResult {
  Mesh mesh;
  /// Per output vertex: its index in the patch's mesh for a locked (boundary) vertex, else -1.
  std::vector<int> origin;
  std::vector<SurfacePoint> output_on_reference; ///< per output vertex
  /// Per reference vertex tracked (a valid face in reference_on_mesh): its closest point on the
  /// output; an invalid face for the others.
  std::vector<SurfacePoint> reference_on_output;
  RemeshReport report; ///< counts and timings (no figures)
};

/// Remeshes `patch` on `reference` (the surface it must lie on, e.g. the part of a smoothed
/// input under it and a margin) with the steps of remesh() and options.target_length, which must
/// be > 0 (the whole mesh's l). The boundary spacing and feature lines do not apply
/// (boundary_spacing is ignored; feature_angle_deg must be 0). Throws InvalidArgument for a
/// patch without boundary, mismatched sizes, a location outside the reference or the mesh, a
/// target length or area that is not positive, and what remesh() throws for its options.
RemeshPatchResult remesh_patch(const Mesh& reference, const RemeshPatch& patch,
                               const RemeshOptions& options);

} // namespace remora
