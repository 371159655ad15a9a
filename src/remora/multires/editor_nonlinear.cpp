// Method nonlinear's state of a region (multires/nonlinear_region.h): its deformers from B0, the
// labels and the handles' scalar weights, and for a large support the coarse level of its
// preview. Built by set_region, by the first frame after set_method(), or apart from both
// (Editor::NonlinearBuild: a server shows the region first).
#include <map>
#include <memory>
#include <string>
#include <utility>

#include "remora/common/error.h"
#include "remora/common/timer.h"
#include "remora/multires/editor_detail.h"

namespace remora {

struct Editor::NonlinearBuild::State {
  Editor::Impl* editor = nullptr; // reads its preprocessed parts only
  std::uint64_t serial = 0;       // the region captured
  NonlinearOptions options;       // the editor's, with its threads
  Eigen::MatrixXd rest, weights;  // B0; the handles' scalar weights (n × h)
  std::vector<int> labels, free_vertices;
  std::shared_ptr<const RemeshResult> coarse; // the editor's coarse level at the capture
  // The result: the state, the coarse level it uses (new or the one captured), the times.
  std::unique_ptr<NonlinearRegion> nonlinear;
  std::shared_ptr<const RemeshResult> made_coarse;
  std::map<std::string, double> milliseconds;
  bool built = false;
  bool apart = false; // nonlinear_build()'s, not set_region's or a frame's
};

std::unique_ptr<Editor::NonlinearBuild::State>
Editor::Impl::capture_nonlinear(const RegionState& r) {
  auto s = std::make_unique<NonlinearBuild::State>();
  s->editor = this;
  s->serial = r.serial;
  s->options = options.nonlinear;
  s->options.threads = options.threads;
  // The handles' scalar weights: the basis functions' "1" columns, and 1 on each handle.
  s->weights = Eigen::MatrixXd::Zero(r.rest.rows(), r.handles);
  for (std::size_t row = 0; row < r.free_vertices.size(); ++row)
    for (int j = 0; j < r.handles; ++j)
      s->weights(r.free_vertices[row], j) =
          static_cast<double>(r.basis(static_cast<Eigen::Index>(row), 3 + 4 * j + 3));
  for (int j = 0; j < r.handles; ++j)
    for (const int v : r.handle_base[static_cast<std::size_t>(j)]) s->weights(v, j) = 1.0;
  s->rest = r.rest;
  s->labels = r.base_label;
  s->free_vertices = r.free_vertices;
  s->coarse = coarse;
  return s;
}

// For a large support, the coarse base of its preview: a remesh of the support's part of the
// base, the editor's last one while the support lies in it at about the same coarse edge length.
void Editor::NonlinearBuild::run(const std::stop_token& stop) {
  if (!state_ || state_->built) return;
  State& s = *state_;
  Editor::Impl& m = *s.editor;
  if (s.apart) m.progress("nonlinear state", 0, 1); // not in a frame: under a caller's lock
  const auto t0 = Clock::now();
  // Propagated rotations take one solve per frame, blended motions none: no preview.
  const NonlinearEnergy energy = s.options.energy;
  const bool preview = energy != NonlinearEnergy::PropagatedRotations &&
                       energy != NonlinearEnergy::BlendedMotions &&
                       s.options.preview_vertices > 0 &&
                       s.free_vertices.size() > 2 * std::size_t(s.options.preview_vertices);
  if (preview) {
    const double length = m.mean_base_length();
    s.made_coarse = s.coarse;
    if (!s.made_coarse || !coarse_base_serves(*s.made_coarse, m.base, m.topology, length,
                                              s.free_vertices, s.options)) {
      if (stop.stop_requested()) return;
      const auto t1 = Clock::now();
      try {
        s.made_coarse = std::make_shared<const RemeshResult>(
            make_coarse_base(m.base, m.topology, m.base_rest, length, s.free_vertices, s.options));
      } catch (const Error&) { // no preview: the fine level alone, which works
        s.made_coarse.reset();
      }
      s.milliseconds["nonlinear coarse base"] = ms_since(t1);
    }
  }
  if (stop.stop_requested()) return;
  s.nonlinear = std::make_unique<NonlinearRegion>(m.base, preview ? s.made_coarse.get() : nullptr,
                                                  s.rest, s.labels, s.weights, s.options);
  s.milliseconds["nonlinear setup"] = ms_since(t0);
  s.built = true;
}

void Editor::Impl::adopt_nonlinear(RegionState& r, NonlinearBuild::State& built, EditReport& into) {
  r.nonlinear_energy = built.options.energy;
  r.nonlinear = std::move(built.nonlinear);
  r.coarse = std::move(built.made_coarse);
  for (const auto& [key, ms] : built.milliseconds) into.milliseconds[key] = ms;
  r.dirty = true; // the state starts from the identity: the next frame sets the transforms
}

void Editor::Impl::build_nonlinear(RegionState& r, EditReport& into) {
  NonlinearBuild build;
  build.state_ = capture_nonlinear(r);
  build.run();
  adopt_nonlinear(r, *build.state_, into);
}

Editor::NonlinearBuild::NonlinearBuild() = default;
Editor::NonlinearBuild::NonlinearBuild(NonlinearBuild&&) noexcept = default;
Editor::NonlinearBuild& Editor::NonlinearBuild::operator=(NonlinearBuild&&) noexcept = default;
Editor::NonlinearBuild::~NonlinearBuild() = default;

bool Editor::NonlinearBuild::empty() const {
  return !state_;
}

Editor::NonlinearBuild Editor::nonlinear_build() {
  Impl& m = *impl_;
  NonlinearBuild build;
  if (!m.region || m.options.method != EditMethod::Nonlinear || !m.needs_nonlinear(*m.region))
    return build;
  m.region->nonlinear_deferred = true;
  build.state_ = m.capture_nonlinear(*m.region);
  build.state_->apart = true;
  return build;
}

void Editor::finish_nonlinear(NonlinearBuild&& build) {
  Impl& m = *impl_;
  if (!build.state_ || build.state_->editor != &m) return;
  NonlinearBuild::State& s = *build.state_;
  RegionState* r = m.region && m.region->serial == s.serial ? m.region.get() : nullptr;
  for (const auto& kept : m.recent)
    if (!r && kept->serial == s.serial) r = kept.get();
  if (!r) return; // dropped meanwhile
  r->nonlinear_deferred = false;
  if (!s.built || (r->nonlinear && r->nonlinear_energy == s.options.energy)) return;
  m.adopt_nonlinear(*r, s, r->report);
  if (r->coarse) m.coarse = r->coarse;
  if (r == m.region.get())
    for (const auto& [key, ms] : s.milliseconds) m.report.milliseconds[key] = ms;
}

} // namespace remora
