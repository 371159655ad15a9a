#include "remora/geometry/quality.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <limits>
#include <numbers>

#include <nlohmann/json.hpp>

#include "remora/geometry/per_face.h"

namespace remora {
namespace {

// Number of elements in an OpenMesh range (the skipping ranges leave deleted elements out).
std::size_t count(const auto& range) {
  return static_cast<std::size_t>(std::distance(range.begin(), range.end()));
}

double percent(std::size_t part, std::size_t whole) {
  return whole == 0 ? 0.0 : 100.0 * static_cast<double>(part) / static_cast<double>(whole);
}

// Dividing by pi before multiplying by 180 keeps pi/2, pi/4 and pi exactly 90, 45 and 180.
double degrees(double radians) {
  return radians / std::numbers::pi * 180.0;
}

bool below(double deg, double threshold) {
  return deg < threshold - kAngleThresholdToleranceDeg;
}
bool above(double deg, double threshold) {
  return deg > threshold + kAngleThresholdToleranceDeg;
}

AngleFigures angle_figures(const Mesh& mesh) {
  AngleFigures figures;
  double min_deg = std::numeric_limits<double>::infinity();
  double max_deg = -std::numeric_limits<double>::infinity();
  double deviation_sum = 0.0;
  std::size_t angles = 0;
  std::size_t faces = 0;
  std::size_t below_10 = 0;
  std::size_t below_30 = 0;
  std::size_t above_90 = 0;
  std::size_t above_150 = 0;
  std::size_t faces_min_below_10 = 0;
  const auto face_angles = per_face<std::array<double, 3>>(mesh, [&](FaceHandle f) {
    auto v = mesh.cfv_iter(f);
    const Vec3& a = mesh.point(*v);
    const Vec3& b = mesh.point(*++v);
    const Vec3& c = mesh.point(*++v);
    return triangle_angles(a, b, c);
  });
  for (const FaceHandle f : mesh.faces()) {
    double face_min = std::numeric_limits<double>::infinity();
    for (const double theta : face_angles[static_cast<std::size_t>(f.idx())]) {
      const double deg = degrees(theta);
      min_deg = std::min(min_deg, deg);
      max_deg = std::max(max_deg, deg);
      face_min = std::min(face_min, deg);
      deviation_sum += std::abs(deg - 60.0);
      ++angles;
      below_10 += below(deg, 10.0) ? 1 : 0;
      below_30 += below(deg, 30.0) ? 1 : 0;
      above_90 += above(deg, 90.0) ? 1 : 0;
      above_150 += above(deg, 150.0) ? 1 : 0;
    }
    ++faces;
    faces_min_below_10 += below(face_min, 10.0) ? 1 : 0;
  }
  if (angles == 0) return figures;
  figures.min_deg = min_deg;
  figures.max_deg = max_deg;
  figures.mean_abs_deviation_from_60_deg = deviation_sum / static_cast<double>(angles);
  figures.percent_below_10 = percent(below_10, angles);
  figures.percent_below_30 = percent(below_30, angles);
  figures.percent_above_90 = percent(above_90, angles);
  figures.percent_above_150 = percent(above_150, angles);
  figures.percent_faces_min_below_10 = percent(faces_min_below_10, faces);
  return figures;
}

EdgeLengthFigures edge_length_figures(const Mesh& mesh) {
  EdgeLengthFigures figures;
  std::vector<double> lengths(mesh.n_edges(), -1.0);
  parallel_for(lengths.size(), 0, [&](std::size_t i) {
    const EdgeHandle e(static_cast<int>(i));
    if (!mesh.status(e).deleted()) lengths[i] = mesh.calc_edge_length(e);
  });
  lengths.erase(std::remove(lengths.begin(), lengths.end(), -1.0), lengths.end());
  if (lengths.empty()) return figures;
  const auto [min_it, max_it] = std::minmax_element(lengths.begin(), lengths.end());
  figures.min = *min_it;
  figures.max = *max_it;
  const double n = static_cast<double>(lengths.size());
  double sum = 0.0;
  for (const double l : lengths) sum += l;
  figures.mean = sum / n;
  double squares = 0.0; // second pass: no cancellation
  for (const double l : lengths) squares += (l - figures.mean) * (l - figures.mean);
  figures.cv = figures.mean > 0.0 ? std::sqrt(squares / n) / figures.mean : 0.0;
  return figures;
}

} // namespace

VertexAreaFigures vertex_area_figures(const Eigen::VectorXd& areas,
                                      const std::vector<VertexHandle>& interior) {
  VertexAreaFigures figures;
  if (interior.empty()) return figures;
  const double n = static_cast<double>(interior.size());
  double sum = 0.0;
  for (const VertexHandle v : interior) sum += areas[v.idx()];
  figures.mean = sum / n;
  if (!(figures.mean > 0.0)) return figures;
  double squares = 0.0;
  double absolute = 0.0;
  for (const VertexHandle v : interior) {
    const double d = areas[v.idx()] - figures.mean;
    squares += d * d;
    absolute += std::abs(d);
  }
  figures.rel_std = std::sqrt(squares / n) / figures.mean;
  figures.rel_mad = absolute / n / figures.mean;
  return figures;
}

namespace {

nlohmann::json histogram_json(const std::map<int, std::size_t>& histogram) {
  nlohmann::json array = nlohmann::json::array();
  for (const auto& [valence, count] : histogram) {
    array.push_back({{"valence", valence}, {"count", count}});
  }
  return array;
}

nlohmann::json area_json(const VertexAreaFigures& figures) {
  return {{"mean", figures.mean}, {"rel_std", figures.rel_std}, {"rel_mad", figures.rel_mad}};
}

nlohmann::json point_json(const Vec3& p) {
  return nlohmann::json::array({p[0], p[1], p[2]});
}

} // namespace

double percent_edges_within(const Mesh& mesh, double lo, double hi) {
  std::size_t edges = 0, within = 0;
  for (const EdgeHandle e : mesh.edges()) {
    const double length = mesh.calc_edge_length(e);
    ++edges;
    if (length >= lo && length <= hi) ++within;
  }
  return edges > 0 ? 100.0 * static_cast<double>(within) / static_cast<double>(edges) : 0.0;
}

void vertex_figures(const Mesh& mesh, MeshQuality& q, std::vector<VertexHandle>& interior) {
  std::size_t interior_6 = 0;
  std::size_t boundary_4 = 0;
  for (const VertexHandle v : mesh.vertices()) {
    if (mesh.is_isolated(v)) {
      ++q.isolated_vertices;
      continue;
    }
    const int valence = static_cast<int>(mesh.valence(v));
    if (mesh.is_boundary(v)) {
      ++q.boundary_vertices;
      ++q.valence.boundary[valence];
      boundary_4 += valence == 4 ? 1 : 0;
    } else {
      interior.push_back(v);
      ++q.valence.interior[valence];
      interior_6 += valence == 6 ? 1 : 0;
    }
  }
  q.interior_vertices = interior.size();
  q.valence.percent_interior_6 = percent(interior_6, q.interior_vertices);
  q.valence.percent_boundary_4 = percent(boundary_4, q.boundary_vertices);
}

MeshQuality mesh_quality(const Mesh& mesh, const QualityOptions& options) {
  MeshQuality q;

  // Counts and topology.
  q.vertices = count(mesh.vertices());
  q.faces = count(mesh.faces());
  q.edges = count(mesh.edges());
  if (options.topology) {
    q.boundary_loops = boundary_loops(mesh).size();
    q.component_topology = component_topology(mesh);
    q.components = q.component_topology.size();
  }

  std::vector<VertexHandle> interior;
  vertex_figures(mesh, q, interior);
  q.angles = angle_figures(mesh);
  q.edge_length = edge_length_figures(mesh);
  q.barycentric_area = vertex_area_figures(vertex_areas_barycentric(mesh), interior);
  q.mixed_area = vertex_area_figures(vertex_areas_mixed(mesh), interior);

  q.bounding_box = bounding_box(mesh);
  q.bounding_box_diagonal = q.bounding_box.diagonal();
  const std::vector<double> areas =
      per_face<double>(mesh, [&](FaceHandle f) { return face_area(mesh, f); });
  for (const FaceHandle f : mesh.faces())
    q.zero_area_faces +=
        is_zero_area(areas[static_cast<std::size_t>(f.idx())], q.bounding_box_diagonal) ? 1 : 0;
  return q;
}

nlohmann::json to_json(const MeshQuality& q) {
  nlohmann::json components = nlohmann::json::array();
  for (const ComponentTopology& c : q.component_topology) {
    components.push_back({{"vertices", c.vertices},
                          {"edges", c.edges},
                          {"faces", c.faces},
                          {"boundary_loops", c.boundary_loops},
                          {"euler", c.euler},
                          {"genus", c.genus},
                          {"closed", c.closed}});
  }
  const AngleFigures& a = q.angles;
  const EdgeLengthFigures& l = q.edge_length;
  return {
      {"vertices", q.vertices},
      {"faces", q.faces},
      {"edges", q.edges},
      {"boundary_loops", q.boundary_loops},
      {"components", q.components},
      {"interior_vertices", q.interior_vertices},
      {"boundary_vertices", q.boundary_vertices},
      {"isolated_vertices", q.isolated_vertices},
      {"component_topology", components},
      {"angles",
       {{"min_deg", a.min_deg},
        {"max_deg", a.max_deg},
        {"mean_abs_deviation_from_60_deg", a.mean_abs_deviation_from_60_deg},
        {"percent_below_10", a.percent_below_10},
        {"percent_below_30", a.percent_below_30},
        {"percent_above_90", a.percent_above_90},
        {"percent_above_150", a.percent_above_150},
        {"percent_faces_min_below_10", a.percent_faces_min_below_10}}},
      {"valence",
       {{"interior", histogram_json(q.valence.interior)},
        {"boundary", histogram_json(q.valence.boundary)},
        {"percent_interior_6", q.valence.percent_interior_6},
        {"percent_boundary_4", q.valence.percent_boundary_4}}},
      {"edge_length", {{"mean", l.mean}, {"cv", l.cv}, {"min", l.min}, {"max", l.max}}},
      {"vertex_area_barycentric", area_json(q.barycentric_area)},
      {"vertex_area_mixed", area_json(q.mixed_area)},
      {"zero_area_faces", q.zero_area_faces},
      {"bounding_box",
       {{"min", point_json(q.bounding_box.min)},
        {"max", point_json(q.bounding_box.max)},
        {"diagonal", q.bounding_box_diagonal}}},
  };
}

} // namespace remora
