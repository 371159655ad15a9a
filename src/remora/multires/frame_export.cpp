// frame_export() of frame_export.h.
#include "remora/multires/frame_export.h"

#include <algorithm>
#include <limits>

#include "remora/common/error.h"
#include "remora/multires/editor_detail.h"
#include "remora/multires/frame_replay.h"

namespace remora {

namespace {

constexpr std::uint32_t kUnset = std::numeric_limits<std::uint32_t>::max();

/// A numbering of some of `count` items in the order they are first met.
class LocalIds {
public:
  explicit LocalIds(std::size_t count) : local_(count, kUnset) {}
  std::uint32_t operator()(int id) {
    std::uint32_t& l = local_[static_cast<std::size_t>(id)];
    if (l == kUnset) {
      l = static_cast<std::uint32_t>(order_.size());
      order_.push_back(id);
    }
    return l;
  }
  const std::vector<int>& order() const { return order_; }

private:
  std::vector<std::uint32_t> local_;
  std::vector<int> order_;
};

std::vector<std::uint32_t> as_unsigned(const std::vector<int>& v) {
  return {v.begin(), v.end()};
}

} // namespace

FrameExport frame_export(const Editor& editor) {
  const Editor::Impl& m = *editor.impl_;
  if (!m.region) throw InvalidArgument("no region yet: call set_region() first");
  const bool nonlinear = m.options.method == EditMethod::Nonlinear;
  const bool blended = nonlinear && m.options.nonlinear.energy == NonlinearEnergy::BlendedMotions;
  const RegionState& r = *m.region;
  const NormalPlan& plan = r.affected;
  const FrameDetails& details = r.details;
  FrameExport out;
  out.handles = r.handles;
  out.blended = blended;
  out.corrected = nonlinear && !blended;

  // Faces: the normals' faces first (ring indexes them as they are), then the decode's.
  LocalIds face_ids(m.topology.faces.size()),
      vertex_ids(static_cast<std::size_t>(m.base_rest.rows()));
  for (const int f : plan.faces) face_ids(f);
  out.record_face.reserve(details.records.size());
  for (const FrameDetails::Record& rec : details.records)
    out.record_face.push_back(face_ids(rec.face));
  out.faces.reserve(3 * face_ids.order().size());
  for (const int f : face_ids.order())
    for (const int v : m.topology.faces[static_cast<std::size_t>(f)])
      out.faces.push_back(vertex_ids(v));
  for (const int v : plan.vertices) out.normal_vertices.push_back(vertex_ids(v));
  out.ring_begin = as_unsigned(plan.ring_begin);
  out.ring = as_unsigned(plan.ring);
  for (const int v : r.free_vertices) out.free_local.push_back(vertex_ids(v));
  out.handle_begin.push_back(0);
  for (const std::vector<int>& handle : r.handle_base) {
    for (const int v : handle) out.handle_local.push_back(vertex_ids(v));
    out.handle_begin.push_back(static_cast<std::uint32_t>(out.handle_local.size()));
  }
  out.rest.reserve(6 * vertex_ids.order().size());
  for (const int v : vertex_ids.order()) {
    for (int c = 0; c < 3; ++c) out.rest.push_back(static_cast<float>(r.rest(v, c)));
    // The frame's normals: B0's where no frame changes them (the others step 2 computes).
    for (int c = 3; c < 6; ++c) out.rest.push_back(static_cast<float>(r.frame(v, c)));
  }
  out.basis.assign(r.basis.data(), r.basis.data() + r.basis.size()); // row-major

  const std::size_t n = details.records.size();
  out.record_bary.reserve(3 * n);
  out.record_offset.reserve(n);
  out.record_residual.reserve(n);
  out.record_slot.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const FrameDetails::Record& rec = details.records[i];
    for (const double b : rec.bary) out.record_bary.push_back(static_cast<float>(b));
    out.record_offset.push_back(static_cast<float>(rec.offset));
    out.record_residual.push_back(rec.residual);
    const auto at = std::lower_bound(r.encoded.begin(), r.encoded.end(), details.outputs[i]);
    out.record_slot.push_back(static_cast<std::uint32_t>(at - r.encoded.begin()));
  }
  for (const auto& res : details.residuals)
    for (const double x : res) out.residuals.push_back(static_cast<float>(x));
  for (const Eigen::Vector3d& o : details.offsets)
    for (int c = 0; c < 3; ++c) out.offsets.push_back(static_cast<float>(o[c]));
  return out;
}

std::vector<float> frame_base_offsets(const Editor& editor) {
  const Editor::Impl& m = *editor.impl_;
  if (!m.region) throw InvalidArgument("no region yet: call set_region() first");
  if (m.options.method == EditMethod::Nonlinear &&
      m.options.nonlinear.energy == NonlinearEnergy::BlendedMotions)
    throw InvalidArgument("the energy blended-motions has no row offsets: its frames blend the "
                          "handles' motions, not the basis functions");
  const RegionState& r = *m.region;
  if (r.dirty)
    throw InvalidArgument("a transform was set after the last frame: call positions() first");
  std::vector<double> transforms;
  for (const Transform& t : r.transforms)
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 4; ++col) transforms.push_back(t(row, col));
  const auto columns = static_cast<std::size_t>(r.basis.cols());
  const auto handles = static_cast<std::uint32_t>(r.handles);
  std::vector<float> out(3 * r.free_vertices.size());
  std::vector<float> row(columns);
  for (std::size_t i = 0; i < r.free_vertices.size(); ++i) {
    const double* b = r.basis.data() + i * columns; // row-major
    for (std::size_t c = 0; c < columns; ++c) row[c] = static_cast<float>(b[c]);
    double p[3];
    replay_blend_row(row.data(), handles, transforms.data(), p);
    for (int c = 0; c < 3; ++c)
      out[3 * i + static_cast<std::size_t>(c)] =
          static_cast<float>(r.frame(r.free_vertices[i], c) - p[c]);
  }
  return out;
}

} // namespace remora
