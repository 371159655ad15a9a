// The editor's state (multires/editor.h), shared by its two files: editor.cpp (construction, the
// frame, the report) and editor_region.cpp (the steps of set_region: paint, map to the base,
// basis functions, details, memory). Internal: not installed.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <stop_token>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "remora/common/error.h"
#include "remora/geometry/measures.h"
#include "remora/multires/editor.h"
#include "remora/multires/frame.h"
#include "remora/multires/limits.h"
#include "remora/multires/multigrid.h"
#include "remora/multires/nonlinear_region.h"

namespace remora {

/// A region of the editor: its labels, basis functions, details and the frame's state; with the
/// report it was made with (set_region's figures) and the editor that made it.
struct Editor::Prepared::State {
  const void* owner = nullptr;
  EditReport report;
  // What it was prepared from (set_region's arguments and the system), to find it again.
  std::vector<int> support;
  std::vector<std::vector<int>> handle_ids;
  KHarmonicOptions system;
  std::vector<int> input_label; // per O vertex: kFixed, kFree or handle j
  std::vector<int> base_label;  // per B vertex
  int handles = 0;
  std::vector<int> free_vertices; // B vertices, in the row order of `basis`
  BasisRows basis;                // n_free × (3 + 4h)
  std::vector<std::vector<int>> handle_base;
  std::vector<Eigen::Vector3d> handle_centers;
  Eigen::MatrixXd rest;         // B0
  Eigen::MatrixXd rest_normals; // of B0
  std::vector<int> encoded;     // O vertices with a detail, in increasing order
  FrameDetails details;         // their details, decoded into the rows `encoded`
  NormalPlan affected;          // B vertices whose normal can change, and their faces
  std::vector<Transform> transforms;
  FrameRows frame; // B under the transforms: positions and normals
  Eigen::MatrixXd current_positions;
  std::vector<double> face_normals; // update_normals()'s scratch
  bool dirty = true;
  std::unique_ptr<NonlinearRegion> nonlinear; // method nonlinear (multires/nonlinear_region.h)
  NonlinearEnergy nonlinear_energy{};         // what `nonlinear` was built for
  std::shared_ptr<const RemeshResult> coarse; // its preview level (kept by the editor)
  std::uint64_t serial = 0;        // which prepare_region() made it, for finish_nonlinear()
  bool nonlinear_deferred = false; // its nonlinear state is built apart (NonlinearBuild)
  std::uint64_t bytes = 0;         // its estimated memory (region_bytes() of multires/limits.h)
};

using RegionState = Editor::Prepared::State;

// The preprocessed pieces are the base class, so that a bake builds them where the editor keeps
// them (Editor(build, options)): OpenMesh's meshes cannot be moved, only copied.
struct Editor::Impl : EditorParts {
  EditorOptions options;
  std::unique_ptr<MultigridSolver> multigrid;
  std::shared_ptr<const RemeshResult> coarse; // method nonlinear's preview level, for every region
  // B's mean edge length, measured the first time a preview needs it (a region may be prepared
  // on the session's worker while a frame builds another's nonlinear state).
  std::once_flag base_length_once;
  double base_length = 0.0;
  double mean_base_length() {
    std::call_once(base_length_once, [&] { base_length = mean_edge_length(base); });
    return base_length;
  }
  std::unique_ptr<RegionState> region;
  // For each input vertex i, the base vertices whose location on the input (base_on_input) has
  // i as its nearest corner: base_nearest[base_nearest_begin[i] .. base_nearest_begin[i + 1]).
  // Built once per editor (index_base_nearest()), so that mapping a region visits its own
  // vertices, not the whole base.
  std::vector<int> base_nearest_begin, base_nearest;
  void index_base_nearest();
  // The regions installed before the current one, the latest first: set_region() of one of them
  // again (an undo) installs it as it was, without the work.
  std::deque<std::unique_ptr<RegionState>> recent;
  static constexpr std::size_t kRecentRegions = 2;

  // The steps of Editor(mesh, options) after the input's checks, in order.
  void filter_input();
  void make_base(Mesh& s);
  void analyze_base();

  void progress(std::string_view phase, int step, int steps) const {
    if (options.progress) options.progress(phase, step, steps);
  }
  std::string solver_name(bool symmetric) const {
    if (!options.solver.name.empty()) return options.solver.name;
    return symmetric ? default_solver_name() : "lu";
  }
  RegionState& state() {
    if (!region) throw InvalidArgument("no region yet: call set_region() first");
    return *region;
  }
  void update(double budget_ms, const std::function<bool()>& interrupt = {});
  std::uint64_t regions_prepared = 0; // the serial of the last prepare_region()
  void build_nonlinear(RegionState& r, EditReport& into);
  /// What building r's nonlinear state reads, copied (Editor::NonlinearBuild).
  std::unique_ptr<Editor::NonlinearBuild::State> capture_nonlinear(const RegionState& r);
  /// The built state into r; its times into `into`.
  void adopt_nonlinear(RegionState& r, Editor::NonlinearBuild::State& built, EditReport& into);
  /// r's nonlinear state is missing or for another energy.
  bool needs_nonlinear(const RegionState& r) const {
    return !r.nonlinear || r.nonlinear_energy != options.nonlinear.energy;
  }
  void deform_base(RegionState& r, bool moved, double budget_ms,
                   const std::function<bool()>& interrupt);

  // The steps of set_region(), in order, on a new state (the current region stays until all
  // succeed).
  std::unique_ptr<RegionState> paint(const std::vector<int>& support,
                                     const std::vector<std::vector<int>>& handles) const;
  void map_to_base(RegionState& r) const;
  void report_region(const RegionState& r, EditReport& out) const;
  Eigen::MatrixXd constrained_values(const RegionState& r, const std::vector<int>& vertices,
                                     bool by_vertex) const;
  void solve_basis(RegionState& r, EditReport& out, const std::stop_token& stop);
  void encode_details(RegionState& r, EditReport& out, const std::stop_token& stop) const;
  void find_affected(RegionState& r) const;

  // The memory limit (options.memory_bytes; 0 = none). The preprocessing's estimate, by the input
  // triangles.
  std::uint64_t preprocessing_bytes() const { return kEditorBytesPerTriangle * input.n_faces(); }
  void bytes_for(RegionState& r) const;
  void make_room(std::uint64_t beside);
};

} // namespace remora
