// The base's report figures updated by a local bake (base_figures.h).
#include "remora/multires/base_figures.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>

#include <fmt/format.h>

#include "remora/common/error.h"
#include "remora/common/parallel.h"
#include "remora/geometry/laplacian.h"
#include "remora/geometry/measures.h"
#include "remora/geometry/per_face.h"
#include "remora/mesh/surface_point.h"

namespace remora {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double degrees(double radians) {
  return radians / std::numbers::pi * 180.0; // as mesh_quality() converts
}

// mesh_quality()'s angle figures as sums and counts over faces.
struct AngleSums {
  double min = kInf, max = -kInf, deviation = 0;
  double below_10 = 0, below_30 = 0, above_90 = 0, above_150 = 0, faces_min_below_10 = 0;
  void add(const std::array<double, 3>& radians, double sign) {
    double face_min = kInf;
    for (const double theta : radians) {
      const double deg = degrees(theta);
      min = std::min(min, deg);
      max = std::max(max, deg);
      face_min = std::min(face_min, deg);
      deviation += sign * std::abs(deg - 60.0);
      below_10 += sign * (deg < 10.0 - kAngleThresholdToleranceDeg);
      below_30 += sign * (deg < 30.0 - kAngleThresholdToleranceDeg);
      above_90 += sign * (deg > 90.0 + kAngleThresholdToleranceDeg);
      above_150 += sign * (deg > 150.0 + kAngleThresholdToleranceDeg);
    }
    faces_min_below_10 += sign * (face_min < 10.0 - kAngleThresholdToleranceDeg);
  }
};

// mesh_quality()'s edge length figures as sums over edges.
struct EdgeSums {
  double min = kInf, max = -kInf, sum = 0, squares = 0;
  void add(double length, double sign) {
    min = std::min(min, length);
    max = std::max(max, length);
    sum += sign * length;
    squares += sign * length * length;
  }
};

std::array<double, 3> angles_of(const Mesh& mesh, FaceHandle f) {
  const auto fv = face_vertices(mesh, f);
  return triangle_angles(mesh.point(fv[0]), mesh.point(fv[1]), mesh.point(fv[2]));
}

// The terms of `faces` (and of their edges, each once) in `mesh`, added with `sign`; how many of
// them are zero-area for a bounding box of diagonal `diagonal`.
double add_faces(const Mesh& mesh, const std::vector<int>& faces, double sign, double diagonal,
                 AngleSums& angles, EdgeSums& edges) {
  std::vector<char> seen(mesh.n_edges(), 0);
  double zero_area = 0;
  for (const int i : faces) {
    const FaceHandle f(i);
    angles.add(angles_of(mesh, f), sign);
    zero_area += is_zero_area(face_area(mesh, f), diagonal) ? 1 : 0;
    for (const HalfedgeHandle h : mesh.fh_range(f)) {
      const auto e = static_cast<std::size_t>(mesh.edge_handle(h).idx());
      if (seen[e]) continue;
      seen[e] = 1;
      edges.add(mesh.calc_edge_length(h), sign);
    }
  }
  return zero_area;
}

// mesh_quality()'s vertex counts and valence histograms over the vertices of `faces` (each once),
// added to `q` with `sign`.
void add_vertex_classes(const Mesh& mesh, const std::vector<int>& faces, long sign,
                        MeshQuality& q) {
  std::vector<char> seen(mesh.n_vertices(), 0);
  const auto step = static_cast<std::size_t>(sign); // modular: -1 subtracts one
  for (const int f : faces)
    for (const VertexHandle v : mesh.fv_range(FaceHandle(f))) {
      if (seen[static_cast<std::size_t>(v.idx())]) continue;
      seen[static_cast<std::size_t>(v.idx())] = 1;
      const int valence = static_cast<int>(mesh.valence(v));
      if (mesh.is_boundary(v)) {
        q.boundary_vertices += step;
        q.valence.boundary[valence] += step;
      } else {
        q.interior_vertices += step;
        q.valence.interior[valence] += step;
      }
    }
}

// The counts and valences of mesh_quality(): the old ones less the old faces' vertices plus the
// new faces'. A vertex on neither keeps its faces, so its valence and side.
void update_valences(const Mesh& old, const MeshQuality& quality, const Mesh& base,
                     const BaseChange& change, MeshQuality& q) {
  q.interior_vertices = quality.interior_vertices;
  q.boundary_vertices = quality.boundary_vertices;
  q.isolated_vertices = quality.isolated_vertices;
  q.valence = quality.valence;
  add_vertex_classes(old, change.old_faces, -1, q);
  add_vertex_classes(base, change.new_faces, 1, q);
  for (auto* histogram : {&q.valence.interior, &q.valence.boundary})
    std::erase_if(*histogram, [](const auto& entry) { return entry.second == 0; });
  const auto count = [](const std::map<int, std::size_t>& h, int valence) {
    const auto it = h.find(valence);
    return it == h.end() ? std::size_t{0} : it->second;
  };
  const auto percent = [](std::size_t part, std::size_t whole) {
    return whole == 0 ? 0.0 : 100.0 * static_cast<double>(part) / static_cast<double>(whole);
  };
  q.valence.percent_interior_6 = percent(count(q.valence.interior, 6), q.interior_vertices);
  q.valence.percent_boundary_4 = percent(count(q.valence.boundary, 4), q.boundary_vertices);
}

} // namespace

BaseStatistics base_statistics(const Mesh& base) {
  BaseStatistics s;
  s.mixed_areas = vertex_areas_mixed(base);
  s.barycentric_areas = vertex_areas_barycentric(base);
  // As laplacian_symmetry_defect() forms them.
  const std::vector<double> weights = cotan_edge_weights(base);
  Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(base.n_vertices()));
  s.rows = diagonal;
  for (const EdgeHandle e : base.edges()) {
    const HalfedgeHandle h = base.halfedge_handle(e, 0);
    const int i = base.from_vertex_handle(h).idx(), j = base.to_vertex_handle(h).idx();
    const double w = weights[static_cast<std::size_t>(e.idx())];
    diagonal[i] -= w;
    diagonal[j] -= w;
    s.rows[i] += w * w;
    s.rows[j] += w * w;
  }
  s.rows += diagonal.cwiseProduct(diagonal);
  return s;
}

double symmetry_defect(const Mesh& base, const BaseStatistics& s) {
  // laplacian_symmetry_defect()'s sum, Σ row_i (Ā − A_i)² / (A_i Ā)² over Σ row_i / A_i², as
  // sums of row_i / A_i², row_i / A_i and row_i.
  double area = 0, n = 0, r2 = 0, r1 = 0, r0 = 0;
  for (const VertexHandle v : base.vertices()) {
    if (base.is_isolated(v)) continue;
    area += s.mixed_areas[v.idx()];
    ++n;
  }
  if (n == 0 || !(area > 0)) return 0.0;
  const double mean = area / n;
  for (const VertexHandle v : base.vertices()) {
    const double a = s.mixed_areas[v.idx()];
    if (base.is_isolated(v) || !(a > 0)) continue;
    const double row = s.rows[v.idx()];
    r2 += row / (a * a);
    r1 += row / a;
    r0 += row;
  }
  const double difference = r2 - 2 * r1 / mean + r0 / (mean * mean);
  return r2 > 0 ? std::sqrt(std::max(0.0, difference) / r2) : 0.0;
}

VertexFigures update_vertex_figures(const BaseStatistics& statistics, const Mesh& base,
                                    const BaseChange& change, const KHarmonicAssembler& assembler,
                                    BaseStatistics& s, int threads) {
  const auto n = static_cast<Eigen::Index>(base.n_vertices());
  if (static_cast<Eigen::Index>(assembler.vertex_count()) != n)
    throw InvalidArgument(fmt::format("update_vertex_figures: the assembler has {} vertices, the "
                                      "base {}; pass the new base's assembler",
                                      assembler.vertex_count(), n));
  // The mixed areas and the rows of −W are the assembler's; the barycentric areas are carried
  // over, then measured again around the new faces.
  s.mixed_areas = assembler.areas();
  const SparseMatrix& minus_w = assembler.minus_w();
  s.rows.resize(n);
  parallel_for(static_cast<std::size_t>(n), threads, [&](std::size_t v) {
    const auto c = static_cast<Eigen::Index>(v);
    s.rows[c] = minus_w.col(c).squaredNorm();
  });
  s.barycentric_areas.resize(n);
  for (Eigen::Index v = 0; v < statistics.barycentric_areas.size(); ++v) {
    const int to = change.vertex_map.empty() ? static_cast<int>(v)
                                             : change.vertex_map[static_cast<std::size_t>(v)];
    if (to >= 0) s.barycentric_areas[to] = statistics.barycentric_areas[v];
  }
  std::vector<char> done(base.n_vertices(), 0);
  for (const int f : change.new_faces)
    for (const VertexHandle v : base.fv_range(FaceHandle(f))) {
      if (done[static_cast<std::size_t>(v.idx())]) continue;
      done[static_cast<std::size_t>(v.idx())] = 1;
      double barycentric = 0;
      for (const FaceHandle g : base.vf_range(v)) barycentric += face_area(base, g) / 3.0;
      s.barycentric_areas[v.idx()] = barycentric;
    }
  std::vector<VertexHandle> interior;
  for (const VertexHandle v : base.vertices())
    if (!base.is_isolated(v) && !base.is_boundary(v)) interior.push_back(v);
  return {vertex_area_figures(s.mixed_areas, interior),
          vertex_area_figures(s.barycentric_areas, interior), symmetry_defect(base, s)};
}

void update_mesh_figures(const Mesh& old, const MeshQuality& quality, const Mesh& base,
                         const BaseChange& change, MeshQuality& q) {
  q = MeshQuality{};
  q.vertices = base.n_vertices();
  q.faces = base.n_faces();
  q.edges = base.n_edges();
  q.boundary_loops = quality.boundary_loops;
  q.components = quality.components;
  q.component_topology = quality.component_topology;
  update_valences(old, quality, base, change, q);
  q.bounding_box = bounding_box(base);
  q.bounding_box_diagonal = q.bounding_box.diagonal();

  // Angles and edges: the old sums less the old faces' terms, plus the new faces'.
  const double angles = 3.0 * static_cast<double>(quality.faces);
  const AngleFigures& a = quality.angles;
  AngleSums sums;
  sums.deviation = a.mean_abs_deviation_from_60_deg * angles;
  sums.below_10 = std::round(a.percent_below_10 * angles / 100.0);
  sums.below_30 = std::round(a.percent_below_30 * angles / 100.0);
  sums.above_90 = std::round(a.percent_above_90 * angles / 100.0);
  sums.above_150 = std::round(a.percent_above_150 * angles / 100.0);
  sums.faces_min_below_10 =
      std::round(a.percent_faces_min_below_10 * static_cast<double>(quality.faces) / 100.0);
  const EdgeLengthFigures& l = quality.edge_length;
  const double edges = static_cast<double>(quality.edges);
  EdgeSums lengths;
  lengths.sum = l.mean * edges;
  lengths.squares = edges * (std::pow(l.cv * l.mean, 2) + l.mean * l.mean);
  double zero = static_cast<double>(quality.zero_area_faces);
  zero -= add_faces(old, change.old_faces, -1.0, quality.bounding_box_diagonal, sums, lengths);
  const AngleSums gone = sums;
  const EdgeSums gone_lengths = lengths;
  sums.min = lengths.min = kInf;
  sums.max = lengths.max = -kInf;
  zero += add_faces(base, change.new_faces, 1.0, q.bounding_box_diagonal, sums, lengths);
  q.zero_area_faces = static_cast<std::size_t>(std::max(0.0, zero));
  // The extremes: the old ones stand unless they lay on a face that went.
  double min_deg = std::min(a.min_deg, sums.min), max_deg = std::max(a.max_deg, sums.max);
  if (gone.min <= a.min_deg || gone.max >= a.max_deg) {
    const auto all =
        per_face<std::array<double, 3>>(base, [&](FaceHandle f) { return angles_of(base, f); });
    min_deg = kInf;
    max_deg = -kInf;
    for (const auto& t : all)
      for (const double theta : t) {
        min_deg = std::min(min_deg, degrees(theta));
        max_deg = std::max(max_deg, degrees(theta));
      }
  }
  double min_length = std::min(l.min, lengths.min), max_length = std::max(l.max, lengths.max);
  if (gone_lengths.min <= l.min || gone_lengths.max >= l.max) {
    min_length = kInf;
    max_length = -kInf;
    for (const EdgeHandle e : base.edges()) {
      min_length = std::min(min_length, base.calc_edge_length(e));
      max_length = std::max(max_length, base.calc_edge_length(e));
    }
  }
  const double new_count = 3.0 * static_cast<double>(q.faces);
  auto percent = [](double part, double whole) { return whole > 0 ? 100.0 * part / whole : 0.0; };
  q.angles = {min_deg,
              max_deg,
              sums.deviation / new_count,
              percent(sums.below_10, new_count),
              percent(sums.below_30, new_count),
              percent(sums.above_90, new_count),
              percent(sums.above_150, new_count),
              percent(sums.faces_min_below_10, static_cast<double>(q.faces))};
  const double e = static_cast<double>(q.edges);
  const double mean = lengths.sum / e;
  q.edge_length = {mean, std::sqrt(std::max(0.0, lengths.squares / e - mean * mean)) / mean,
                   min_length, max_length};
}

} // namespace remora
