#include "session.h"

#include <algorithm>
#include <atomic>
#include <functional>
#include <stop_token>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include "remora/common/memory.h"
#include "remora/common/timer.h"
#include "remora/geometry/measures.h"
#include "remora/geometry/quality.h"
#include "remora/linalg/kharmonic.h"
#include "remora/mesh/io.h"
#include "remora/multires/bake.h"
#include "remora/multires/limits.h"

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

namespace {

/// The movable vertices' rows of `p` as interleaved Float32.
std::vector<float> movable_floats(const Editor& editor, const Eigen::MatrixXd& p) {
  const std::vector<int>& movable = editor.movable_vertices();
  std::vector<float> out(3 * movable.size());
  for (std::size_t i = 0; i < movable.size(); ++i)
    for (int c = 0; c < 3; ++c)
      out[3 * i + static_cast<std::size_t>(c)] = static_cast<float>(p(movable[i], c));
  return out;
}

bool is_identity(const std::vector<Transform>& transforms) {
  for (const Transform& t : transforms)
    if (t != identity_transform()) return false;
  return true;
}

/// Where a phase of the editor's preprocessing sits in the whole of it, as [begin, end)
/// fractions: a rough split; the bar moves forward, it does not promise a time.
std::pair<double, double> preprocess_share(std::string_view phase) {
  if (phase == "reading") return {0.0, 0.05};
  if (phase == "bake") return {0.0, 1.0}; // a local bake; a full one reports the phases below
  if (phase == "base surface") return {0.05, 0.2};
  if (phase == "remesh: remesh") return {0.2, 0.6};
  if (phase == "remesh: equalize") return {0.6, 0.9};
  if (phase == "remesh: correspondence") return {0.9, 0.97};
  return {0.97, 1.0};
}

/// The steps of the last set_region (docs/editing.md) in ms; none for a region kept for an undo.
nlohmann::json set_region_parts(const EditReport& r) {
  nlohmann::json parts = nlohmann::json::object();
  if (r.region_reused) return parts;
  for (const char* step : kSetRegionSteps)
    if (const auto it = r.milliseconds.find(step); it != r.milliseconds.end())
      parts[step] = it->second;
  return parts;
}

} // namespace

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
  std::condition_variable idle;
  std::thread worker;
  bool busy = false;
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
  void push_snapshot() {
    if (!history.empty()) history.resize(cursor + 1); // drop the redo branch
    history.push_back({box, region, transforms});
    // Old snapshots go first when there are too many, or when they keep too many editors alive
    // (each bake made one; an editor of a million-triangle mesh holds about a gigabyte).
    auto editors = [&] {
      std::vector<const EditorBox*> distinct;
      for (const Snapshot& s : history)
        if (std::find(distinct.begin(), distinct.end(), s.box.get()) == distinct.end())
          distinct.push_back(s.box.get());
      return distinct.size();
    };
    while (history.size() > 1 &&
           (history.size() > options.max_history || editors() > options.max_editors))
      history.erase(history.begin());
    cursor = history.size() - 1;
  }
  /// Re-applies a snapshot (undo/redo): same editor, region and transforms, same positions.
  void apply(const Snapshot& s) {
    if (s.box != box || s.region != region) ++region_id;
    box = s.box;
    region = s.region;
    transforms = s.transforms;
    if (region && box->region != region) {
      box->editor.set_system({region->k, box->editor.options().system.areas});
      box->editor.set_method(region->method);
      box->editor.set_region(region->support, region->handles);
      box->region = region;
    }
    for (std::size_t j = 0; j < transforms.size(); ++j)
      box->editor.set_transform(static_cast<int>(j), transforms[j]);
    shape->set_positions(region ? box->editor.positions() : positions_matrix(box->editor.input()));
    shape_behind = false;
    ++positions_id;
  }
  /// The job's progress: `phase` at `s` of `n` steps; its fraction of the whole job from the
  /// preprocessing shares. Call under the lock.
  void report(std::string_view p, int s, int n) {
    phase = std::string(p);
    step = s;
    steps = n;
    if (p == "set_region") { // the rest of a region job: [span_end, 1]
      fraction = span_end;
      return;
    }
    const auto [begin, end] = preprocess_share(p);
    const double within = n > 0 ? std::clamp(double(s) / n, 0.0, 1.0) : 0.0;
    fraction = span_begin + (span_end - span_begin) * (begin + (end - begin) * within);
  }
  /// Runs `work` on the worker. A region job while one runs stops it and is queued behind it
  /// (replacing one queued already); any other overlap throws Busy. Call under the lock.
  void run(std::string what, std::function<void(std::stop_token)> work) {
    if (busy) {
      if (what == "region" && job == "region") {
        stop.request_stop();
        pending = std::move(work);
        return;
      }
      throw Busy(fmt::format("the session is busy ({}: {})", job, phase));
    }
    if (worker.joinable()) worker.join();
    busy = true;
    job = std::move(what);
    begin_job();
    worker = std::thread([this, work = std::move(work), token = stop.get_token()]() mutable {
      for (;;) {
        try {
          work(token);
        } catch (const Cancelled&) {
          // A newer region stopped it: that one runs next.
        } catch (const std::exception& e) {
          auto lock = acquire();
          error = e.what();
        }
        auto lock = acquire();
        if (pending) {
          work = std::move(pending);
          pending = nullptr;
          begin_job();
          token = stop.get_token();
          continue;
        }
        busy = false;
        phase.clear();
        idle.notify_all();
        return;
      }
    });
  }
  /// A job's start: a fresh stop request, no progress, no error. Call under the lock.
  void begin_job() {
    stop = std::stop_source();
    phase = "starting";
    step = steps = 0;
    fraction = 0.0;
    error.clear();
  }
  /// The editor that `current` under `moved_by` bakes into (the edited shape as a new input), or
  /// the one a stopped job made for the same bake.
  std::shared_ptr<EditorBox> bake_once(const std::shared_ptr<EditorBox>& current,
                                       const std::vector<Transform>& moved_by) {
    {
      auto lock = acquire();
      if (baked && baked_from == current && baked_transforms == moved_by) return baked;
    }
    // The edited shape becomes the next input: filtered and remeshed again where the edit
    // changed it (multires/bake.h), or in full where that cannot work.
    const auto t0 = Clock::now();
    BakeResult result = remora::bake(current->editor);
    auto next = std::make_shared<EditorBox>(std::move(result.editor));
    next->preprocess_ms = ms_since(t0);
    next->bake = std::move(result.report);
    auto lock = acquire();
    baked = next;
    baked_from = current;
    baked_transforms = moved_by;
    return next;
  }
  /// What a region job does: bake first (a handle moved and the paint changed), solve the paint
  /// again under the same transforms (k or the method changed), set a new region (paint or k).
  struct RegionWork {
    bool bake, resolve, new_region;
  };
  /// A region job: the bake, the region prepared, then installed unless a newer region stopped it.
  void region_job(const RegionKey& key, RegionWork work, const std::shared_ptr<EditorBox>& current,
                  const std::vector<Transform>& moved_by, const std::stop_token& token) {
    {
      auto lock = acquire();
      span_begin = 0.0;
      span_end = work.bake ? 0.85 : 0.0;
    }
    const std::shared_ptr<EditorBox> next = work.bake ? bake_once(current, moved_by) : current;
    progress("set_region", 0, 1);
    // The method and k are the editor's options for set_region; a failed or stopped job puts
    // them back, so that it leaves the session as it was.
    Editor& editor = next->editor;
    const KHarmonicOptions previous_system = editor.options().system;
    const EditMethod previous_method = editor.options().method;
    const NonlinearEnergy previous_energy = editor.options().nonlinear.energy;
    const auto restore = [&] {
      editor.set_system(previous_system);
      editor.set_method(previous_method);
      editor.set_nonlinear_energy(previous_energy);
    };
    std::optional<Editor::Prepared> prepared;
    try {
      editor.set_system({key.k, previous_system.areas});
      if (!token.stop_requested()) editor.prepare_regions(); // a new k (the load job: the first)
      editor.set_method(key.method);
      editor.set_nonlinear_energy(key.energy);
      if (work.new_region) prepared = editor.prepare_region(key.support, key.handles, token);
    } catch (...) {
      restore();
      throw;
    }
    auto lock = acquire();
    if (token.stop_requested()) { // stale: the newer region is queued
      restore();
      return;
    }
    if (prepared) editor.install_region(std::move(*prepared));
    next->region = key;
    box = next;
    region = key;
    baked.reset();
    baked_from.reset();
    ++region_id;
    if (work.resolve) {
      for (std::size_t j = 0; j < moved_by.size(); ++j)
        box->editor.set_transform(static_cast<int>(j), moved_by[j]);
      shape->set_positions(box->editor.positions());
      shape_behind = false;
      ++positions_id;
    } else {
      transforms.assign(key.handles.size(), identity_transform());
      // A move that went unanswered: the shape shows the new base (the baked move) in full,
      // not only around the new region's movable vertices.
      if (shape_behind) {
        shape->set_positions(box->editor.positions());
        shape_behind = false;
      }
    }
    push_snapshot();
  }
  /// positions(budget) of the editor, as the answer to a move or a relax step. Under the lock.
  Frame frame(double budget_ms, FrameAnswer answer = FrameAnswer::Positions,
              const std::function<bool()>& interrupt = {}) {
    Editor& editor = box->editor;
    const auto t0 = Clock::now();
    Frame f;
    const Eigen::MatrixXd& p = editor.positions(budget_ms, interrupt);
    if (answer == FrameAnswer::Positions || answer == FrameAnswer::PositionsAndBaseOffsets)
      f.positions = movable_floats(editor, p);
    if (answer == FrameAnswer::BaseOffsets || answer == FrameAnswer::PositionsAndBaseOffsets)
      f.base_offsets = frame_base_offsets(editor);
    f.converged = editor.converged();
    f.iterations = editor.report().method == "nonlinear" ? editor.report().nonlinear.iterations : 0;
    f.ms = last_frame_ms = ms_since(t0);
    shape->set_positions(editor.movable_vertices(), p);
    shape_behind = false;
    return f;
  }
  /// report() under the lock, then the options' own progress callback without it. On the worker.
  void progress(std::string_view p, int s, int n) {
    {
      auto lock = acquire();
      report(p, s, n);
    }
    if (options.editor.progress) options.editor.progress(p, s, n);
  }
  EditorOptions editor_options() {
    EditorOptions o = options.editor;
    o.threads = options.threads;
    o.progress = [this](std::string_view p, int s, int n) { progress(p, s, n); };
    return o;
  }
};

Session::Session(SessionOptions options) : impl_(std::make_unique<Impl>()) {
  impl_->options = std::move(options);
}

Session::~Session() {
  if (impl_->worker.joinable()) impl_->worker.join();
}

void Session::wait() {
  auto lock = impl_->acquire();
  impl_->idle.wait(lock, [&] { return !impl_->busy; });
}

std::size_t Session::vertex_count() const {
  auto lock = impl_->acquire();
  return impl_->box ? impl_->box->editor.input().n_vertices() : 0;
}

void Session::wait_for(std::chrono::milliseconds timeout) {
  auto lock = impl_->acquire();
  impl_->idle.wait_for(lock, timeout, [&] { return !impl_->busy; });
}

void Session::start_load(std::string bytes, std::string name) {
  auto lock = impl_->acquire();
  const MeshFormat format = format_from_path(name); // IoError for an unknown extension at once
  impl_->run("load", [this, bytes = std::move(bytes), name, format](std::stop_token) {
    Impl& m = *impl_;
    const auto t0 = Clock::now();
    {
      std::lock_guard guard(m.mutex);
      m.span_begin = 0.0;
      m.span_end = 1.0;
    }
    m.progress("reading", 0, 1);
    LoadResult loaded = read_mesh_from_memory(bytes, format, name, {}, m.options.read);
    auto shape = std::make_shared<Shape>(loaded.mesh);
    auto box = std::make_shared<EditorBox>(Editor(std::move(loaded.mesh), m.editor_options()));
    // The first regions' factors then find warm pages (common/memory.h).
    warm_heap(warm_heap_bytes(box->editor.base().n_vertices(), box->editor.options().system.k));
    // The regions' systems then come from one set of rows and their factors follow one order of
    // the base (docs/solvers.md).
    box->editor.prepare_regions();
    box->preprocess_ms = ms_since(t0);
    std::lock_guard guard(m.mutex);
    m.box = box;
    m.shape = std::move(shape);
    m.shape_behind = false;
    ++m.mesh_id;
    ++m.positions_id;
    ++m.region_id;
    m.name = name;
    m.region.reset();
    m.transforms.clear();
    m.history.clear();
    m.push_snapshot();
  });
}

void Session::start_region(std::vector<int> support, std::vector<std::vector<int>> handles, int k,
                           EditMethod method, std::optional<NonlinearEnergy> energy) {
  auto lock = impl_->acquire();
  Impl& m = *impl_;
  if (!(m.busy && m.job == "region")) m.require_ready(); // a region job: stopped and followed
  if (k < 1 || k > 3) throw InvalidArgument(fmt::format("k = {} is not 1, 2 or 3", k));
  if (handles.size() > static_cast<std::size_t>(m.options.max_handles))
    throw InvalidArgument(fmt::format("{} handles: at most {} are accepted (remora serve "
                                      "--max-handles)",
                                      handles.size(), m.options.max_handles));
  const auto n = static_cast<int>(m.box->editor.input().n_vertices());
  // Longer lists can only repeat ids: refused before any work sized by them.
  const auto too_long = [n](std::size_t size) { return size > static_cast<std::size_t>(n); };
  if (too_long(support.size()) || std::any_of(handles.begin(), handles.end(),
                                              [&](const auto& h) { return too_long(h.size()); }))
    throw InvalidArgument(
        fmt::format("a region lists more ids than the mesh has vertices ({})", n));
  for (const int v : support)
    if (v < 0 || v >= n)
      throw InvalidArgument(fmt::format("support vertex {} is out of range (the mesh has {} "
                                        "vertices)",
                                        v, n));
  for (const auto& h : handles)
    for (const int v : h)
      if (v < 0 || v >= n)
        throw InvalidArgument(fmt::format("handle vertex {} is out of range (the mesh has {} "
                                          "vertices)",
                                          v, n));
  RegionKey key{std::move(support), std::move(handles), k, method,
                energy.value_or(m.options.editor.nonlinear.energy)};
  // Only k or the method changes: the same handles keep their transforms, solved again (no
  // bake), so that a user compares them on the same drag. A new method alone needs no new
  // set_region.
  const bool same_paint =
      m.region && m.region->support == key.support && m.region->handles == key.handles;
  const bool resolve = same_paint && (m.region->k != key.k || m.region->method != key.method ||
                                      m.region->energy != key.energy);
  const bool new_region = !resolve || m.region->k != key.k;
  const bool bake = !resolve && !is_identity(m.transforms);
  m.run("region", [this, key = std::move(key), bake, resolve, new_region, current = m.box,
                   moved_by = m.transforms](std::stop_token token) {
    impl_->region_job(key, {bake, resolve, new_region}, current, moved_by, token);
  });
}

Frame Session::set_transform(int handle, const Transform& transform, FrameAnswer answer) {
  auto lock = impl_->acquire();
  Impl& m = *impl_;
  m.require_region();
  m.require_offsets(answer);
  m.box->editor.set_transform(handle, transform); // validates
  m.transforms[static_cast<std::size_t>(handle)] = transform;
  if (answer != FrameAnswer::None) return m.frame(m.options.frame_budget_ms, answer);
  m.shape_behind = true;
  return {}; // no positions, no frame time
}

Frame Session::relax(double budget_ms, FrameAnswer answer) {
  auto lock = impl_->acquire();
  Impl& m = *impl_;
  m.require_region();
  m.require_offsets(answer);
  if (!(budget_ms > 0.0) || !(budget_ms <= 10000.0))
    throw InvalidArgument("budget_ms: expected milliseconds above 0, at most 10000");
  if (answer == FrameAnswer::None) throw InvalidArgument("a relax step answers something");
  return m.frame(budget_ms, answer, [&m] { return m.waiting > 0; }); // another request first
}

void Session::commit() {
  auto lock = impl_->acquire();
  Impl& m = *impl_;
  m.require_region();
  const Snapshot& s = m.history[m.cursor];
  if (s.box == m.box && s.region == m.region && s.transforms == m.transforms) return;
  m.push_snapshot();
}

bool Session::undo() {
  auto lock = impl_->acquire();
  Impl& m = *impl_;
  m.require_ready();
  if (m.cursor == 0) return false;
  m.apply(m.history[--m.cursor]);
  return true;
}

bool Session::redo() {
  auto lock = impl_->acquire();
  Impl& m = *impl_;
  m.require_ready();
  if (m.cursor + 1 >= m.history.size()) return false;
  m.apply(m.history[++m.cursor]);
  return true;
}

nlohmann::json Session::status() const {
  auto lock = impl_->acquire();
  const Impl& m = *impl_;
  nlohmann::json j;
  j["state"] = m.busy ? "busy" : (m.box ? "ready" : "empty");
  if (m.busy)
    j["progress"] = {{"job", m.job},
                     {"phase", m.phase},
                     {"step", m.step},
                     {"steps", m.steps},
                     {"fraction", m.fraction}};
  j["mesh_id"] = m.mesh_id;
  j["positions_id"] = m.positions_id;
  j["region_id"] = m.region_id;
  if (!m.error.empty()) j["error"] = m.error;
  j["undo"] = !m.busy && m.cursor > 0;
  j["redo"] = !m.busy && m.cursor + 1 < m.history.size();
  // While the worker runs it may be writing the editor: report nothing from it.
  if (!m.box || m.busy) return j;
  const EditReport& r = m.box->editor.report();
  j["mesh"] = {{"name", m.name}, {"vertices", r.input_vertices}, {"faces", r.input_faces}};
  j["base"] = {{"vertices", r.base_vertices},
               {"faces", r.base_faces},
               {"preprocess_ms", m.box->preprocess_ms},
               {"area_rel_mad", r.base_quality.mixed_area.rel_mad},
               {"min_angle_deg", r.base_quality.angles.min_deg},
               {"symmetry_defect", r.base_symmetry_defect}};
  if (m.box->bake)
    j["base"]["bake"] = {{"local", m.box->bake->local},
                         {"fallback", m.box->bake->fallback},
                         {"milliseconds", m.box->bake->milliseconds}};
  j["k"] = m.region ? m.region->k : m.box->editor.options().system.k;
  j["frame_ms"] = m.last_frame_ms;
  if (m.region) {
    j["region"] = {{"support", m.region->support.size()},
                   {"handles", m.region->handles.size()},
                   {"k", m.region->k},
                   {"method", to_string(m.region->method)},
                   {"energy", to_string(m.region->energy)},
                   {"free_base_vertices", r.free_base_vertices},
                   {"set_region_ms",
                    r.milliseconds.count("set_region") ? r.milliseconds.at("set_region") : 0.0},
                   {"set_region_parts_ms", set_region_parts(r)},
                   {"movable", m.box->editor.movable_vertices().size()},
                   {"coarse_support", r.coarse_support}};
    nlohmann::json transforms = nlohmann::json::array();
    for (const Transform& t : m.transforms) {
      std::vector<double> row_major;
      for (int r_ = 0; r_ < 3; ++r_)
        for (int c = 0; c < 4; ++c) row_major.push_back(t(r_, c));
      transforms.push_back(row_major);
    }
    j["transforms"] = transforms;
    if (m.region->method == EditMethod::Nonlinear)
      j["nonlinear"] = {{"iterations", r.nonlinear.total_iterations},
                        {"converged", m.box->editor.converged()},
                        {"fallback", r.fallback}};
  }
  return j;
}

nlohmann::json Session::region() const {
  auto lock = impl_->acquire();
  const Impl& m = *impl_;
  m.require_ready();
  if (!m.region) return nullptr;
  return {{"support", m.region->support},
          {"handles", m.region->handles},
          {"k", m.region->k},
          {"method", to_string(m.region->method)},
          {"energy", to_string(m.region->energy)}};
}

namespace {
/// Rows x, y, z of `p` as interleaved Float32, the API's wire format.
std::vector<float> to_floats(const Eigen::MatrixXd& p) {
  std::vector<float> out(3 * static_cast<std::size_t>(p.rows()));
  for (Eigen::Index v = 0; v < p.rows(); ++v)
    for (int c = 0; c < 3; ++c)
      out[3 * static_cast<std::size_t>(v) + static_cast<std::size_t>(c)] =
          static_cast<float>(p(v, c));
  return out;
}
} // namespace

std::vector<float> Session::positions() const {
  auto lock = impl_->acquire();
  const Impl& m = *impl_;
  m.require_ready();
  Editor& editor = m.box->editor;
  return to_floats(m.region ? editor.positions() : positions_matrix(editor.input()));
}

namespace {
std::vector<std::uint32_t> face_indices(const Mesh& mesh) {
  std::vector<std::uint32_t> out;
  out.reserve(3 * mesh.n_faces());
  for (const FaceHandle f : mesh.faces())
    for (const VertexHandle v : mesh.fv_range(f))
      out.push_back(static_cast<std::uint32_t>(v.idx()));
  return out;
}
} // namespace

std::vector<std::uint32_t> Session::indices() const {
  auto lock = impl_->acquire();
  impl_->require_ready();
  return face_indices(impl_->box->editor.input());
}

std::vector<std::uint32_t> Session::movable_vertices() const {
  auto lock = impl_->acquire();
  impl_->require_ready();
  const auto& movable = impl_->box->editor.movable_vertices();
  return {movable.begin(), movable.end()};
}

FrameExport Session::frame_export() const {
  auto lock = impl_->acquire();
  const Impl& m = *impl_;
  m.require_region();
  return remora::frame_export(m.box->editor);
}

std::vector<float> Session::base_positions() const {
  auto lock = impl_->acquire();
  const Impl& m = *impl_;
  m.require_ready();
  Editor& editor = m.box->editor;
  return to_floats(m.region ? editor.base_positions() : positions_matrix(editor.base()));
}

std::vector<std::uint32_t> Session::base_indices() const {
  auto lock = impl_->acquire();
  impl_->require_ready();
  return face_indices(impl_->box->editor.base());
}

std::vector<float> Session::base_areas() const {
  auto lock = impl_->acquire();
  impl_->require_ready();
  const Eigen::VectorXd a = vertex_areas_mixed(impl_->box->editor.base());
  const double mean = a.size() > 0 ? a.mean() : 1.0;
  std::vector<float> out(static_cast<std::size_t>(a.size()));
  for (Eigen::Index i = 0; i < a.size(); ++i)
    out[static_cast<std::size_t>(i)] = static_cast<float>(a[i] / mean);
  return out;
}

Pick Session::pick(const Vec3& origin, const Vec3& direction, double radius, Brush brush,
                   std::int64_t stroke) {
  auto lock = impl_->acquire();
  if (!impl_->shape) throw Busy("no mesh is loaded yet: load one first");
  Impl& m = *impl_;
  // Not while a job holds the editor: its install brings the shape up to date.
  if (m.shape_behind && m.region && !m.busy) m.frame(m.options.frame_budget_ms);
  return m.shape->pick(origin, direction, radius, brush, stroke);
}

std::string Session::name() const {
  auto lock = impl_->acquire();
  return impl_->name;
}

std::string Session::export_mesh(const std::string& format) const {
  if (format != "obj" && format != "ply" && format != "stl")
    throw InvalidArgument(fmt::format("unknown export format '{}': use obj, ply or stl", format));
  Mesh result;
  {
    auto lock = impl_->acquire();
    impl_->require_ready();
    result = impl_->region ? impl_->box->editor.result() : impl_->box->editor.input();
  }
  const std::string name = "edited." + format;
  return write_mesh_to_memory(result, format_from_path(name), name);
}

} // namespace remora::server
