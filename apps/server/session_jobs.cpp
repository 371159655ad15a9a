// The session's worker (session.h): loading a mesh, region jobs and the bakes before them.
#include <algorithm>
#include <utility>

#include <fmt/format.h>

#include "remora/common/memory.h"
#include "remora/common/timer.h"
#include "remora/mesh/io.h"
#include "remora/multires/bake.h"
#include "session_impl.h"

namespace remora::server {

namespace {

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

} // namespace

/// The job's progress: `phase` at `s` of `n` steps; its fraction of the whole job from the
/// preprocessing shares. Call under the lock.
void Session::Impl::report(std::string_view p, int s, int n) {
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
/// (replacing one queued already); so is any job while the worker finishes a region's
/// nonlinear state; any other overlap throws Busy. Call under the lock.
void Session::Impl::run(std::string what, std::function<void(std::stop_token)> work) {
  relax_on = false;
  if (finishing && !busy) { // the nonlinear build stops; this job follows it
    stop.request_stop();
    pending = std::move(work);
    busy = true;
    job = std::move(what);
    reset_progress();
    return;
  }
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
      // Ended here, not in the job: run() may join the worker once nothing is finishing.
      finishing = false;
      idle.notify_all();
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
void Session::Impl::begin_job() {
  stop = std::stop_source();
  reset_progress();
}

/// No progress and no error yet. Call under the lock.
void Session::Impl::reset_progress() {
  phase = "starting";
  step = steps = 0;
  fraction = 0.0;
  error.clear();
}

/// The editor that `current` under `moved_by` bakes into (the edited shape as a new input), or
/// the one a stopped job made for the same bake.
std::shared_ptr<EditorBox> Session::Impl::bake_once(const std::shared_ptr<EditorBox>& current,
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

/// A region job: the bake, the region prepared, then installed unless a newer region stopped it.
void Session::Impl::region_job(const RegionKey& key, RegionWork work,
                               const std::shared_ptr<EditorBox>& current,
                               const std::vector<Transform>& moved_by,
                               const std::stop_token& token) {
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
    if (work.new_region)
      prepared = editor.prepare_region(key.support, key.handles, token, !work.resolve);
  } catch (...) {
    restore();
    throw;
  }
  auto lock = acquire();
  if (token.stop_requested()) { // stale: the newer region is queued
    restore();
    return;
  }
  Editor::NonlinearBuild build = make_current(next, key, prepared, work.resolve, moved_by);
  push_snapshot();
  if (build.empty()) return;
  build_nonlinear(editor, build, token, lock);
}

/// region_job()'s install, under the lock: `next` with `prepared` (when set) and `key` become the
/// session's editor and region; returns the nonlinear state left to build (or none).
Editor::NonlinearBuild Session::Impl::make_current(const std::shared_ptr<EditorBox>& next,
                                                   const RegionKey& key,
                                                   std::optional<Editor::Prepared>& prepared,
                                                   bool resolve,
                                                   const std::vector<Transform>& moved_by) {
  Editor& editor = next->editor;
  // Method nonlinear: a new region is shown first, its nonlinear state built after.
  Editor::NonlinearBuild build;
  if (prepared) {
    editor.install_region(std::move(*prepared));
    if (!resolve) build = editor.nonlinear_build();
  }
  next->region = key;
  box = next;
  region = key;
  baked.reset();
  baked_from.reset();
  ++region_id;
  if (resolve) {
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
      shape->set_positions(build.empty() ? box->editor.positions()
                                         : box->editor.positions(options.frame_budget_ms));
      shape_behind = false;
    }
  }
  return build;
}

/// region_job()'s end: `build` run with the lock released, then handed to `editor`.
void Session::Impl::build_nonlinear(Editor& editor, Editor::NonlinearBuild& build,
                                    const std::stop_token& token,
                                    std::unique_lock<std::mutex>& lock) {
  // The region is shown (no longer busy); its nonlinear state is built without the lock.
  finishing = true;
  busy = false;
  phase.clear();
  idle.notify_all();
  lock.unlock();
  try {
    build.run(token);
  } catch (const std::exception&) {
    // Not built: the region's next frame builds it, and reports what fails.
  }
  lock = acquire();
  editor.finish_nonlinear(std::move(build)); // `finishing` ends as the worker's job ends
}

/// report() under the lock, then the options' own progress callback without it. On the worker.
void Session::Impl::progress(std::string_view p, int s, int n) {
  {
    auto lock = acquire();
    if (!finishing) report(p, s, n); // a finishing build is no job's progress
  }
  if (options.editor.progress) options.editor.progress(p, s, n);
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

} // namespace remora::server
