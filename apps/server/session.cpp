#include "session.h"

#include <algorithm>
#include <chrono>
#include <exception>
#include <utility>

#include <fmt/format.h>

#include "remora/common/timer.h"
#include "remora/geometry/measures.h"
#include "remora/geometry/quality.h"
#include "remora/linalg/kharmonic.h"
#include "remora/mesh/io.h"
#include "remora/multires/limits.h"
#include "session_impl.h"

namespace remora::server {

namespace {

/// The relaxer's budget per editor.positions() call: a bound, as a request ends the call first.
constexpr double kRelaxerBudgetMs = 10000.0;

/// The movable vertices' rows of `p` as interleaved Float32.
std::vector<float> movable_floats(const Editor& editor, const Eigen::MatrixXd& p) {
  const std::vector<int>& movable = editor.movable_vertices();
  std::vector<float> out(3 * movable.size());
  for (std::size_t i = 0; i < movable.size(); ++i)
    for (int c = 0; c < 3; ++c)
      out[3 * i + static_cast<std::size_t>(c)] = static_cast<float>(p(movable[i], c));
  return out;
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

void Session::Impl::push_snapshot() {
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
void Session::Impl::apply(const Snapshot& s) {
  relax_on = false;
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

/// positions(budget) of the editor, as the answer to a move or a relax step. Under the lock.
Frame Session::Impl::frame(double budget_ms, FrameAnswer answer,
                           const std::function<bool()>& interrupt) {
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

void Session::Impl::relax_loop() {
  std::unique_lock lock(mutex);
  while (!closing) {
    if (!relax_on || busy || finishing || !region) {
      relax_wake.wait(lock);
      continue;
    }
    if (waiting > 0) { // a request first; the lock is free again within its handling
      relax_wake.wait_for(lock, std::chrono::milliseconds(2));
      continue;
    }
    Editor& editor = box->editor;
    if (editor.converged()) {
      relax_on = false;
      continue;
    }
    try {
      editor.positions(kRelaxerBudgetMs, [this] { return waiting > 0 || closing; });
    } catch (const std::exception&) {
      relax_on = false; // the next relax step meets the failure and reports it
    }
    shape_behind = true; // a pick brings the shape up to date
  }
}

Session::Session(SessionOptions options) : impl_(std::make_unique<Impl>()) {
  impl_->options = std::move(options);
  impl_->relaxer = std::thread([m = impl_.get()] { m->relax_loop(); });
}

Session::~Session() {
  impl_->closing = true;
  {
    auto lock = impl_->acquire();
    impl_->stop.request_stop(); // a region's nonlinear build ends early
    impl_->relax_wake.notify_all();
  }
  impl_->relaxer.join();
  if (impl_->worker.joinable()) impl_->worker.join();
}

void Session::wait() {
  auto lock = impl_->acquire();
  impl_->idle.wait(lock, [&] { return !impl_->busy && !impl_->finishing; });
}

std::size_t Session::vertex_count() const {
  auto lock = impl_->acquire();
  return impl_->box ? impl_->box->editor.input().n_vertices() : 0;
}

void Session::wait_for(std::chrono::milliseconds timeout) {
  auto lock = impl_->acquire();
  impl_->idle.wait_for(lock, timeout, [&] { return !impl_->busy; });
}

Frame Session::set_transform(int handle, const Transform& transform, FrameAnswer answer,
                             bool then_relax) {
  auto lock = impl_->acquire();
  Impl& m = *impl_;
  m.require_region();
  m.require_offsets(answer);
  m.box->editor.set_transform(handle, transform); // validates
  m.transforms[static_cast<std::size_t>(handle)] = transform;
  ++m.moves;
  if (m.finishing) m.idle.notify_all(); // a relax step waiting for the nonlinear state answers
  m.relax_on = false;                   // the page relaxes again after its pause
  Frame f;
  if (answer != FrameAnswer::None)
    f = m.frame(m.options.frame_budget_ms, answer);
  else
    m.shape_behind = true;                        // no positions, no frame time
  if (then_relax && !m.box->editor.converged()) { // the relaxer iterates while the answer travels
    m.relax_on = true;
    m.relax_wake.notify_one();
  }
  return f;
}

Frame Session::relax(double budget_ms, FrameAnswer answer) {
  auto lock = impl_->acquire();
  Impl& m = *impl_;
  m.require_region();
  m.require_offsets(answer);
  if (!(budget_ms > 0.0) || !(budget_ms <= 10000.0))
    throw InvalidArgument("budget_ms: expected milliseconds above 0, at most 10000");
  if (answer == FrameAnswer::None) throw InvalidArgument("a relax step answers something");
  const auto t0 = Clock::now();
  if (m.finishing) { // the region's nonlinear state first, within the budget, unless a move comes
    const std::uint64_t moves = m.moves;
    m.idle.wait_for(lock, std::chrono::duration<double, std::milli>(budget_ms),
                    [&m, moves] { return !m.finishing || m.moves != moves; });
    m.require_region(); // a job may have begun meanwhile
    budget_ms = std::max(1.0, budget_ms - ms_since(t0));
  }
  Frame f = m.frame(budget_ms, answer, [&m] { return m.waiting > 0; }); // another request first
  if (!f.converged) { // the relaxer goes on while the answer travels and the next step comes
    m.relax_on = true;
    m.relax_wake.notify_one();
  }
  return f;
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
                        {"preparing", m.finishing},
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
  impl_->await_nonlinear(lock);
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
  impl_->await_nonlinear(lock);
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
    impl_->await_nonlinear(lock);
    impl_->require_ready();
    result = impl_->region ? impl_->box->editor.result() : impl_->box->editor.input();
  }
  const std::string name = "edited." + format;
  return write_mesh_to_memory(result, format_from_path(name), name);
}

} // namespace remora::server
