// What session.cpp (frames, history, status) and session_jobs.cpp (the worker: loading, region
// jobs, bakes) share of a Session (session.h): its state and its steps. Private to the server.
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <stop_token>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "remora/multires/bake.h"
#include "session.h"

namespace remora::server {

// Named, not anonymous: Session::Impl holds these, and a unity build would otherwise give Impl
// fields of internal linkage (GCC's -Wsubobject-linkage).
namespace session_parts {

struct RegionKey {
  std::vector<int> support;
  std::vector<std::vector<int>> handles;
  int k = 2;
  EditMethod method = EditMethod::Linear;
  NonlinearEnergy energy = NonlinearEnergy::RotatedLaplacian; // method nonlinear's
  bool operator==(const RegionKey&) const = default;
};

/// An editor and the region it currently has.
struct EditorBox {
  explicit EditorBox(Editor e) : editor(std::move(e)) {}
  Editor editor;
  std::optional<RegionKey> region;
  double preprocess_ms = 0.0;
  std::optional<BakeReport> bake; ///< how a bake made it (none for a load)
};

struct Snapshot {
  std::shared_ptr<EditorBox> box;
  std::optional<RegionKey> region;
  std::vector<Transform> transforms;
};

} // namespace session_parts

using namespace session_parts;

struct Session::Impl {
  SessionOptions options;
  mutable std::mutex mutex;
  mutable std::atomic<int> waiting{0}; // callers blocked on `mutex`: a relax step gives way
  std::unique_lock<std::mutex> acquire() const {
    ++waiting;
    std::unique_lock lock(mutex);
    --waiting;
    return lock;
  }
  std::condition_variable idle; // a job ended, the region's nonlinear state is there, or a move
  std::thread worker;
  /// Method nonlinear: a relax step ended before the iteration converged, so the relaxer thread
  /// iterates on between requests (relax_loop()) until it converges or something else changes
  /// the shape (a move, an undo or redo, a job), which clears this.
  bool relax_on = false;
  std::condition_variable relax_wake; // relax_on set, or closing
  std::atomic<bool> closing{false};   // the session is being destroyed
  std::thread relaxer;
  /// The relaxer's loop: under the lock (not acquire(): requests do not wait for it), one
  /// editor.positions() call at a time, each ended by the first request that waits for the
  /// lock; it looks again once that request has had it.
  void relax_loop();
  bool busy = false;
  /// The worker builds the new region's nonlinear state after showing the region
  /// (Editor::NonlinearBuild): frames go on, linear until it is there.
  bool finishing = false;
  /// Waits, the lock released, until the worker has finished the region's nonlinear state.
  void await_nonlinear(std::unique_lock<std::mutex>& lock) {
    idle.wait(lock, [&] { return !finishing; });
  }
  // The running job's stop request, and the job queued behind it (a new region stops a region job).
  std::stop_source stop;
  std::function<void(std::stop_token)> pending;
  // A bake kept for the next region job when a newer region stopped the job after its bake.
  std::shared_ptr<EditorBox> baked, baked_from;
  std::vector<Transform> baked_transforms;
  std::string job, phase; // what the worker does ("load", "region"), and its current phase
  int step = 0, steps = 0;
  double fraction = 0.0;                   // of the whole job
  double span_begin = 0.0, span_end = 1.0; // the share of the job preprocessing takes
  std::string error;                       // the last job's failure, if any
  std::string name;                        // the mesh's file name
  std::shared_ptr<EditorBox> box;          // current editor
  std::optional<RegionKey> region;         // current region
  std::vector<Transform> transforms;       // live transforms
  std::vector<Snapshot> history;
  std::size_t cursor = 0; // history[cursor] is the applied snapshot
  double last_frame_ms = 0.0;
  /// The shape lags the editor: a move went unanswered (set_transform without an answer).
  bool shape_behind = false;
  std::shared_ptr<Shape> shape; // what the page shows and paints on
  // Change counters (status): the faces (a load), the positions other than through a frame of
  // set_transform (load, undo, redo, a new k under moved handles), the region.
  std::uint64_t mesh_id = 0, positions_id = 0, region_id = 0;
  /// set_transform() calls: a relax step waiting for the nonlinear state ends at a move.
  std::uint64_t moves = 0;

  void require_ready() const {
    if (busy) throw Busy(fmt::format("the session is busy ({}: {})", job, phase));
    if (!box) throw Busy("no mesh is loaded yet: load one first");
  }
  void require_region() const {
    require_ready();
    if (!region) throw Busy("no region yet: paint a support and a handle first");
  }
  /// Base offsets are refused before anything changes where frame_base_offsets() refuses them.
  void require_offsets(FrameAnswer answer) const {
    const EditorOptions& o = box->editor.options();
    if ((answer == FrameAnswer::BaseOffsets || answer == FrameAnswer::PositionsAndBaseOffsets) &&
        o.method == EditMethod::Nonlinear && o.nonlinear.energy == NonlinearEnergy::BlendedMotions)
      throw InvalidArgument("the energy blended-motions has no base offsets: its frames blend "
                            "the handles' motions (answer \"positions\" or \"none\")");
  }
  void push_snapshot();
  /// Re-applies a snapshot (undo/redo): same editor, region and transforms, same positions.
  void apply(const Snapshot& s);
  /// The job's progress: `phase` at `s` of `n` steps; its fraction of the whole job from the
  /// preprocessing shares. Call under the lock.
  void report(std::string_view p, int s, int n);
  /// Runs `work` on the worker. A region job while one runs stops it and is queued behind it
  /// (replacing one queued already); so is any job while the worker finishes a region's
  /// nonlinear state; any other overlap throws Busy. Call under the lock.
  void run(std::string what, std::function<void(std::stop_token)> work);
  /// A job's start: a fresh stop request, no progress, no error. Call under the lock.
  void begin_job();
  void reset_progress(); ///< begin_job()'s part but the stop request
  /// The editor that `current` under `moved_by` bakes into (the edited shape as a new input), or
  /// the one a stopped job made for the same bake.
  std::shared_ptr<EditorBox> bake_once(const std::shared_ptr<EditorBox>& current,
                                       const std::vector<Transform>& moved_by);
  /// What a region job does: bake first (a handle moved and the paint changed), solve the paint
  /// again under the same transforms (k or the method changed), set a new region (paint or k).
  struct RegionWork {
    bool bake, resolve, new_region;
  };
  /// A region job: the bake, the region prepared, then installed unless a newer region stopped
  /// it; method nonlinear's state of a new region is built after the install, the job no
  /// longer busy (`finishing`).
  void region_job(const RegionKey& key, RegionWork work, const std::shared_ptr<EditorBox>& current,
                  const std::vector<Transform>& moved_by, const std::stop_token& token);
  /// region_job()'s install, under the lock: `next` with `prepared` (when set) and `key` become
  /// the session's editor and region; returns the nonlinear state left to build (or none).
  Editor::NonlinearBuild make_current(const std::shared_ptr<EditorBox>& next, const RegionKey& key,
                                      std::optional<Editor::Prepared>& prepared, bool resolve,
                                      const std::vector<Transform>& moved_by);
  /// region_job()'s end: `build` run with the lock released, then handed to `editor`.
  void build_nonlinear(Editor& editor, Editor::NonlinearBuild& build, const std::stop_token& token,
                       std::unique_lock<std::mutex>& lock);
  /// positions(budget) of the editor, as the answer to a move or a relax step. Under the lock.
  Frame frame(double budget_ms, FrameAnswer answer = FrameAnswer::Positions,
              const std::function<bool()>& interrupt = {});
  /// report() under the lock, then the options' own progress callback without it. On the worker.
  void progress(std::string_view p, int s, int n);
  EditorOptions editor_options() {
    EditorOptions o = options.editor;
    o.threads = options.threads;
    o.progress = [this](std::string_view p, int s, int n) { progress(p, s, n); };
    return o;
  }
};

} // namespace remora::server
