// The multiresolution editor of Botsch & Kobbelt 2004 (§3, Fig. 3; basis functions of §6): the
// whole pipeline behind one object.
//
//   Editor editor(mesh, options);        // 1-3: load O, base surface S (low-pass of O, same
//                                        //      connectivity), area-equalizing remesh of S into
//                                        //      the base B with its correspondence (cached here:
//                                        //      every later region reuses it)
//   editor.set_region(support, handles); // 4-5: paint on O, mapped onto B; solve Δ^k = 0 on B with
//                                        //      the handles undeformed (B0), encode every vertex
//                                        //      of O in the support as a Phong detail against B0,
//                                        //      factor once, solve the 3 + 4h basis functions
//   editor.set_transform(j, T);          // 6:   store T (affine 3×4) for handle j
//   editor.positions() / result();       // 7:   blend the basis functions, decode: no solve
//
// Basis functions: the solution is linear in the constrained values, and handle j's values are
// T_j [x; 1] of its rest positions, so with Φ_0 = the solution for the fixed vertices' x, y, z
// (handles at 0) and Φ_j = the solutions for handle j's x, y, z and 1 (everything else at 0),
//   X_free = Φ_0 + Σ_j Φ_j [M_jᵀ; t_jᵀ]     (T_j = [M_j | t_j]),
// a product with an n_free × 4 block per handle (Botsch & Kobbelt 2004, "An intuitive framework
// for real-time freeform modeling").
//
// O's connectivity is never changed. Vertices of O outside the support keep their positions bit
// for bit. Errors throw InvalidArgument (bad ids, empty or inconsistent regions, NaN transforms)
// or NumericalError (a solver that fails, e.g. BiCGSTAB on the "no remesh" baseline).
#pragma once

#include <array>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stop_token>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "remora/geometry/quality.h"
#include "remora/linalg/kharmonic.h"
#include "remora/linalg/solver.h"
#include "remora/mesh/mesh.h"
#include "remora/multires/base_figures.h"
#include "remora/multires/base_surface.h"
#include "remora/multires/nonlinear.h"
#include "remora/multires/phong.h"
#include "remora/remesh/remesh.h"

namespace remora {

/// An affine map x -> M x + t as the 3×4 matrix [M | t].
using Transform = Eigen::Matrix<double, 3, 4>;

Transform identity_transform();
Transform translation(const Eigen::Vector3d& offset);
/// Rotation by `radians` about `axis` (any non-zero length) through `center`.
Transform rotation(const Eigen::Vector3d& axis, double radians, const Eigen::Vector3d& center);
/// Scaling by `factors` along x, y, z about `center`.
Transform scaling(const Eigen::Vector3d& factors, const Eigen::Vector3d& center);
/// a ∘ b: first b, then a.
Transform compose(const Transform& a, const Transform& b);

/// How the vertices of O follow the deformed base.
enum class DetailMode {
  Normal,       ///< Phong: base point + offset along the interpolated normal (the paper)
  Displacement, ///< base point + the rest-pose offset vector, not rotated (for comparison)
  None,         ///< the base point alone: details are lost (for comparison)
};
std::string to_string(DetailMode mode);
DetailMode parse_detail_mode(const std::string& name); ///< "normal", "displacement", "none"

struct EditorOptions {
  LowPassOptions base;                ///< the base surface's low-pass filter
  bool remesh = true;                 ///< false: the "no remesh" baseline on O's own connectivity
  RemeshOptions remesh_options = [] { ///< the base's remesh (target length 0.9 × mean edge)
    RemeshOptions r;
    r.compute_report = false;
    return r;
  }();
  KHarmonicOptions system; ///< k and the area weights (Mean: the paper's SPD system)
  /// By name (linalg/solver.h, plus "multigrid" for the remeshed base); empty = the default
  /// direct solver for a symmetric system, "lu" for the Mixed one.
  SolverOptions solver;
  DetailMode details = DetailMode::Normal;
  EditMethod method = EditMethod::Linear;
  NonlinearOptions nonlinear; ///< method Nonlinear: the energy and its iterations
  PhongOptions phong;
  int threads = 0; ///< 0 = all hardware threads
  /// The memory this editor may plan with (0 = no limit): set_region refuses (InvalidArgument) a
  /// region whose estimate (region_bytes() of multires/limits.h) added to the preprocessing's
  /// (kEditorBytesPerTriangle per input triangle) exceeds it, and keeps fewer regions for an
  /// undo where they would not fit beside it.
  std::uint64_t memory_bytes = 0;
  /// Called at the start of every phase: (phase name, step, number of steps).
  std::function<void(std::string_view phase, int step, int steps)> progress;
};

/// EditReport::coarse_support is set above this support_edge_ratio.
inline constexpr double kCoarseSupportRatio = 4.0;

/// The steps of set_region() that EditReport::milliseconds times (docs/editing.md), in order;
/// the nonlinear ones only for method nonlinear.
inline constexpr std::array<const char*, 8> kSetRegionSteps = {
    "map",   "assemble", "factor", "solve", "encode", "nonlinear setup", "nonlinear coarse base",
    "finish"};

struct EditReport {
  std::size_t input_vertices = 0, input_faces = 0;
  std::size_t base_vertices = 0, base_faces = 0;
  bool remeshed = true;
  double sigma = 0.0;                    ///< the low-pass filter's length scale
  double sigma_min = 0.0;                ///< its smallest value at a vertex (the feature cap)
  std::size_t sigma_capped_vertices = 0; ///< vertices of O where the cap lowered it
  std::size_t sigma_capped_loops = 0;    ///< boundary loops of O it lowered it on
  std::size_t intrinsic_flips = 0, input_negative_weights = 0;
  double base_target_length = 0.0;
  double base_symmetry_defect = 0.0; ///< laplacian_symmetry_defect() of the base
  MeshQuality base_quality;
  // set_region
  std::size_t support_vertices = 0;         ///< of O, handles included
  std::vector<std::size_t> handle_vertices; ///< of O, per handle
  std::size_t free_base_vertices = 0, constrained_base_vertices = 0;
  std::vector<std::size_t> handle_base_vertices;
  /// Edges of the system's mesh with a free end whose cotan weight is negative (none on a good
  /// remesh; many on a scan's own connectivity).
  std::size_t negative_weights_in_support = 0;
  /// The longest edge of O with both ends in the support over the base's edge length (its
  /// target length, or with no remesh its mean edge length). Only O's vertices move, so a
  /// support whose own triangles are much longer than the base's bends in facets.
  double support_edge_ratio = 0.0;
  /// Set when support_edge_ratio exceeds kCoarseSupportRatio: what the user sees and can do.
  std::string coarse_support;
  /// The region was one of the last ones installed, set again (an undo): installed as it was,
  /// without the work; the other figures are those of its first set_region().
  bool region_reused = false;
  std::string solver;
  SolverStats solver_stats;
  int solves = 0; ///< right-hand sides solved (3 + 4h)
  PhongStats phong;
  /// The base's deformation in the last frame: "linear" or "nonlinear".
  std::string method = "linear";
  NonlinearStats nonlinear; ///< method nonlinear: the last frame's iterations
  /// Method nonlinear: its energy's name (to_string(NonlinearEnergy)).
  std::string nonlinear_energy;
  /// Method nonlinear: "coarse" when the last frame showed the preview of a large support,
  /// "fine" otherwise (multires/nonlinear_region.h), "preparing" while its state is built apart
  /// (Editor::NonlinearBuild: the frame is linear).
  std::string nonlinear_level;
  /// Method nonlinear: why the last frame shows the linear result instead (empty otherwise).
  std::string fallback;
  /// Wall time in milliseconds: "base", "remesh", "set_region" (and its parts "assemble",
  /// "factor", "solve", "encode"), "frame" (the last positions() that had work to do).
  std::map<std::string, double> milliseconds;
};

nlohmann::json to_json(const EditReport& report);

/// The preprocessed pieces of an editor (steps 1-3), as a bake (multires/bake.h) hands them to
/// a new editor: O, its low-pass S, the base B with both correspondences, and the base's figures.
/// Shapes: input_positions and smooth n_input × 3, base_rest n_base × 3; base_on_input has a
/// location on O per base vertex, input_on_base one on B per input vertex (invalid face for an
/// isolated one).
struct EditorParts {
  Mesh input;
  Eigen::MatrixXd input_positions; ///< O
  TriangleTopology input_topology;
  std::shared_ptr<const LowPassFilter> filter; ///< immutable, shared by the editors of a bake
  Eigen::MatrixXd smooth;                      ///< S = filter(O)
  Mesh base;
  TriangleTopology topology;
  Eigen::MatrixXd base_rest; ///< B
  std::vector<SurfacePoint> base_on_input, input_on_base;
  std::vector<std::pair<int, int>> negative_edges; ///< base edges with a negative cotan weight
  BaseStatistics statistics; ///< per base vertex, what the report's figures sum
  EditReport report;         ///< the base's figures
  /// The base's Laplacian assembler when the maker has it (the bake updates the old one);
  /// otherwise the editor builds it.
  std::optional<KHarmonicAssembler> assembler;
  /// B's vertex normals (vertex_normals() of topology and base_rest) when the maker has them;
  /// empty: the editor computes them.
  Eigen::MatrixXd base_normals;
  /// A nested-dissection order of B's k-ring graph, a key per vertex (Editor::prepare_regions();
  /// a bake carries it over); empty when there is none. base_order_k: its k. base_order_tree:
  /// the elimination tree of the k-ring graph the order was made for, by position (separator.h's
  /// elimination_tree()), on which a bake keeps the carried keys (raise_to_common_ancestors() of
  /// nested_dissection.h); empty when there is none.
  std::vector<int> base_order;
  int base_order_k = 0;
  std::vector<int> base_order_tree;
};

/// The same pieces of an existing editor, read-only (what a bake reads).
struct EditorPartsView {
  const Mesh& input;
  const Eigen::MatrixXd& input_positions;
  const TriangleTopology& input_topology;
  const std::shared_ptr<const LowPassFilter>& filter;
  const Eigen::MatrixXd& smooth;
  const Mesh& base;
  const TriangleTopology& topology;
  const Eigen::MatrixXd& base_rest;
  const std::vector<SurfacePoint>& base_on_input;
  const std::vector<SurfacePoint>& input_on_base;
  const std::vector<std::pair<int, int>>& negative_edges;
  const BaseStatistics& statistics;
  const EditReport& report;
  const KHarmonicAssembler& assembler;
  const Eigen::MatrixXd& base_normals;
  const std::vector<int>& base_order;
  int base_order_k;
  const std::vector<int>& base_order_tree;
};

struct FrameExport;

class Editor {
public:
  /// Steps 1-3. `mesh` must be a repaired mesh without deleted elements (read_mesh() gives one).
  /// Throws InvalidArgument for an empty mesh, non-finite points or bad options.
  explicit Editor(Mesh mesh, EditorOptions options = {});
  /// Steps 1-3 adopted from a bake (multires/bake.h): `build` fills the parts in place, where the
  /// editor keeps them (OpenMesh's meshes cannot be moved, only copied); nothing is recomputed
  /// but the base's normals, statistics and Laplacian assembler where the parts have none for
  /// this base.
  /// `options` as they made the pieces, remesh on. Throws what `build` throws, and
  /// InvalidArgument when the pieces' sizes disagree.
  Editor(const std::function<void(EditorParts&)>& build, EditorOptions options);
  Editor(Editor&&) noexcept;
  Editor& operator=(Editor&&) noexcept;
  ~Editor();

  /// Steps 4-5. `support`: vertex ids of O, handles included; handles[j]: the ids of handle j,
  /// each inside the support and disjoint from the others. Resets every transform to the
  /// identity. Throws InvalidArgument for an empty support, no handle, an empty handle, an id out
  /// of range, a handle vertex outside the support or in two handles, a support that maps to no
  /// free base vertex, a support component (on the base) with no constrained vertex, or a region
  /// over options().memory_bytes (checked before the factorization); throws NumericalError when
  /// the solver fails, and Cancelled when `stop` is triggered (checked between the steps; a
  /// factorization runs to its end). On a throw the previous region and the report stay as they
  /// were. One of the last two regions installed before this one, set again with the same ids
  /// and system (an undo), is installed as it was, without the work: the same positions bit for
  /// bit. Those kept regions are dropped, the oldest first, when a new region would not fit
  /// beside them in options().memory_bytes, before its work (so also when that work then fails):
  /// they are a cache, and a dropped one set again is built again.
  void set_region(const std::vector<int>& support, const std::vector<std::vector<int>>& handles,
                  const std::stop_token& stop = {});

  /// set_region() in two halves: prepare_region() does the work (it may throw as set_region()
  /// does) and changes nothing the editor shows; install_region() makes the prepared region the
  /// current one, at no cost. A caller can thus drop a region that a newer request made stale.
  /// install_region() throws InvalidArgument for a region another editor prepared, or one
  /// installed already.
  class Prepared {
  public:
    Prepared();
    Prepared(Prepared&&) noexcept;
    Prepared& operator=(Prepared&&) noexcept;
    ~Prepared();
    struct State;

  private:
    friend class Editor;
    std::unique_ptr<State> state_;
  };
  /// `defer_nonlinear`: method nonlinear's state is left out of the region (NonlinearBuild).
  Prepared prepare_region(const std::vector<int>& support,
                          const std::vector<std::vector<int>>& handles,
                          const std::stop_token& stop = {}, bool defer_nonlinear = false);
  void install_region(Prepared&& prepared);

  /// Method nonlinear's state of the current region (its deformers, factored, and the coarse
  /// level of its preview), built apart from set_region, so that a server shows the region
  /// before that state is ready:
  /// - nonlinear_build(), under the caller's lock, captures what the build reads and marks the
  ///   region deferred;
  /// - NonlinearBuild::run() builds it from that capture and from the editor's preprocessed
  ///   parts, which nothing changes, so the caller's lock can be released meanwhile;
  /// - finish_nonlinear(), under the lock, gives it to the region it was captured from, the
  ///   current one or one kept for an undo, unless that region has one by then, and ends the
  ///   deferral whether or not the build ran.
  /// While a region is deferred, positions(budget) leave the linear result (report()'s
  /// nonlinear_level "preparing", converged() false), and positions() without a budget builds
  /// the state itself. The build is empty (run() and finish_nonlinear() do nothing) when the
  /// region needs none: method linear, no region, or its state is there. The editor must outlive
  /// its builds.
  class NonlinearBuild {
  public:
    NonlinearBuild();
    NonlinearBuild(NonlinearBuild&&) noexcept;
    NonlinearBuild& operator=(NonlinearBuild&&) noexcept;
    ~NonlinearBuild();
    bool empty() const;
    /// Builds, unless `stop` is triggered first (checked before each factorization: the
    /// region's next frame then builds it). Throws what set_region's nonlinear step throws.
    void run(const std::stop_token& stop = {});
    struct State;

  private:
    friend class Editor;
    std::unique_ptr<State> state_;
  };
  NonlinearBuild nonlinear_build();
  void finish_nonlinear(NonlinearBuild&& build);

  int handle_count() const;
  /// The vertices of O that can move under the current region (the support, handles included),
  /// in increasing order; empty before set_region().
  const std::vector<int>& movable_vertices() const;
  /// Precomputes, once, what the regions to come share: the rows of the base's k-harmonic
  /// operator for the current k and area weights (KHarmonicAssembler::keep_rows: a region's
  /// system is then copied out of them), and for `cholmod` (amd) on two threads or more a nested
  /// dissection of the base's k-ring graph (linalg/nested_dissection.h), at the top of whose
  /// elimination tree each region's two-half factor is then cut, each half following it, instead
  /// of a breadth-first cut and CAMD: fewer flops and no ordering per region (docs/solvers.md).
  /// Worth its cost (METIS on the whole base) before many regions: `remora serve` and `remora
  /// bench edit` call it after loading, and a bake of a prepared editor prepares the new one
  /// (carrying the order over where it can). The results are those of an unprepared editor to
  /// round-off. Does nothing above kMaxPreparedBaseVertices base vertices or for the multigrid
  /// solver; one set of rows and one order are kept, so another k or weighting prepares anew.
  /// When METIS fails the regions order themselves (no order is kept); throws std::bad_alloc
  /// when the rows do not fit.
  void prepare_regions();
  static constexpr std::size_t kMaxPreparedBaseVertices = 200000;
  /// Changes k and the area weights for the next set_region(). Throws InvalidArgument for a k
  /// other than 1, 2, 3, or weights the configured solver cannot take.
  void set_system(const KHarmonicOptions& system);
  /// Switches the base's deformation, for the current region and the next ones. Cheap: the next
  /// positions() call builds what nonlinear needs for the current region if set_region did not
  /// (a factorization, as in set_region; a failure leaves the linear result with a message in
  /// the report).
  void set_method(EditMethod method);
  /// Method nonlinear's energy (multires/nonlinear.h), for the current region and the next ones;
  /// cheap as set_method(): the next positions() call builds the region's nonlinear state again.
  void set_nonlinear_energy(NonlinearEnergy energy);
  /// The centroid of handle j's vertices on O (the default center of rotations and scalings).
  Eigen::Vector3d handle_center(int handle) const;

  /// Step 6: handle j's vertices go to T [x; 1] of their rest positions. Throws InvalidArgument
  /// for j out of range, a non-finite T, or a linear part M that mirrors (det M <= 0) or
  /// collapses (a singular value below 1e-6 of the largest) the handle. Cheap: the work happens
  /// in positions().
  void set_transform(int handle, const Transform& transform);
  const Transform& transform(int handle) const;

  /// Step 7: O's vertex positions under the current transforms (n_vertices × 3). Blends the basis
  /// functions and decodes the details when a transform changed since the last call. Method
  /// nonlinear: iterates until converged (or its max_iterations).
  const Eigen::MatrixXd& positions();
  /// Method nonlinear while a handle is dragged: at most `budget_ms` of iterations (at least
  /// one), continuing from the last call, then the decode; call again to go on towards
  /// convergence. The same as positions() for method linear.
  const Eigen::MatrixXd& positions(double budget_ms);
  /// The same, and no iteration begins after the one under way once `interrupt` returns true
  /// (a server with another request waiting). Called on this thread between iterations.
  const Eigen::MatrixXd& positions(double budget_ms, const std::function<bool()>& interrupt);
  /// Whether positions() are final: true for method linear, and for nonlinear once the
  /// iteration has converged, reached its max_iterations or fallen back to the linear result.
  bool converged() const;
  /// O with positions(): same connectivity, bit-identical points outside the support.
  Mesh result();

  const Mesh& input() const;
  /// The base B (the remeshed base surface, or S itself without remeshing) at rest.
  const Mesh& base() const;
  /// B's vertex positions under the current transforms (B0 where nothing moved), a copy.
  Eigen::MatrixXd base_positions();
  /// Applies the editor's low-pass filter (the one that made S) to per-vertex values of O.
  Eigen::MatrixXd low_pass(const Eigen::MatrixXd& values);
  /// Whether vertex i of O is in the current support (handles included).
  bool in_support(int vertex) const;

  const EditReport& report() const;
  const EditorOptions& options() const;
  /// Steps 1-3's pieces, read-only (valid while the editor lives and is not moved from).
  EditorPartsView parts() const;

private:
  friend FrameExport frame_export(const Editor& editor); // multires/frame_export.h
  friend std::vector<float> frame_base_offsets(const Editor& editor);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

} // namespace remora
