#include "report.h"

#include <map>

#include <fmt/format.h>

namespace remora::cli {

namespace {

// One row of the two-column table.
void row(std::ostream& os, const std::string& label, const std::string& text) {
  os << fmt::format("{:<13}{}\n", label, text);
}

std::string histogram(const std::map<int, std::size_t>& h) {
  std::string s;
  for (const auto& [valence, count] : h) s += fmt::format("{}:{} ", valence, grouped(count));
  if (!s.empty()) s.pop_back();
  return s.empty() ? "-" : s;
}

} // namespace

void print_load_report(std::ostream& os, const LoadReport& r) {
  row(os, "file", fmt::format("{} ({}, {})", r.path, r.file.format, r.file.encoding));
  row(os, "in file",
      fmt::format("{} vertices, {} faces", grouped(r.file.vertices_in_file),
                  grouped(r.file.faces_in_file)));
  for (std::size_t i = 0; i < r.file.skipped.size(); ++i)
    row(os, i == 0 ? "skipped" : "", r.file.skipped[i]);
  const std::vector<std::string> repairs = describe(r.repair);
  if (repairs.empty()) row(os, "repair", "nothing to repair");
  for (std::size_t i = 0; i < repairs.size(); ++i) row(os, i == 0 ? "repair" : "", repairs[i]);
  row(os, "loaded",
      fmt::format("{} vertices, {} faces ({} component{} sharing vertices in the file)",
                  grouped(r.repair.vertices_loaded), grouped(r.repair.faces_loaded),
                  r.repair.components_in, r.repair.components_in == 1 ? "" : "s"));
}

void print_quality(std::ostream& os, const MeshQuality& q) {
  row(os, "mesh",
      fmt::format("V {}  F {}  E {}", grouped(q.vertices), grouped(q.faces), grouped(q.edges)));
  std::map<int, std::size_t> genus;
  std::size_t closed = 0;
  for (const ComponentTopology& c : q.component_topology) {
    ++genus[c.genus];
    closed += c.closed ? 1 : 0;
  }
  std::string genera;
  for (const auto& [g, n] : genus)
    genera += fmt::format("{}genus {} x{}", genera.empty() ? "" : ", ", g, n);
  row(os, "topology",
      fmt::format("{} component{} ({} closed; {}), {} boundary loop{}", q.components,
                  q.components == 1 ? "" : "s", closed, genera.empty() ? "-" : genera,
                  q.boundary_loops, q.boundary_loops == 1 ? "" : "s"));
  const AngleFigures& a = q.angles;
  row(os, "angles",
      fmt::format("min {:.3g} deg  max {:.4g} deg  mean |theta-60| {:.3g} deg", a.min_deg,
                  a.max_deg, a.mean_abs_deviation_from_60_deg));
  row(os, "",
      fmt::format("<10: {:.2f}%  <30: {:.2f}%  >90: {:.2f}%  >150: {:.2f}% (of all angles)",
                  a.percent_below_10, a.percent_below_30, a.percent_above_90, a.percent_above_150));
  row(os, "valence",
      fmt::format("interior {}  ({:.1f}% are 6)", histogram(q.valence.interior),
                  q.valence.percent_interior_6));
  row(os, "",
      fmt::format("boundary {}  ({:.1f}% are 4)", histogram(q.valence.boundary),
                  q.valence.percent_boundary_4));
  row(os, "edge length",
      fmt::format("mean {:.4g}  cv {:.3f}  min {:.3g}  max {:.3g}", q.edge_length.mean,
                  q.edge_length.cv, q.edge_length.min, q.edge_length.max));
  row(os, "vertex area",
      fmt::format("mixed Voronoi: rel std {:.3f}  rel MAD {:.3f}   (interior, mean {:.3g})",
                  q.mixed_area.rel_std, q.mixed_area.rel_mad, q.mixed_area.mean));
  row(os, "",
      fmt::format("barycentric:   rel std {:.3f}  rel MAD {:.3f}", q.barycentric_area.rel_std,
                  q.barycentric_area.rel_mad));
  row(os, "zero-area", fmt::format("{} faces", grouped(q.zero_area_faces)));
  const BoundingBox& b = q.bounding_box;
  row(os, "bounding box",
      fmt::format("[{:.4g}, {:.4g}, {:.4g}] .. [{:.4g}, {:.4g}, {:.4g}], diagonal {:.4g}", b.min[0],
                  b.min[1], b.min[2], b.max[0], b.max[1], b.max[2], q.bounding_box_diagonal));
}

std::string capped_sigma_line(std::size_t vertices, double sigma_min, std::size_t loops) {
  std::string line = "sigma lowered";
  if (vertices > 0)
    line +=
        fmt::format(" at {} vertices of thin parts (down to {:.4g})", grouped(vertices), sigma_min);
  if (loops > 0)
    line += fmt::format("{} on {} small boundary loop{}", vertices > 0 ? " and" : "",
                        grouped(loops), loops == 1 ? "" : "s");
  return line;
}

} // namespace remora::cli
