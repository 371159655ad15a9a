// One editing session of `remora serve`: the mesh being edited, its Editor (multires/editor.h),
// the region and handle transforms, and the undo/redo history. Thread-safe: every public call
// locks the session. Long work (loading and preprocessing a mesh, or baking the current result
// into a new base before a new region) runs on a worker thread; status() reports its progress,
// and other calls throw Busy meanwhile.
//
// History: every load, region and committed transform is a snapshot (editor, region, k,
// transforms). Undo and redo re-apply a snapshot; the same editor, region and transforms give the
// same positions bit for bit. A new region after non-identity transforms first bakes the current
// result into a new editor (the edited shape becomes the next input), as a user expects: locally,
// only where the edit changed the shape (multires/bake.h), or in full where that cannot work.
// The editors a history keeps share nothing they change (a bake's share the immutable filter).
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "remora/common/error.h"
#include "remora/mesh/mesh.h"
#include "remora/mesh/soup.h"
#include "remora/multires/editor.h"
#include "remora/multires/frame_export.h"
#include "remora/multires/limits.h"
#include "shape.h"

namespace remora::server {

/// The session is working (or has nothing loaded) and cannot take the request now.
class Busy : public Error {
public:
  using Error::Error;
};

struct SessionOptions {
  int threads = 0;               ///< editor threads (0 = all)
  ReadLimits read;               ///< what a load accepts (mesh/soup.h; 0 = no limit)
  int max_handles = kMaxHandles; ///< handles a region may have (multires/limits.h)
  /// Method nonlinear: milliseconds of iterations per frame of set_transform() (at least one
  /// iteration); relax() goes on from there.
  double frame_budget_ms = 6.0;
  std::size_t max_history = 64; ///< snapshots kept for undo
  std::size_t max_editors = 3;  ///< distinct editors (one per bake) the history keeps alive
  /// Defaults for every editor the session builds. Its progress callback, if any, is called on
  /// the worker at every phase of every job ("reading", the editor's phases, "set_region"),
  /// after the session has recorded it, without the session's lock held.
  EditorOptions editor;
};

/// What a handle move or a relax step answers: nothing (a client that evaluates its own frames),
/// the positions of movable_vertices(), the base's row offsets (multires/frame_export.h,
/// frame_base_offsets(): a client that evaluates a nonlinear region's frames from its kernel),
/// or both.
enum class FrameAnswer { None, Positions, BaseOffsets, PositionsAndBaseOffsets };

/// The answer to a handle move or a relax step: the positions of movable_vertices() (Float32
/// x, y, z) and the base's row offsets (x, y, z per basis row of the region's kernel), each
/// when asked for, the server's time, and for method nonlinear whether the iteration is finished
/// and how many iterations the call made.
struct Frame {
  std::vector<float> positions;
  std::vector<float> base_offsets;
  double ms = 0.0;
  bool converged = true;
  int iterations = 0;
};

class Session {
public:
  explicit Session(SessionOptions options = {});
  ~Session(); ///< waits for the worker
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  /// Starts loading (parse, repair, preprocess) on the worker. `bytes` are a file's content, `name`
  /// its file name (the extension gives the format). A file over options.read fails the job
  /// before the memory for it is allocated. Throws Busy while other work runs.
  void start_load(std::string bytes, std::string name);
  /// Starts a new region on the worker (baking the current result first when a handle moved,
  /// except when only k, the method or its energy changes: then the handles keep their
  /// transforms and the region is solved again under them). `energy`: method nonlinear's, by
  /// default options.editor's. Validates first (InvalidArgument): k, ids in range, at most
  /// max_handles handles, no list longer than the mesh has vertices. Throws Busy while other
  /// work runs.
  void start_region(std::vector<int> support, std::vector<std::vector<int>> handles, int k,
                    EditMethod method = EditMethod::Linear,
                    std::optional<NonlinearEnergy> energy = std::nullopt);
  /// The vertex count of the mesh loaded (0 before the first load): no list of a region can
  /// hold more ids without repeating one.
  std::size_t vertex_count() const;
  /// Blocks until the worker is idle (tests and the CLI).
  void wait();
  /// Blocks until the worker is idle or `timeout` has passed (a client's long poll of the
  /// status: it learns of the end of a job at once, without polling fast).
  void wait_for(std::chrono::milliseconds timeout);

  /// Moves handle j (live: not in the history until commit()). Returns what `answer` asks for.
  /// Method nonlinear iterates for frame_budget_ms. With FrameAnswer::None nothing is computed
  /// now (a client that evaluates its own linear frames: the page) and the Frame holds nothing;
  /// the frame is computed when something reads the shape (a pick, the positions, an export, the
  /// next answered move). Base offsets for the energy blended-motions throw InvalidArgument.
  /// With `then_relax` (the last move of a drag, after which the page asks for relax steps),
  /// method nonlinear goes on iterating after the answer, as after an unconverged relax step.
  Frame set_transform(int handle, const Transform& transform,
                      FrameAnswer answer = FrameAnswer::Positions, bool then_relax = false);
  /// Method nonlinear: iterates for at most `budget_ms` more under the live transforms (the
  /// page calls it while the user pauses, until converged), ending after the iteration under
  /// way when another call waits for the session. Method linear: the frame as it is, converged.
  /// Answers as set_transform() does, but never nothing.
  Frame relax(double budget_ms, FrameAnswer answer = FrameAnswer::Positions);
  /// Records the live transforms as a snapshot (the end of a drag). No-op when nothing changed.
  void commit();
  bool undo(); ///< false when there is nothing to undo
  bool redo();

  /// {"state": "empty" | "busy" | "ready", "progress": {job, phase, step, steps, fraction} while
  /// busy, "error" of the last job, "undo", "redo", the change counters "mesh_id" (a load),
  /// "positions_id" (positions changed other than by a set_transform frame) and "region_id",
  /// and when ready the mesh, base, region and transforms (docs/server.md).
  nlohmann::json status() const;
  /// Picks on the shape shown (the current positions, live transforms included) with a brush;
  /// works while a region job runs. With `stroke` >= 0 the brush holds only what earlier picks
  /// of that stroke did not answer (Shape::pick). Throws Busy before the first load,
  /// InvalidArgument for a bad ray or radius.
  Pick pick(const Vec3& origin, const Vec3& direction, double radius, Brush brush,
            std::int64_t stroke = -1);
  /// The loaded file's name ("" before the first load).
  std::string name() const;
  /// The current region as {"support": [ids], "handles": [[ids], ...], "k": k, "method":
  /// "linear" | "nonlinear", "energy": method nonlinear's energy}, or null.
  nlohmann::json region() const;
  /// Current positions of every vertex (Float32 x, y, z) and the faces (Uint32 triples).
  std::vector<float> positions() const;
  std::vector<std::uint32_t> indices() const;
  /// The vertices that can move under the current region (sorted), as ids.
  std::vector<std::uint32_t> movable_vertices() const;
  /// The current region's frame as data (multires/frame_export.h), for a page that evaluates the
  /// frames of a drag itself (for an energy that iterates, with the row offsets the frames
  /// answer). Throws Busy without a region or while a job runs.
  FrameExport frame_export() const;
  /// The base surface (remeshed) under the current transforms, its faces, and its vertex areas
  /// over their mean (the "coloured by vertex area" view).
  std::vector<float> base_positions() const;
  std::vector<std::uint32_t> base_indices() const;
  std::vector<float> base_areas() const;
  /// The current result (the input before a region) as the bytes of a file in `format` ("obj",
  /// "ply", "stl"; mesh/io.h's writer, binary PLY and STL). Throws InvalidArgument for another
  /// format and Busy while nothing is loaded or the worker runs.
  std::string export_mesh(const std::string& format) const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

} // namespace remora::server
