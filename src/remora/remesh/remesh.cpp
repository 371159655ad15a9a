#include "remora/remesh/remesh.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <unordered_set>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "remora/common/error.h"
#include "remora/common/parallel.h"
#include "remora/geometry/closest_point.h"
#include "remora/geometry/laplacian.h"
#include "remora/geometry/locate.h"
#include "remora/geometry/measures.h"
#include "remora/mesh/build.h"
#include "remora/mesh/topology.h"

namespace remora {

namespace {

using Clock = std::chrono::steady_clock;

// Above this many faces the mesh no longer stays in cache, and the remesher renumbers it
// spatially (copy_in_order).
constexpr std::size_t kSpatialOrderFaces = 32768;

// Slivers below this angle (5 degrees) between two curves may merge two curve vertices
// (Remesher::repair_pass).
constexpr double kFlatRepairRad = 5.0 * M_PI / 180.0;

// Closed curves shorter than this many target lengths keep at least three corners
// (Remesher::keep_three_corners). Longer ones hold six or more vertices at the boundary spacing,
// and no smoothing flattens them.
constexpr double kSmallLoopLengths = 8.0;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// The boundary halfedge leaving v (invalid for an interior vertex).
HalfedgeHandle boundary_out(const Mesh& mesh, VertexHandle v) {
  for (auto h : mesh.voh_range(v))
    if (mesh.is_boundary(h)) return h;
  return HalfedgeHandle();
}

// What each output vertex is allowed to do.
enum class Kind : std::uint8_t {
  Interior, // moves tangentially, projected onto the input surface
  Curve,    // slides along an input curve: the boundary or a feature line
  Corner,   // never moves (a sharp corner of a curve, or where feature lines meet or end)
};

// Where copy_in_order took each element of the copy from: old index by new index.
struct MeshOrder {
  std::vector<int> vertices, edges, faces;
};

// A compacted copy of `mesh` (its deleted elements left out): with `spatially`, the vertices are
// renumbered along a Z-order (Morton) curve of their positions, else they keep their order; then
// the faces by their smallest new vertex index and the edges by first use in that face order, so
// that neighbours sit close in memory. Each face keeps its first halfedge (its corners keep their
// order). The half-edge structure is copied through the index maps in linear time, no rebuild
// from triangles.
Mesh copy_in_order(const Mesh& mesh, bool spatially, MeshOrder& order) {
  const std::size_t nv_old = mesh.n_vertices(), ne_old = mesh.n_edges(), nf_old = mesh.n_faces();
  Vec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
  for (auto v : mesh.vertices()) {
    lo.minimize(mesh.point(v));
    hi.maximize(mesh.point(v));
  }
  auto spread = [](std::uint64_t x) { // 21 bits -> every third bit of 63
    x &= 0x1fffff;
    x = (x | x << 32) & 0x1f00000000ffffULL;
    x = (x | x << 16) & 0x1f0000ff0000ffULL;
    x = (x | x << 8) & 0x100f00f00f00f00fULL;
    x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
    x = (x | x << 2) & 0x1249249249249249ULL;
    return x;
  };
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed;
  keyed.reserve(nv_old);
  for (auto v : mesh.vertices()) { // live vertices only
    if (!spatially) {
      keyed.push_back({0, static_cast<std::uint32_t>(v.idx())});
      continue;
    }
    const Vec3 q = mesh.point(v) - lo;
    std::uint64_t key = 0;
    for (int d = 0; d < 3; ++d) {
      const double extent = hi[d] - lo[d];
      const double unit = extent > 0 ? std::clamp(q[d] / extent, 0.0, 1.0) : 0.0;
      key |= spread(static_cast<std::uint64_t>(unit * 2097151.0)) << d;
    }
    keyed.push_back({key, static_cast<std::uint32_t>(v.idx())});
  }
  if (spatially) std::sort(keyed.begin(), keyed.end());
  const std::size_t nv = keyed.size();
  std::vector<int> vmap(nv_old, -1);
  for (std::size_t r = 0; r < nv; ++r) vmap[keyed[r].second] = static_cast<int>(r);

  // Faces by smallest new vertex index, ties in old order (a counting sort).
  std::vector<std::uint32_t> first(nv + 1, 0);
  std::vector<int> face_key(nf_old, -1);
  for (auto f : mesh.faces()) {
    const auto fv = face_vertices(mesh, f);
    const int m = std::min({vmap[fv[0].idx()], vmap[fv[1].idx()], vmap[fv[2].idx()]});
    face_key[f.idx()] = m;
    ++first[static_cast<std::size_t>(m) + 1];
  }
  for (std::size_t r = 0; r < nv; ++r) first[r + 1] += first[r];
  const std::size_t nf = first[nv];
  std::vector<int>& face_order = order.faces;
  face_order.assign(nf, -1);
  std::vector<int> fmap(nf_old, -1);
  for (std::size_t f = 0; f < nf_old; ++f)
    if (face_key[f] >= 0) {
      const std::uint32_t slot = first[static_cast<std::size_t>(face_key[f])]++;
      face_order[slot] = static_cast<int>(f);
      fmap[f] = static_cast<int>(slot);
    }
  // Edges by first use; every live edge has a face.
  std::vector<int> emap(ne_old, -1), edge_order;
  edge_order.reserve(ne_old);
  for (int f : face_order)
    for (auto h : mesh.fh_range(FaceHandle(f))) {
      const int e = h.idx() / 2;
      if (emap[static_cast<std::size_t>(e)] < 0) {
        emap[static_cast<std::size_t>(e)] = static_cast<int>(edge_order.size());
        edge_order.push_back(e);
      }
    }
  // OpenMesh numbers the halfedges of edge e as 2e and 2e + 1.
  auto hmap = [&](HalfedgeHandle h) {
    return HalfedgeHandle(2 * emap[static_cast<std::size_t>(h.idx() / 2)] + (h.idx() & 1));
  };

  Mesh out;
  out.reserve(nv, edge_order.size(), nf);
  for (std::size_t r = 0; r < nv; ++r)
    out.new_vertex(mesh.point(VertexHandle(static_cast<int>(keyed[r].second))));
  for (int e : edge_order) {
    const HalfedgeHandle h0 = mesh.halfedge_handle(EdgeHandle(e), 0);
    out.new_edge(VertexHandle(vmap[mesh.from_vertex_handle(h0).idx()]),
                 VertexHandle(vmap[mesh.to_vertex_handle(h0).idx()]));
  }
  for (int f : face_order) {
    const FaceHandle fh = out.new_face();
    out.set_halfedge_handle(fh, hmap(mesh.halfedge_handle(FaceHandle(f))));
  }
  for (std::size_t i = 0; i < edge_order.size(); ++i)
    for (int side = 0; side < 2; ++side) {
      const HalfedgeHandle h(2 * edge_order[i] + side);
      const HalfedgeHandle hn(static_cast<int>(2 * i) + side);
      out.set_next_halfedge_handle(hn, hmap(mesh.next_halfedge_handle(h)));
      const FaceHandle f = mesh.face_handle(h);
      if (f.is_valid())
        out.set_face_handle(hn, FaceHandle(fmap[static_cast<std::size_t>(f.idx())]));
    }
  order.edges = std::move(edge_order);
  order.vertices.resize(nv);
  for (std::size_t r = 0; r < nv; ++r) {
    order.vertices[r] = static_cast<int>(keyed[r].second);
    const HalfedgeHandle h = mesh.halfedge_handle(VertexHandle(order.vertices[r]));
    if (h.is_valid()) out.set_halfedge_handle(VertexHandle(static_cast<int>(r)), hmap(h));
  }
  return out;
}

// The first input vertex located on an output face (the head of a list through Remesher::next_).
struct PointList {
  int head = -1;
};

class Remesher {
public:
  Remesher(const Mesh& input, const RemeshOptions& options)
      : input_(input), options_(options), mesh_(input) {
    // Working properties of the private copy; removed before the mesh is handed out.
    add_working_properties();
  }

  RemeshResult run() {
    const auto t_total = Clock::now();
    RemeshResult result;
    RemeshReport& report = result.report;
    // Runs f and adds its wall time to the phase's entry of the report.
    auto timed = [&report](const char* phase, auto&& f) {
      const auto t0 = Clock::now();
      f();
      report.milliseconds[phase] += ms_since(t0);
    };
    const LengthScale scale = length_scale(input_);
    length_ =
        options_.target_length > 0 ? options_.target_length : options_.length_factor * scale.length;
    report.length_from_area = options_.target_length <= 0 && scale.needles;
    if (!std::isfinite(length_) || length_ <= 0)
      throw InvalidArgument("remesh: the target edge length must be positive and finite (got " +
                            std::to_string(length_) + ")");
    report.target_length = length_;
    // Bounded work: a remesh at length l has about area / (√3/4 l²) faces. Splitting stops at
    // eight times that (plus the input's own count), whatever the geometry does.
    max_faces_ =
        static_cast<std::size_t>(std::min(1e9, 8.0 * surface_area(input_) /
                                                   (std::sqrt(3.0) / 4.0 * length_ * length_))) +
        2 * input_.n_faces();
    live_faces_ = mesh_.n_faces();
    lo2_ = (0.8 * length_) * (0.8 * length_);
    guard_rad_ = options_.equalize_guard_deg * M_PI / 180.0;
    cos_guard_ = std::cos(guard_rad_);
    hi_ = 4.0 / 3.0 * length_;
    hi2_ = hi_ * hi_;
    flat_cross_ = 1e-6 * length_ * length_;

    const bool figures = options_.compute_report;
    if (figures)
      timed("report", [&] {
        report.input = mesh_quality(input_);
        report.symmetry_defect_input = laplacian_symmetry_defect(input_);
      });

    init_locations();
    report.feature_edges = feature_count_;
    init_points();
    // At least options_.cycles cycles, then more while the last one still reconnected more than
    // settle_fraction of the faces (CAD parts keep doing so around their creases), up to
    // max_cycles.
    const int max_cycles = std::max(options_.cycles, options_.max_cycles);
    for (int cycle = 0; cycle < max_cycles; ++cycle) {
      progress("remesh", cycle, std::max(options_.cycles, cycle + 1));
      if (cycle == 1 && options_.boundary_spacing > 1)
        timed("collapse", [&] { report.collapses += resample_boundary(); });
      const std::size_t before = report.splits + report.collapses + report.flips;
      timed("split", [&] { report.splits += split_long_edges(); });
      timed("collapse", [&] { report.collapses += collapse_short_edges(); });
      timed("flip", [&] { report.flips += equalize_valences(); });
      const std::size_t changes = report.splits + report.collapses + report.flips - before;
      const bool last = cycle + 1 >= max_cycles ||
                        (cycle + 1 >= options_.cycles &&
                         (options_.settle_fraction >= 1 ||
                          static_cast<double>(changes) <=
                              options_.settle_fraction * static_cast<double>(live_faces_)));
      timed("smooth", [&] { tangential_smoothing(); });
      report.cycles = cycle + 1;
      if (last) break;
      if (cycle == 0) timed("reorder", [&] { compact(); });
    }
    timed("reorder", [&] { compact(); });
    timed("repair", [&] { report.repairs += repair_bad_triangles(options_.repair_angle_deg); });
    if (figures)
      timed("report", [&] {
        // The repair's few deleted elements stay until the end; the figures need them gone.
        Mesh compacted = mesh_;
        compacted.garbage_collection();
        report.after_cycles = mesh_quality(compacted);
        report.edges_in_band_cycles = percent_edges_within(compacted, 0.8 * length_, hi_);
        report.symmetry_defect_cycles = laplacian_symmetry_defect(compacted);
      });

    timed("equalize", [&] {
      previous_points_.clear(); // the first iteration has no previous move
      for (int it = 0; it < options_.equalize_iterations; ++it) {
        progress("equalize", it, options_.equalize_iterations);
        report.delaunay_flips += equalize_areas();
      }
      report.guarded_moves = guarded_;
      if (options_.equalize_iterations > 0)
        report.repairs += repair_bad_triangles(options_.repair_angle_deg);
    });
    timed("reorder", [&] { remove_deleted(); });
    if (figures)
      timed("report", [&] {
        report.after_equalization = mesh_quality(mesh_);
        report.edges_in_band_output = percent_edges_within(mesh_, 0.8 * length_, hi_);
        report.symmetry_defect_output = laplacian_symmetry_defect(mesh_);
        report.symmetry_defect_output_interior =
            laplacian_symmetry_defect(mesh_, SymmetryRows::Interior);
        measure_distances(report);
      });

    timed("correspondence", [&] {
      progress("correspondence", 0, 1);
      result.output_on_input.resize(mesh_.n_vertices());
      for (auto v : mesh_.vertices()) result.output_on_input[v.idx()] = loc(v);
      reproject_points(); // the repair changed faces after the last moves
      result.input_on_output = closest_input_locations(report);
    });

    mesh_.remove_property(loc_prop_);
    mesh_.remove_property(bloc_prop_);
    mesh_.remove_property(kind_prop_);
    mesh_.remove_property(feature_prop_);
    mesh_.remove_property(points_prop_);
    result.mesh = std::move(mesh_);
    report.milliseconds["total"] = ms_since(t_total);
    return result;
  }

private:
  void progress(std::string_view phase, int step, int steps) const {
    if (options_.progress) options_.progress(phase, step, steps);
  }

  // --- the correspondence -------------------------------------------------------------------

  // Every output vertex starts as its input vertex: at a corner of an incident face, and on a
  // curve at an outgoing halfedge of it (on the boundary its outgoing boundary halfedge).
  void init_locations() {
    // The input's curves: its boundary and, with feature_angle_deg, its feature lines. The
    // working mesh starts as a copy, with the same handles.
    input_curve_ = options_.feature_angle_deg > 0
                       ? feature_edges(input_, options_.feature_angle_deg)
                       : std::vector<char>(input_.n_edges(), 0);
    for (auto e : input_.edges())
      if (input_.is_boundary(e)) input_curve_[static_cast<std::size_t>(e.idx())] = 1;
    if (options_.feature_angle_deg > 0) prune_short_lines();
    for (auto e : input_.edges()) {
      feature(e) = input_curve_[static_cast<std::size_t>(e.idx())] && !input_.is_boundary(e);
      feature_count_ += feature(e);
    }
    for (auto v : mesh_.vertices()) {
      kind(v) = Kind::Interior;
      if (mesh_.is_isolated(v)) {
        kind(v) = Kind::Corner;
        continue;
      }
      // The same handles index the copy and the input.
      const FaceHandle f = *input_.cvf_begin(v);
      SurfacePoint sp;
      sp.face = f;
      const auto fv = face_vertices(input_, f);
      sp.bary = {fv[0] == v ? 1.0 : 0.0, fv[1] == v ? 1.0 : 0.0, fv[2] == v ? 1.0 : 0.0};
      loc(v) = sp;
      if (mesh_.is_boundary(v)) {
        kind(v) = Kind::Curve;
        bloc(v) = boundary_out(input_, v);
      } else if (feature_count_ > 0) {
        for (auto h : input_.voh_range(v))
          if (input_curve_[static_cast<std::size_t>(h.idx() / 2)]) {
            kind(v) = Kind::Curve;
            bloc(v) = h;
            break;
          }
      }
    }
    mark_corners();
  }

  // A feature line of the input: its vertices, from an end (a vertex with other than two curve
  // edges) to an end, or around a loop (`closed`, the first vertex not repeated).
  struct Line {
    std::vector<VertexHandle> vertices;
    std::vector<EdgeHandle> edges;
    bool closed = false;
  };

  // The input's feature lines (input_curve_ without the boundary), each once.
  std::vector<Line> feature_lines() const {
    std::vector<int> degree(input_.n_vertices(), 0);
    for (auto v : input_.vertices()) degree[static_cast<std::size_t>(v.idx())] = curve_degree(v);
    std::vector<char> seen(input_.n_edges(), 0);
    std::vector<Line> lines;
    auto trace = [&](HalfedgeHandle h) {
      Line line;
      line.vertices.push_back(input_.from_vertex_handle(h));
      while (true) {
        seen[static_cast<std::size_t>(h.idx() / 2)] = 1;
        line.edges.push_back(input_.edge_handle(h));
        const VertexHandle v = input_.to_vertex_handle(h);
        if (v == line.vertices.front()) {
          line.closed = true;
          break;
        }
        line.vertices.push_back(v);
        if (degree[static_cast<std::size_t>(v.idx())] != 2) break;
        HalfedgeHandle next;
        for (auto g : input_.voh_range(v))
          if (input_curve_[static_cast<std::size_t>(g.idx() / 2)] &&
              input_.edge_handle(g) != input_.edge_handle(h))
            next = g;
        h = next;
      }
      lines.push_back(std::move(line));
    };
    // Open lines from their ends first; what is left are loops.
    for (int pass = 0; pass < 2; ++pass)
      for (auto v : input_.vertices()) {
        const int d = degree[static_cast<std::size_t>(v.idx())];
        if (d == 0 || (pass == 0 && d == 2)) continue;
        for (auto h : input_.voh_range(v)) {
          const std::size_t e = static_cast<std::size_t>(h.idx() / 2);
          if (input_curve_[e] && !seen[e] && !input_.is_boundary(input_.edge_handle(h))) trace(h);
        }
      }
    return lines;
  }

  // Drops the feature lines shorter than l, until none is left: between two corners closer
  // than that, no edge can be in the band, and where lines meet at such distances (the teeth of
  // gears.stl, the facets of a coarse cylinder) their corners pin slivers. Features smaller
  // than the target length are lost anyway.
  void prune_short_lines() {
    for (int pass = 0; pass < 16; ++pass) {
      bool pruned = false;
      for (const Line& line : feature_lines()) {
        double length = 0;
        for (EdgeHandle e : line.edges) length += input_.calc_edge_length(e);
        if (length >= length_) continue;
        for (EdgeHandle e : line.edges) input_curve_[static_cast<std::size_t>(e.idx())] = 0;
        pruned = true;
      }
      if (!pruned) break;
    }
  }

  // The number of input curve edges (boundary or feature) at v.
  int curve_degree(VertexHandle v) const {
    int n = 0;
    for (auto h : input_.voh_range(v)) n += input_curve_[static_cast<std::size_t>(h.idx() / 2)];
    return n;
  }

  // Marks as corners the vertices of `vs` (a curve of the input, closed or open) where it turns
  // sharply at the scale of the target length: the turn at v is measured between the chords to
  // the curve's points about l/2 before and after it, and again 2 l before and after it; a corner
  // turns sharply at both scales. So the zigzag of a scanned hole (sharp at the scale of its own
  // edges, or of l/2: the raw bunny's rims had 82 corners, 39 now) is not a corner while a CAD
  // corner is. Of the vertices around one corner only the sharpest is kept, and none within l/2
  // of a vertex where feature lines end or meet (which is a corner already: blade.off has a
  // boundary turn 0.03 l from where a feature line meets the boundary, and the edge between two
  // corners cannot go).
  void mark_turns(const std::vector<VertexHandle>& vs, bool closed, double corner_cos) {
    const std::size_t n = vs.size();
    if (n < 3) return;
    // The cosine of the turn at vs[i] between the chords to the curve's points at least `reach`
    // away before and after it; b and a receive their indices.
    auto turn_at = [&](std::size_t i, double reach, std::size_t& b, std::size_t& a) {
      const double reach2 = reach * reach;
      const Vec3 p = input_.point(vs[i]);
      b = (i + n - 1) % n;
      a = (i + 1) % n;
      if (closed) {
        while (b != a && (input_.point(vs[b]) - p).sqrnorm() < reach2) b = (b + n - 1) % n;
        while (a != b && (input_.point(vs[a]) - p).sqrnorm() < reach2) a = (a + 1) % n;
      } else {
        while (b > 0 && (input_.point(vs[b]) - p).sqrnorm() < reach2) --b;
        while (a + 1 < n && (input_.point(vs[a]) - p).sqrnorm() < reach2) ++a;
      }
      const Vec3 d_in = p - input_.point(vs[b]), d_out = input_.point(vs[a]) - p;
      const double len = d_in.norm() * d_out.norm();
      return len > 0 ? OpenMesh::dot(d_in, d_out) / len : 1.0;
    };
    std::vector<double> turn(n, 1.0); // cosine of the turning angle; lower is sharper
    std::vector<std::size_t> before(n), after(n);
    for (std::size_t i = 0; i < n; ++i) {
      before[i] = after[i] = i;
      if (!closed && (i == 0 || i + 1 == n)) continue;
      turn[i] = turn_at(i, 0.5 * length_, before[i], after[i]);
      std::size_t b = 0, a = 0;
      if (turn[i] < corner_cos && turn_at(i, 2 * length_, b, a) >= corner_cos) turn[i] = 1.0;
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (turn[i] >= corner_cos) continue;
      // Non-maximum suppression over the same window (ties go to the lower index).
      bool sharpest = true;
      for (std::size_t j = before[i]; j != after[i] && sharpest; j = (j + 1) % n)
        if (j != i && (turn[j] < turn[i] || (turn[j] == turn[i] && j < i))) sharpest = false;
      if (feature_count_ > 0)
        for (std::size_t j = before[i]; j != (after[i] + 1) % n && sharpest; j = (j + 1) % n)
          if (curve_degree(vs[j]) != 2) sharpest = false;
      if (sharpest) kind(vs[i]) = Kind::Corner;
    }
    if (closed) keep_three_corners(vs);
  }

  // A closed curve shorter than kSmallLoopLengths l with fewer than three corners (a small hole,
  // or an island of a few triangles: mark_turns keeps one vertex of a small polygon, none of a
  // round loop) was smoothed and collapsed down to a flat triangle (lato000.ply: three islands
  // of 0.6–1.4 l² came out with areas 0.01, 0 and 0.19 l²). It keeps three: its sharpest corner
  // (or its first vertex) and the vertices closest to a third and two thirds of the way round.
  void keep_three_corners(const std::vector<VertexHandle>& vs) {
    const std::size_t n = vs.size();
    std::vector<double> arc(n + 1, 0.0);
    for (std::size_t i = 0; i < n; ++i)
      arc[i + 1] = arc[i] + (input_.point(vs[(i + 1) % n]) - input_.point(vs[i])).norm();
    const double perimeter = arc[n];
    if (n < 3 || !(perimeter < kSmallLoopLengths * length_)) return;
    std::size_t corners = 0, first = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (kind(vs[i]) == Kind::Corner && corners++ == 0) first = i;
    if (corners >= 3) return;
    kind(vs[first]) = Kind::Corner;
    for (double third : {1.0 / 3.0, 2.0 / 3.0}) {
      const double target = arc[first] + third * perimeter;
      std::size_t best = first;
      double best_gap = std::numeric_limits<double>::max();
      for (std::size_t i = 0; i < n; ++i) {
        if (kind(vs[i]) == Kind::Corner) continue;
        const double s = arc[i] < arc[first] ? arc[i] + perimeter : arc[i];
        if (std::abs(s - target) < best_gap) {
          best_gap = std::abs(s - target);
          best = i;
        }
      }
      kind(vs[best]) = Kind::Corner;
    }
  }

  // Corners: where a curve turns sharply (mark_turns), and where feature lines end or meet, each
  // other or the boundary (a curve vertex with other than two curve edges).
  void mark_corners() {
    const double corner_cos = std::cos(options_.corner_angle_deg * M_PI / 180.0);
    const auto loops = boundary_loops(input_);
    has_boundary_ = !loops.empty();
    for (const auto& loop : loops) {
      std::vector<VertexHandle> vs(loop.size());
      for (std::size_t i = 0; i < loop.size(); ++i) vs[i] = input_.from_vertex_handle(loop[i]);
      mark_turns(vs, true, corner_cos);
    }
    if (feature_count_ == 0) return;
    for (auto v : input_.vertices()) {
      const int degree = curve_degree(v);
      if (degree > 0 && degree != 2) kind(v) = Kind::Corner;
    }
    for (const Line& line : feature_lines()) mark_turns(line.vertices, line.closed, corner_cos);
  }

  // Finds where `p` lies on the input, starting from the location of `near`, and returns the
  // point to place the vertex at (the projection when projecting).
  Vec3 relocate(VertexHandle v, const Vec3& p, VertexHandle near) {
    if (kind(near) != Kind::Interior && kind(v) != Kind::Interior) {
      const BoundaryPoint bp = walk_to_closest_on_curve(input_, p, bloc(near), input_curve_);
      loc(v) = bp.point;
      bloc(v) = bp.halfedge;
    } else {
      // Most moves stay close above the face the vertex was on, or cross a few faces: a directed
      // walk follows the closest point across the edge or around the corner it leaves by, only
      // downhill. Its answer is taken when it ends strictly inside a face and within l/100 (then
      // only a sheet of the surface passing closer than that could be closer), or within l/20
      // when no face of the walk turned more than 18 degrees from the first (a smooth sheet, no
      // crease crossed: on curved organic parts the smoothing's goals sit l/100 to l/20 above
      // the surface, and the full walk for each cost lucy 20 % of its smoothing). Otherwise the
      // full walk runs from the start: a walk from wherever a wrong turn led (across a crease, or
      // the fold of a thin plate) can end in a local minimum far from p; taking such answers at
      // l/20 without the turn test left 9 to 78 flat faces on gears.stl.
      const FaceHandle start = loc(near).face;
      FaceHandle f = start;
      SurfacePoint quick;
      double d2 = 0;
      bool found = close_inside(p, f, quick, d2);
      const Vec3 start_normal = input_face_cross(start);
      bool smooth_walk = true; // every face so far within 18 degrees of the start face
      for (int step = 0; step < 8 && !found; ++step) {
        const FaceHandle g = next_face_towards(p, f, quick);
        if (!g.is_valid()) break;
        SurfacePoint there;
        double there_d2 = 0;
        found = close_inside(p, g, there, there_d2);
        if (!(there_d2 < d2)) {
          found = false;
          break;
        }
        f = g;
        quick = there;
        d2 = there_d2;
        if (smooth_walk) {
          const Vec3 n = input_face_cross(g);
          smooth_walk = OpenMesh::dot(n, start_normal) >= 0.95 * n.norm() * start_normal.norm();
        }
      }
      constexpr double inside = 1e-6; // as in close_inside
      if (!found && smooth_walk && quick.bary[0] > inside && quick.bary[1] > inside &&
          quick.bary[2] > inside && d2 <= length_ * length_ / 400.0)
        found = true;
      loc(v) = found ? quick : walk_to_closest(input_, p, start);
    }
    return options_.project ? evaluate(input_, loc(v)) : p;
  }

  // How far the output lies from the input: its vertices (tracked locations) and its faces'
  // centroids (located by a walk from a corner's location).
  void measure_distances(RemeshReport& report) {
    const double diag = bounding_box_diagonal(input_);
    if (!(diag > 0)) return;
    std::vector<double> vd(mesh_.n_vertices(), 0.0), fd(mesh_.n_faces(), 0.0);
    parallel_for(mesh_.n_vertices(), options_.threads, [&](std::size_t i) {
      const VertexHandle v(static_cast<int>(i));
      if (!mesh_.is_isolated(v)) vd[i] = (mesh_.point(v) - evaluate(input_, loc(v))).norm();
    });
    parallel_for(mesh_.n_faces(), options_.threads, [&](std::size_t i) {
      const auto fv = face_vertices(mesh_, FaceHandle(static_cast<int>(i)));
      const Vec3 c = (mesh_.point(fv[0]) + mesh_.point(fv[1]) + mesh_.point(fv[2])) / 3.0;
      const SurfacePoint sp = walk_to_closest(input_, c, loc(fv[0]).face);
      fd[i] = (c - evaluate(input_, sp)).norm();
    });
    auto summarize = [&](const std::vector<double>& d, double& mean, double& max) {
      double sum = 0;
      max = 0;
      for (double x : d) {
        sum += x;
        max = std::max(max, x);
      }
      mean = d.empty() ? 0.0 : sum / static_cast<double>(d.size()) / diag;
      max /= diag;
    };
    summarize(vd, report.vertex_distance_mean, report.vertex_distance_max);
    summarize(fd, report.centroid_distance_mean, report.centroid_distance_max);
  }

  // Removes deleted elements; on large meshes also renumbers them spatially. Below ~30k faces
  // the whole mesh stays in cache and renumbering only costs (measured: fandisk and fertility
  // 10-15 % slower with it, bunny and lucy 9-12 % faster). Compacting matters even there:
  // keeping the deleted elements of the cycles until the end made fertility and camelhead
  // 15-25 % slower (the split vertices sit at the end, away from their neighbours).
  void compact() { renumber(live_faces_ > kSpatialOrderFaces); }

  // Compacts the mesh (copy_in_order) and carries the working properties and point lists along.
  // After the cycles, with many deleted elements, the copy is faster than OpenMesh's
  // garbage_collection (camelhead: 8 ms against 11); the repair, which deletes a few, keeps the
  // garbage collection.
  void renumber(bool spatially) {
    MeshOrder order;
    Mesh out = copy_in_order(mesh_, spatially, order);
    const std::size_t nv = order.vertices.size(), nf = order.faces.size();
    std::vector<PointList> lists(nf);
    for (std::size_t r = 0; r < nf; ++r) lists[r] = points(FaceHandle(order.faces[r]));
    std::vector<SurfacePoint> locs(nv);
    std::vector<HalfedgeHandle> blocs(nv);
    std::vector<Kind> kinds(nv);
    std::vector<char> old_features;
    if (feature_count_ > 0) {
      old_features.resize(mesh_.n_edges());
      for (auto e : mesh_.edges()) old_features[static_cast<std::size_t>(e.idx())] = feature(e);
    }
    for (std::size_t r = 0; r < nv; ++r) {
      const VertexHandle v(order.vertices[r]);
      locs[r] = loc(v);
      blocs[r] = bloc(v);
      kinds[r] = kind(v);
    }
    mesh_ = std::move(out);
    add_working_properties();
    for (std::size_t r = 0; r < nv; ++r) {
      const VertexHandle v(static_cast<int>(r));
      loc(v) = locs[r];
      bloc(v) = blocs[r];
      kind(v) = kinds[r];
    }
    for (std::size_t r = 0; r < nf; ++r) points(FaceHandle(static_cast<int>(r))) = lists[r];
    if (feature_count_ > 0)
      for (std::size_t r = 0; r < order.edges.size(); ++r)
        feature(EdgeHandle(static_cast<int>(r))) =
            old_features[static_cast<std::size_t>(order.edges[r])];
    rebind_points();
    live_faces_ = mesh_.n_faces();
  }

  // Twice the area vector of input face f.
  Vec3 input_face_cross(FaceHandle f) const {
    const auto fv = face_vertices(input_, f);
    const Vec3& a = input_.point(fv[0]);
    return OpenMesh::cross(input_.point(fv[1]) - a, input_.point(fv[2]) - a);
  }

  // Is the closest point of face f to p strictly inside f and within l/100 of p? `out` gets it
  // either way.
  bool close_inside(const Vec3& p, FaceHandle f, SurfacePoint& out, double& distance2) const {
    const auto fv = face_vertices(input_, f);
    const Vec3 &a = input_.point(fv[0]), &b = input_.point(fv[1]), &c3 = input_.point(fv[2]);
    constexpr double inside = 1e-6;
    // Most moves end above the interior of a face: there the closest point is the foot of the
    // perpendicular, a few dot products instead of the full region test.
    std::array<double, 3> w{};
    if (plane_barycentrics(p, a, b, c3, w) && w[0] > inside && w[1] > inside && w[2] > inside) {
      out = SurfacePoint{f, w};
      distance2 = (p - (a * w[0] + b * w[1] + c3 * w[2])).sqrnorm();
      return distance2 <= 1e-4 * length_ * length_;
    }
    const TriangleClosest c = closest_point_on_triangle(p, a, b, c3);
    out = SurfacePoint{f, c.bary};
    distance2 = c.distance2;
    return c.bary[0] > inside && c.bary[1] > inside && c.bary[2] > inside &&
           c.distance2 <= 1e-4 * length_ * length_;
  }

  // Where the closest point `sp` of p on face f left it: across an edge (one weight vanished),
  // the face on the other side; at a corner (two vanished), the face around that corner closest
  // to p. Invalid at the input boundary or when no face of the fan is closer.
  FaceHandle next_face_towards(const Vec3& p, FaceHandle f, const SurfacePoint& sp) const {
    int zero = -1, zeros = 0, kept = -1;
    for (int k = 0; k < 3; ++k) {
      if (sp.bary[k] <= 0.0) {
        zero = k;
        ++zeros;
      } else {
        kept = k;
      }
    }
    if (zeros == 1) {
      // halfedge_handle(f) runs v0 -> v1, opposite v2; then v1 -> v2 (opposite v0), v2 -> v0.
      HalfedgeHandle h = input_.halfedge_handle(f);
      if (zero == 0) h = input_.next_halfedge_handle(h);
      if (zero == 1) h = input_.prev_halfedge_handle(h);
      return input_.face_handle(input_.opposite_halfedge_handle(h));
    }
    if (zeros != 2) return FaceHandle();
    const VertexHandle corner = face_vertices(input_, f)[static_cast<std::size_t>(kept)];
    double best = (p - evaluate(input_, sp)).sqrnorm();
    FaceHandle best_face;
    for (auto h : input_.voh_range(corner)) {
      const FaceHandle g = input_.face_handle(h);
      if (!g.is_valid() || g == f) continue;
      const Vec3 q = input_.point(input_.to_vertex_handle(h));
      const Vec3 r = input_.point(input_.to_vertex_handle(input_.next_halfedge_handle(h)));
      const double d2 = closest_point_on_triangle(p, input_.point(corner), q, r).distance2;
      if (d2 < best) {
        best = d2;
        best_face = g;
      }
    }
    return best_face;
  }

  // --- input -> output: every input vertex on a face of the working mesh ------------------
  //
  // Each input vertex i has a location track_[i] (an output face and barycentrics), and each
  // output face lists the input vertices located on it: a doubly linked list through next_/prev_
  // whose head is a face property, so that it follows the faces through garbage collection and an
  // operation finds the input vertices it displaces without a search. Every operation keeps each
  // input vertex on a live face next to it: a split and a flip keep their faces (an input vertex
  // stays on the half or the new triangle of its old face, at most one face from where it lies),
  // a collapse puts the input vertices of its two deleted faces on the closest face around the
  // survivor. After each pass of vertex moves (tangential smoothing, every equalization step)
  // and before the end, each input vertex is projected again by a walk across the edges its
  // projection falls beyond (reproject_points). At the very end one last walk makes each
  // location the input vertex's closest point on the output.

  PointList& points(FaceHandle f) { return mesh_.property(points_prop_, f); }

  void link_point(int i, FaceHandle f) {
    PointList& list = points(f);
    const auto u = static_cast<std::size_t>(i);
    prev_[u] = -1;
    next_[u] = list.head;
    if (list.head >= 0) prev_[static_cast<std::size_t>(list.head)] = i;
    list.head = i;
    track_[u].face = f;
  }

  void unlink_point(int i) {
    const auto u = static_cast<std::size_t>(i);
    if (prev_[u] >= 0)
      next_[static_cast<std::size_t>(prev_[u])] = next_[u];
    else
      points(track_[u].face).head = next_[u];
    if (next_[u] >= 0) prev_[static_cast<std::size_t>(next_[u])] = prev_[u];
  }

  // Takes every input vertex off face f and appends it to `out`.
  void take_points(FaceHandle f, std::vector<int>& out) {
    PointList& list = points(f);
    for (int i = list.head; i >= 0; i = next_[static_cast<std::size_t>(i)]) out.push_back(i);
    list.head = -1;
  }

  // Puts every input vertex of `taken` on the closest of the faces around v, and clears `taken`.
  void place_points_around(VertexHandle v, std::vector<int>& taken) {
    if (taken.empty()) return;
    FaceHandle faces[64];
    std::array<Vec3, 3> corners[64];
    int n = 0;
    for (auto f : mesh_.vf_range(v)) {
      if (n == 64) break;
      const auto fv = face_vertices(mesh_, f);
      faces[n] = f;
      corners[n] = {mesh_.point(fv[0]), mesh_.point(fv[1]), mesh_.point(fv[2])};
      ++n;
    }
    for (int i : taken) {
      const Vec3 q = input_.point(VertexHandle(i));
      double best = std::numeric_limits<double>::infinity();
      int best_k = 0;
      std::array<double, 3> bary{1.0, 0.0, 0.0};
      for (int k = 0; k < n; ++k) {
        const TriangleClosest c =
            closest_point_on_triangle(q, corners[k][0], corners[k][1], corners[k][2]);
        if (c.distance2 < best) {
          best = c.distance2;
          best_k = k;
          bary = c.bary;
        }
      }
      link_point(i, faces[best_k]);
      track_[static_cast<std::size_t>(i)].bary = bary;
    }
    taken.clear();
  }

  // Every input vertex starts at its own output vertex (the working mesh is a copy of the input).
  void init_points() {
    const std::size_t n = input_.n_vertices();
    track_.assign(n, SurfacePoint());
    next_.assign(n, -1);
    prev_.assign(n, -1);
    for (auto v : input_.vertices()) {
      if (input_.is_isolated(v)) continue;
      const FaceHandle f = *mesh_.cvf_begin(v);
      const auto fv = face_vertices(mesh_, f);
      link_point(v.idx(), f);
      track_[static_cast<std::size_t>(v.idx())].bary = {
          fv[0] == v ? 1.0 : 0.0, fv[1] == v ? 1.0 : 0.0, fv[2] == v ? 1.0 : 0.0};
    }
  }

  // After garbage collection or renumbering the faces have new handles; the lists moved with
  // them, so each input vertex takes its face from the list it is on.
  void rebind_points() {
    for (auto f : mesh_.faces())
      for (int i = points(f).head; i >= 0; i = next_[static_cast<std::size_t>(i)])
        track_[static_cast<std::size_t>(i)].face = f;
  }

  // Projects every input vertex onto its face again after vertices moved or faces changed: a
  // visibility walk that steps across the edge its projection falls beyond until the projection
  // lies in the face (almost always at once, or after one step). Where that stops at the
  // boundary, or turns in a circle on a strongly curved part, a short closest-point walk takes
  // over. Data-parallel, then the lists are updated in input order.
  void reproject_points() {
    const std::size_t n = track_.size();
    std::vector<SurfacePoint>& moved = reprojected_; // kept between calls: no fresh pages each time
    moved.resize(n);
    parallel_for(n, options_.threads, [&](std::size_t i) {
      if (!track_[i].face.is_valid()) return;
      const Vec3 q = input_.point(VertexHandle(static_cast<int>(i)));
      FaceHandle f = track_[i].face;
      for (int step = 0; step < 8; ++step) {
        const HalfedgeHandle h0 = mesh_.halfedge_handle(f);
        const HalfedgeHandle h1 = mesh_.next_halfedge_handle(h0);
        const HalfedgeHandle h2 = mesh_.next_halfedge_handle(h1);
        std::array<double, 3> w{};
        if (!plane_barycentrics(q, mesh_.point(mesh_.from_vertex_handle(h0)),
                                mesh_.point(mesh_.to_vertex_handle(h0)),
                                mesh_.point(mesh_.to_vertex_handle(h1)), w))
          break;
        const int k = static_cast<int>(std::min_element(w.begin(), w.end()) - w.begin());
        if (w[static_cast<std::size_t>(k)] >= 0) {
          moved[i] = SurfacePoint{f, w};
          return;
        }
        // The edge opposite corner k: h1 for corner 0, h2 for corner 1, h0 for corner 2.
        const HalfedgeHandle exit = k == 0 ? h1 : k == 1 ? h2 : h0;
        const FaceHandle g = mesh_.face_handle(mesh_.opposite_halfedge_handle(exit));
        if (!g.is_valid()) break;
        f = g;
      }
      moved[i] = walk_to_closest(mesh_, q, f, 8);
    });
    for (std::size_t i = 0; i < n; ++i) {
      if (!track_[i].face.is_valid()) continue;
      if (moved[i].face != track_[i].face) {
        unlink_point(static_cast<int>(i));
        link_point(static_cast<int>(i), moved[i].face);
      }
      track_[i].bary = moved[i].bary;
    }
  }

  // The tracked locations made exact: each input vertex's closest point on the output, by a
  // local walk from its tracked face. The report gets how far the walk had to go.
  std::vector<SurfacePoint> closest_input_locations(RemeshReport& report) const {
    const std::size_t n = track_.size();
    std::vector<SurfacePoint> out(n);
    std::vector<double> excess(n, 0.0);
    parallel_for(n, options_.threads, [&](std::size_t i) {
      if (!track_[i].face.is_valid()) return;
      const Vec3 q = input_.point(VertexHandle(static_cast<int>(i)));
      out[i] = walk_to_closest(mesh_, q, track_[i].face, 256);
      excess[i] = (q - evaluate(mesh_, track_[i])).norm() - (q - evaluate(mesh_, out[i])).norm();
    });
    std::size_t located = 0, same = 0;
    double sum = 0, worst = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!track_[i].face.is_valid()) continue;
      ++located;
      same += out[i].face == track_[i].face ? 1 : 0;
      sum += excess[i];
      worst = std::max(worst, excess[i]);
    }
    const double count = static_cast<double>(std::max<std::size_t>(located, 1));
    report.tracked_same_face = located > 0 ? static_cast<double>(same) / count : 1.0;
    report.tracked_excess_mean = sum / count / length_;
    report.tracked_excess_max = worst / length_;
    return out;
  }

  // --- the four steps of a cycle -------------------------------------------------------------

  // Splits every edge longer than 4/3 l at its midpoint, in passes until none is left (a pass
  // visits the edges that existed when it began), the longest first: while edges longer than
  // twice 4/3 l remain, a pass splits only those longer than half the longest of the last pass
  // (length classes, after Rivara's longest-edge bisection). Split in index order, a CAD fan's
  // long spokes were cut while its rim edges were still whole: each cut joined a spoke's
  // midpoint to a far rim vertex by an edge nearly as long, whose own cuts fanned out again (a
  // disc of 64 needles, 32 l in radius: 29,800 splits where 3,700 vertices do; 8,800 in
  // classes; Remesh.SplitsLongEdgesLongestFirst). On conrod.stl (needles up to 60 l) the first
  // cycle split 44,930 edges in index order and 22,377 in classes; its cycles then settle after
  // 7 instead of 9 (docs/remesh.md, "Splitting in length classes"). An input without edges
  // longer than 8/3 l is split as before, in index order.
  //
  // New vertices, like the survivors of collapses, stay where the operation put them, at the
  // midpoint of a chord, and take the location of an endpoint as a start: the cycle's smoothing
  // moves every vertex and projects it onto the input, walking from there. That is the paper's
  // order (it projects only the smoothing's updates) and CGAL's. Projecting each new vertex at
  // once cost a walk per split and collapse that the smoothing redid, and did not help quality:
  // with it, fertility took 10 % longer and the goals table (docs/remesh.md) came out the same or
  // worse (camelhead smoothed: smallest angle 10.0 degrees, 26.4 without; raw gears: defect 0.132
  // against 0.057).
  std::size_t split_long_edges() {
    std::size_t count = 0;
    double longest2 = 0; // of the last pass's edges
    for (auto e : mesh_.edges()) longest2 = std::max(longest2, mesh_.calc_edge_sqr_length(e));
    // Passes at 4/3 l: at most 10 (bounded work whatever the geometry); the classes above it
    // halve the length each pass, at most 64 of them (a factor of 2^64).
    for (int pass = 0, final_passes = 0; pass < 64 && final_passes < 10; ++pass) {
      const double t2 = std::max(hi2_, longest2 / 4);
      final_passes += t2 <= hi2_ ? 1 : 0;
      longest2 = 0;
      std::size_t made = 0;
      const std::size_t n = mesh_.n_edges();
      for (std::size_t i = 0; i < n && live_faces_ < max_faces_; ++i) {
        const EdgeHandle e(static_cast<int>(i));
        if (mesh_.status(e).deleted()) continue;
        const HalfedgeHandle h = mesh_.halfedge_handle(e, 0);
        const VertexHandle a = mesh_.from_vertex_handle(h), b = mesh_.to_vertex_handle(h);
        const Vec3 pa = mesh_.point(a), pb = mesh_.point(b);
        const double length2 = (pa - pb).sqrnorm();
        if (length2 <= t2) {
          longest2 = std::max(longest2, length2);
          continue;
        }
        const bool on_boundary = mesh_.is_boundary(e);
        const bool on_feature = feature(e);
        const VertexHandle v = mesh_.split(e, (pa + pb) * 0.5);
        live_faces_ += on_boundary ? 1 : 2;
        for (auto w : mesh_.vv_range(v)) // the halves and the edges to the opposite corners
          longest2 = std::max(longest2, (mesh_.point(w) - mesh_.point(v)).sqrnorm());
        kind(v) = on_boundary || on_feature ? Kind::Curve : Kind::Interior;
        // On a curve, start from an endpoint that slides along it; between two corners, from
        // the curve edge of the input at a that is closest to the midpoint. With feature lines
        // this matters on the boundary too: the walk along a curve stops where lines meet, and
        // from the corner's own boundary halfedge, which may leave it the other way, the new
        // vertex would stay on the corner (the bunny at 45 degrees: zero-length edges).
        const bool lines = feature_count_ > 0 && (on_feature || on_boundary);
        const VertexHandle near = lines && kind(a) == Kind::Corner ? b : a;
        loc(v) = loc(near);
        bloc(v) = bloc(near);
        if (lines && kind(near) == Kind::Corner) bloc(v) = curve_start(near, (pa + pb) * 0.5);
        if (on_feature) {
          for (auto g : mesh_.voh_range(v)) {
            const VertexHandle w = mesh_.to_vertex_handle(g);
            feature(mesh_.edge_handle(g)) = w == a || w == b;
          }
        } else if (feature_count_ > 0) {
          for (auto g : mesh_.voh_range(v)) feature(mesh_.edge_handle(g)) = 0;
        }
        ++made;
      }
      count += made;
      if ((made == 0 && t2 <= hi2_) || live_faces_ >= max_faces_) break;
    }
    return count;
  }

  // The input curve halfedge leaving corner c's input vertex whose segment is closest to p.
  HalfedgeHandle curve_start(VertexHandle c, const Vec3& p) const {
    const VertexHandle x = input_.from_vertex_handle(mesh_.property(bloc_prop_, c));
    HalfedgeHandle best;
    double best_d2 = std::numeric_limits<double>::max();
    for (auto h : input_.voh_range(x)) {
      if (!input_curve_[static_cast<std::size_t>(h.idx() / 2)]) continue;
      const double d2 =
          closest_point_on_segment(p, input_.point(x), input_.point(input_.to_vertex_handle(h)))
              .distance2;
      if (d2 < best_d2) {
        best_d2 = d2;
        best = h;
      }
    }
    return best.is_valid() ? best : mesh_.property(bloc_prop_, c);
  }

  // Does collapsing h (its source into its target) keep the mesh a manifold? The link condition
  // (the only common neighbours of the endpoints are the tips of the edge's faces), no face with
  // two boundary edges, no interior edge between two boundary vertices, and no collapse of a
  // closed tetrahedron. OpenMesh's is_collapse_ok tests the same with vertex tags; this one
  // keeps the first ring in a small array (about 7 % of a remesh faster).
  bool collapse_keeps_manifold(HalfedgeHandle h) const {
    const HalfedgeHandle o = mesh_.opposite_halfedge_handle(h);
    const VertexHandle a = mesh_.from_vertex_handle(h), b = mesh_.to_vertex_handle(h);
    if (mesh_.status(a).deleted() || mesh_.status(b).deleted()) return false;
    VertexHandle tips[2];
    int n_tips = 0;
    for (HalfedgeHandle side : {h, o}) {
      if (mesh_.is_boundary(side)) continue;
      const HalfedgeHandle n1 = mesh_.next_halfedge_handle(side);
      const HalfedgeHandle n2 = mesh_.next_halfedge_handle(n1);
      if (mesh_.is_boundary(mesh_.opposite_halfedge_handle(n1)) &&
          mesh_.is_boundary(mesh_.opposite_halfedge_handle(n2)))
        return false;
      tips[n_tips++] = mesh_.to_vertex_handle(n1);
    }
    if (n_tips == 2 && tips[0] == tips[1]) return false;
    if (n_tips == 2 && mesh_.is_boundary(a) && mesh_.is_boundary(b)) return false;
    constexpr int kMax = 64;
    VertexHandle ring[kMax];
    int k = 0;
    for (auto w : mesh_.vv_range(a)) {
      if (k == kMax) return false;
      ring[k++] = w;
    }
    int valence_b = 0;
    for (auto w : mesh_.vv_range(b)) {
      ++valence_b;
      bool tip = false;
      for (int t = 0; t < n_tips; ++t) tip |= w == tips[t];
      if (tip) continue;
      for (int i = 0; i < k; ++i)
        if (ring[i] == w) return false;
    }
    // A tetrahedron would fold onto one double-sided triangle. Where b is on the boundary, the
    // face opposite a is missing: the three faces around a are an island (or the tip of a
    // strip) and become one triangle (thinned cubes: an interior vertex of valence 3 pressed
    // onto the line of two boundary vertices, a flat face nothing else could mend).
    return !(n_tips == 2 && k == 3 && valence_b == 3 && !mesh_.is_boundary(b));
  }

  // Would merging a and b at p leave every edge of the survivor within √max_length2 (4/3 l in
  // the cycles)? Where b stays where it is (p is b's point), only a's edges are new: b's own
  // may be longer already (a corner of a coarse, jagged boundary) without barring the collapse.
  bool neighbours_within(VertexHandle a, VertexHandle b, const Vec3& p, double max_length2) const {
    const bool b_stays = p == mesh_.point(b);
    for (VertexHandle v : {a, b}) {
      if (v == b && b_stays) continue;
      for (auto w : mesh_.vv_range(v))
        if (w != a && w != b && (mesh_.point(w) - p).sqrnorm() > max_length2) return false;
    }
    return true;
  }

  // Would moving `keep` to `p` (after removing `gone`) keep every remaining face's orientation
  // (within 60 degrees) and a non-trivial area?
  bool collapse_keeps_orientation(HalfedgeHandle h, const Vec3& p) const {
    const VertexHandle gone = mesh_.from_vertex_handle(h), keep = mesh_.to_vertex_handle(h);
    const FaceHandle fl = mesh_.face_handle(h),
                     fr = mesh_.face_handle(mesh_.opposite_halfedge_handle(h));
    for (VertexHandle v : {gone, keep}) {
      for (auto f : mesh_.vf_range(v)) {
        if (f == fl || f == fr) continue;
        auto fv = face_vertices(mesh_, f);
        Vec3 q[3];
        for (int k = 0; k < 3; ++k) q[k] = mesh_.point(fv[k]);
        const Vec3 n_before = OpenMesh::cross(q[1] - q[0], q[2] - q[0]);
        for (int k = 0; k < 3; ++k)
          if (fv[k] == gone || fv[k] == keep) q[k] = p;
        const Vec3 n_after = OpenMesh::cross(q[1] - q[0], q[2] - q[0]);
        // The new face must keep its orientation (within 60 degrees) and a non-trivial area.
        const double before = n_before.norm(), after = n_after.norm();
        if (after <= 1e-12 * hi2_) return false;
        if (before > 0 && OpenMesh::dot(n_before, n_after) < 0.5 * before * after) return false;
      }
    }
    return true;
  }

  // Is the smallest angle of the faces around h's endpoints larger after collapsing h into p
  // than before?
  bool collapse_raises_min_angle(HalfedgeHandle h, const Vec3& p) const {
    const VertexHandle gone = mesh_.from_vertex_handle(h), keep = mesh_.to_vertex_handle(h);
    const FaceHandle fl = mesh_.face_handle(h),
                     fr = mesh_.face_handle(mesh_.opposite_halfedge_handle(h));
    double before = M_PI, after = M_PI;
    auto smallest = [](const Vec3& a, const Vec3& b, const Vec3& c) {
      const auto t = triangle_angles(a, b, c);
      return std::min({t[0], t[1], t[2]});
    };
    for (VertexHandle v : {gone, keep})
      for (auto f : mesh_.vf_range(v)) {
        const auto fv = face_vertices(mesh_, f);
        Vec3 q[3];
        for (int k = 0; k < 3; ++k) q[k] = mesh_.point(fv[k]);
        before = std::min(before, smallest(q[0], q[1], q[2]));
        if (f == fl || f == fr) continue;
        for (int k = 0; k < 3; ++k)
          if (fv[k] == gone || fv[k] == keep) q[k] = p;
        after = std::min(after, smallest(q[0], q[1], q[2]));
      }
    return after > before;
  }

  // Collapses every edge shorter than 4/5 l that the rules allow (try_collapse), sequentially.
  std::size_t collapse_short_edges() {
    std::size_t count = 0;
    const std::size_t n = mesh_.n_edges();
    for (std::size_t i = 0; i < n; ++i) {
      const EdgeHandle e(static_cast<int>(i));
      if (mesh_.status(e).deleted()) continue;
      if (mesh_.calc_edge_sqr_length(e) >= lo2_) continue;
      count += try_collapse(e, Collapse::Short) ? 1 : 0;
    }
    return count;
  }

  // Flat: a repair of a sliver between two curves (below), which may merge two of their vertices.
  // Degenerate: a repair of a zero-area face, which may leave edges up to 8/3 l long.
  enum class Collapse { Short, Repair, Boundary, Flat, Degenerate };
  static bool is_repair(Collapse purpose) {
    return purpose == Collapse::Repair || purpose == Collapse::Flat ||
           purpose == Collapse::Degenerate;
  }

  // Collapses e if the rules allow it: corners never go, an interior vertex goes onto a curve
  // vertex (which stays put), two curve vertices merge along a curve edge only (a Flat repair
  // excepted: it merges them into the corner if one is, else into either), and the
  // survivor's edges stay short, the mesh stays manifold and no face turns over (two vertices at
  // one point need only the kinds and the manifold rule). Otherwise the survivor moves to the
  // midpoint: in the cycles it stays there until the smoothing projects
  // it (split_long_edges), a repair, which comes after the last smoothing, projects it at once.
  bool try_collapse(EdgeHandle e, Collapse purpose) {
    HalfedgeHandle h = mesh_.halfedge_handle(e, 0);
    VertexHandle a = mesh_.from_vertex_handle(h), b = mesh_.to_vertex_handle(h);
    const Kind ka = kind(a), kb = kind(b);
    // Which endpoint goes, and where the survivor ends up.
    bool midpoint = true;
    if (ka == Kind::Corner && kb == Kind::Corner) return false;
    if (ka != Kind::Interior && kb != Kind::Interior && !on_curve(e)) {
      if (purpose != Collapse::Flat) return false;
      if (kb != Kind::Corner) { // keep the corner if one is
        h = mesh_.opposite_halfedge_handle(h);
        std::swap(a, b);
      }
      midpoint = false;
    } else if (ka == Kind::Corner || (ka == Kind::Curve && kb == Kind::Interior)) {
      h = mesh_.opposite_halfedge_handle(h); // remove b, keep a where it is
      std::swap(a, b);
      midpoint = false;
    } else if (kb == Kind::Corner || (kb == Kind::Curve && ka == Kind::Interior)) {
      midpoint = false; // remove a, keep b where it is
    }
    Vec3 target = midpoint ? (mesh_.point(a) + mesh_.point(b)) * 0.5 : mesh_.point(b);
    if (!collapse_allowed(purpose, h, a, b, target, midpoint)) return false;
    live_faces_ -= mesh_.is_boundary(e) ? 1 : 2;
    // The two faces of the edge go: their input vertices move to the survivor's faces. In each,
    // the edges from a and b to the tip merge; the merged edge is a feature if either was.
    VertexHandle tips[2];
    char merged[2] = {0, 0};
    int n_tips = 0;
    for (auto side : {h, mesh_.opposite_halfedge_handle(h)}) {
      if (mesh_.is_boundary(side)) continue;
      take_points(mesh_.face_handle(side), displaced_);
      if (feature_count_ == 0) continue;
      const HalfedgeHandle n1 = mesh_.next_halfedge_handle(side);
      tips[n_tips] = mesh_.to_vertex_handle(n1);
      merged[n_tips++] = feature(mesh_.edge_handle(n1)) ||
                         feature(mesh_.edge_handle(mesh_.next_halfedge_handle(n1)));
    }
    mesh_.collapse(h);
    for (int t = 0; t < n_tips; ++t) {
      const HalfedgeHandle kept = mesh_.find_halfedge(b, tips[t]);
      if (kept.is_valid()) feature(mesh_.edge_handle(kept)) = merged[t];
    }
    // A repair comes after the last smoothing: its survivor is placed on the input at once.
    if (midpoint) mesh_.set_point(b, is_repair(purpose) ? relocate(b, target, b) : target);
    place_points_around(b, displaced_);
    return true;
  }

  // The rules of try_collapse() beyond the kinds, for collapsing h (a into b) with the survivor
  // at `target`: the manifold rule, and unless a and b are at one point the geometric ones.
  // Where the first choice fails, a collapse the other way (and for a repair into either
  // endpoint) may be taken instead, which updates h, a, b, target and midpoint.
  bool collapse_allowed(Collapse purpose, HalfedgeHandle& h, VertexHandle& a, VertexHandle& b,
                        Vec3& target, bool& midpoint) const {
    if ((mesh_.point(a) - mesh_.point(b)).sqrnorm() <= 1e-12 * hi2_) {
      // Two vertices at one point (the smoothing, moving all vertices at once, placed both on
      // the same input vertex or crack tip): merging them changes no remaining face, it only
      // removes the two flat ones; so only the kinds and the manifold rule hold here.
      // Otherwise a cluster of such vertices never went: each collapse left a flat face.
      bool ok = collapse_keeps_manifold(h);
      if (!ok && midpoint) {
        h = mesh_.opposite_halfedge_handle(h);
        std::swap(a, b);
        ok = collapse_keeps_manifold(h);
      }
      target = mesh_.point(b);
      midpoint = false;
      return ok;
    }
    // A repair may leave an edge up to √1.4 × 4/3 l ≈ 1.58 l long (one long edge costs the
    // Laplacian less than a sliver), and must raise the smallest angle around it. The length
    // test comes first: it is the cheapest and the one that fails most (two thirds of the short
    // edges of a cycle cannot go without leaving an edge longer than 4/3 l).
    const bool repair = is_repair(purpose);
    const double reach2 = purpose == Collapse::Short                                 ? hi2_
                          : purpose == Collapse::Repair || purpose == Collapse::Flat ? 1.4 * hi2_
                                                                                     : 4 * hi2_;
    bool ok = neighbours_within(a, b, target, reach2);
    if (ok && !collapse_keeps_manifold(h)) {
      if (!midpoint) return false;
      h = mesh_.opposite_halfedge_handle(h);
      std::swap(a, b);
      ok = collapse_keeps_manifold(h);
      if (!ok && purpose != Collapse::Repair) return false;
    }
    ok = ok && collapse_keeps_orientation(h, target) &&
         (!repair || collapse_raises_min_angle(h, target));
    if (!ok) {
      // A repair of an interior edge may also collapse it into either endpoint, which stays
      // where it is, on the input: on a crease (gears.stl at 0.6 l) the midpoint can be the
      // only position that lowers an angle around it.
      if (!midpoint || purpose != Collapse::Repair) return false;
      midpoint = false;
      for (int side = 0; side < 2 && !ok; ++side) {
        h = mesh_.opposite_halfedge_handle(h); // remove the other endpoint
        std::swap(a, b);
        target = mesh_.point(b);
        ok = neighbours_within(a, b, target, reach2) && collapse_keeps_manifold(h) &&
             collapse_keeps_orientation(h, target) && collapse_raises_min_angle(h, target);
      }
      if (!ok) return false;
    }
    return true;
  }

  // Triangles whose smallest angle is below `min_deg` (folds and slivers the cycles leave,
  // typically a handful per 100k): flip their longest edge when that raises the smallest angle of
  // the pair, else collapse their shortest edge when the collapse rules allow. Sequential, in face
  // order; the deleted elements stay until remove_deleted().
  std::size_t repair_bad_triangles(double min_deg) {
    // Every repair raises the smallest angle of the faces it touches (up to the projection of a
    // moved survivor), so passes do not undo each other; a pass that repairs nothing ends the
    // loop, and three bound the work.
    std::size_t total = 0;
    for (int pass = 0; pass < 3; ++pass) {
      const std::size_t c = repair_pass(min_deg);
      total += c;
      if (c == 0) break;
    }
    return total;
  }

  // Removes the elements the repairs deleted, once at the end (the equalization skips them):
  // OpenMesh's in-place garbage collection, cheaper than renumbering for a few (camelhead: 3 ms
  // a call; it ran after each of the two repairs before).
  void remove_deleted() {
    if (live_faces_ == mesh_.n_faces()) return;
    mesh_.garbage_collection();
    rebind_points();
    live_faces_ = mesh_.n_faces();
  }

  // The smallest angle (radians) of the triangle (x, y, z) at the current positions.
  double min_angle(VertexHandle x, VertexHandle y, VertexHandle z) const {
    const auto a = triangle_angles(mesh_.point(x), mesh_.point(y), mesh_.point(z));
    return std::min({a[0], a[1], a[2]});
  }

  // Flips e where the rules allow it (not on a curve, a manifold result, both new faces facing
  // the old pair's way) and the smaller angle of its two faces grows.
  bool try_repair_flip(EdgeHandle e) {
    if (on_curve(e) || !mesh_.is_flip_ok(e)) return false;
    const HalfedgeHandle h0 = mesh_.halfedge_handle(e, 0), h1 = mesh_.halfedge_handle(e, 1);
    const VertexHandle a = mesh_.to_vertex_handle(h0), b = mesh_.to_vertex_handle(h1);
    const VertexHandle c = mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h0));
    const VertexHandle d = mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h1));
    const double before = std::min(min_angle(b, a, c), min_angle(a, b, d));
    const double after = std::min(min_angle(a, c, d), min_angle(c, b, d));
    if (!(after > before) || !flip_keeps_orientation(a, b, c, d)) return false;
    mesh_.flip(e);
    return true;
  }

  // Moves interior vertex v to its one-ring centroid (the move in its tangent plane, then onto
  // the input) where no face of its ring goes flat or turns over and the ring's smallest angle
  // grows. The repair of a flat face that no flip or collapse mends: an interior vertex that the
  // smoothing left on a boundary edge of the input, in line with two boundary vertices (blade.off
  // at 10 cycles, where the blade's rim curls up from the plate: the goal's closest point lies
  // on the plate, but relocate()'s walk from the rim stops on the rim).
  bool try_repair_move(VertexHandle v) {
    Vec3 goal;
    if (kind(v) != Kind::Interior || mesh_.is_boundary(v) || !centroid_target(v, goal))
      return false;
    const Vec3 p = mesh_.point(v);
    const SurfacePoint there = closest_around(goal, p, loc(v).face, 2 * length_);
    const Vec3 q = options_.project ? evaluate(input_, there) : goal;
    if (!ring_keeps_faces(v, q) || !(ring_min_angle(v, q) > ring_min_angle(v, p))) return false;
    loc(v) = there;
    mesh_.set_point(v, q);
    return true;
  }

  // The closest point to q on the input faces within `radius` of `from` (a point on face
  // `start`): a breadth-first search across the input's edges, at most 4096 faces. Unlike
  // relocate()'s walks it finds the closest point where the surface curls back between `from`
  // and q; the repairs' rare moves can pay for it.
  SurfacePoint closest_around(const Vec3& q, const Vec3& from, FaceHandle start,
                              double radius) const {
    const double radius2 = radius * radius;
    std::vector<FaceHandle> queue{start};
    std::unordered_set<int> seen{start.idx()};
    SurfacePoint best;
    double best_d2 = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < queue.size() && queue.size() < 4096; ++i) {
      const FaceHandle f = queue[i];
      const auto fv = face_vertices(input_, f);
      const Vec3 &a = input_.point(fv[0]), &b = input_.point(fv[1]), &c = input_.point(fv[2]);
      const TriangleClosest to_q = closest_point_on_triangle(q, a, b, c);
      if (to_q.distance2 < best_d2) {
        best_d2 = to_q.distance2;
        best = SurfacePoint{f, to_q.bary};
      }
      for (auto h : input_.fh_range(f)) {
        const FaceHandle g = input_.opposite_face_handle(h);
        if (!g.is_valid() || seen.count(g.idx())) continue;
        seen.insert(g.idx());
        const auto gv = face_vertices(input_, g);
        if (closest_point_on_triangle(from, input_.point(gv[0]), input_.point(gv[1]),
                                      input_.point(gv[2]))
                .distance2 <= radius2)
          queue.push_back(g);
      }
    }
    return best;
  }

  // The smallest angle (radians) of the faces around v, with v at q.
  double ring_min_angle(VertexHandle v, const Vec3& q) const {
    double smallest = M_PI;
    for (auto h : mesh_.voh_range(v)) {
      if (mesh_.is_boundary(h)) continue;
      const Vec3& a = mesh_.point(mesh_.to_vertex_handle(h));
      const Vec3& b = mesh_.point(mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h)));
      const auto t = triangle_angles(q, a, b);
      smallest = std::min({smallest, t[0], t[1], t[2]});
    }
    return smallest;
  }

  // One sweep of repair_bad_triangles().
  std::size_t repair_pass(double min_deg) {
    const double min_rad = min_deg * M_PI / 180.0;
    const double cos_min = std::cos(min_rad);
    std::size_t count = 0;
    const std::size_t n = mesh_.n_faces();
    for (std::size_t i = 0; i < n; ++i) {
      const FaceHandle f(static_cast<int>(i));
      if (mesh_.status(f).deleted()) continue;
      // The face's halfedges, opposite its three corners.
      HalfedgeHandle hs[3];
      hs[0] = mesh_.halfedge_handle(f);
      hs[1] = mesh_.next_halfedge_handle(hs[0]);
      hs[2] = mesh_.next_halfedge_handle(hs[1]);
      double len[3];
      for (int k = 0; k < 3; ++k) len[k] = mesh_.calc_edge_sqr_length(hs[k]);
      const int shortest = static_cast<int>(std::min_element(len, len + 3) - len);
      // The smallest angle is the one opposite the shortest edge: a cosine clearly below the
      // limit's settles almost every face without the exact angles.
      {
        const HalfedgeHandle a = hs[(shortest + 1) % 3], b = hs[(shortest + 2) % 3];
        const Vec3 u =
            mesh_.point(mesh_.to_vertex_handle(a)) - mesh_.point(mesh_.from_vertex_handle(a));
        const Vec3 w =
            mesh_.point(mesh_.from_vertex_handle(b)) - mesh_.point(mesh_.to_vertex_handle(b));
        const double lengths = std::sqrt(u.sqrnorm() * w.sqrnorm());
        if (lengths > 0 && OpenMesh::dot(u, w) < (cos_min - 1e-9) * lengths) continue;
      }
      const auto fv = face_vertices(mesh_, f);
      if (min_angle(fv[0], fv[1], fv[2]) >= min_rad) continue;
      const int longest = static_cast<int>(std::max_element(len, len + 3) - len);
      const EdgeHandle el = mesh_.edge_handle(hs[longest]);
      if (try_repair_flip(el)) {
        ++count;
        continue;
      }
      if (try_collapse(mesh_.edge_handle(hs[shortest]), Collapse::Repair)) {
        ++count;
        continue;
      }
      // A flat face (three corners on a line, as on a sharp crease) is worth any collapse of
      // its edges that the rules allow, the other two included; last, one that may leave edges
      // up to 8/3 l. A face across a crack of the input (two boundary vertices on one side, one
      // on the other, all on the crack's line, next to its tip) had no other way out: there a
      // curve vertex goes into the tip.
      if (face_cross(f).norm() <= flat_cross_) {
        bool done = false;
        for (int k : {(shortest + 1) % 3, (shortest + 2) % 3})
          if (!done && try_collapse(mesh_.edge_handle(hs[k]), Collapse::Repair)) {
            ++count;
            done = true;
          }
        for (int k = 0; k < 3 && !done; ++k)
          if (try_repair_move(fv[k])) {
            ++count;
            done = true;
          }
        for (int k = 0; k < 3 && !done; ++k)
          if (try_collapse(mesh_.edge_handle(hs[k]), Collapse::Degenerate)) {
            ++count;
            done = true;
          }
        if (done) continue;
      }
      // With feature lines, a sliver between two curves that no legal operation fixes (two
      // lines that leave a corner 0.5 degrees apart, a line folded back on itself: scan noise
      // at 45 degrees) is worth merging two of its curve vertices, the corner kept if one is.
      if (feature_count_ > 0 && min_angle(fv[0], fv[1], fv[2]) < kFlatRepairRad)
        for (int k : {shortest, (shortest + 1) % 3, (shortest + 2) % 3})
          if (try_collapse(mesh_.edge_handle(hs[k]), Collapse::Flat)) {
            ++count;
            break;
          }
    }
    return count;
  }

  // Twice the area vector of face f at the current positions.
  Vec3 face_cross(FaceHandle f) const {
    const auto fv = face_vertices(mesh_, f);
    const Vec3& p = mesh_.point(fv[0]);
    return OpenMesh::cross(mesh_.point(fv[1]) - p, mesh_.point(fv[2]) - p);
  }

  // One pass of valence-improving flips over all edges. Valences and targets (6 inside, 4 on
  // the boundary) are cached per vertex and updated by each flip.
  std::size_t equalize_valences() {
    const std::size_t nv = mesh_.n_vertices();
    std::vector<int> excess(nv, 0); // valence minus target valence
    parallel_for(nv, options_.threads, [&](std::size_t i) {
      const VertexHandle v(static_cast<int>(i));
      if (mesh_.status(v).deleted()) return;
      excess[i] = static_cast<int>(mesh_.valence(v)) - (mesh_.is_boundary(v) ? 4 : 6);
    });
    std::size_t count = 0;
    const std::size_t n = mesh_.n_edges();
    for (std::size_t i = 0; i < n; ++i) {
      const EdgeHandle e(static_cast<int>(i));
      if (mesh_.status(e).deleted() || on_curve(e)) continue;
      const HalfedgeHandle h0 = mesh_.halfedge_handle(e, 0), h1 = mesh_.halfedge_handle(e, 1);
      const VertexHandle a = mesh_.to_vertex_handle(h0), b = mesh_.to_vertex_handle(h1);
      const VertexHandle c = mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h0));
      const VertexHandle d = mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h1));
      if (c == d) continue;
      int& xa = excess[static_cast<std::size_t>(a.idx())];
      int& xb = excess[static_cast<std::size_t>(b.idx())];
      int& xc = excess[static_cast<std::size_t>(c.idx())];
      int& xd = excess[static_cast<std::size_t>(d.idx())];
      auto sq = [](int x) { return x * x; };
      const int before = sq(xa) + sq(xb) + sq(xc) + sq(xd);
      const int after = sq(xa - 1) + sq(xb - 1) + sq(xc + 1) + sq(xd + 1);
      if (after >= before || !mesh_.is_flip_ok(e)) continue;
      if (!flip_keeps_orientation(a, b, c, d)) continue;
      mesh_.flip(e);
      --xa;
      --xb;
      ++xc;
      ++xd;
      ++count;
    }
    return count;
  }

  // The triangles (b, a, c) and (a, b, d) around edge ab become (a, c, d) and (c, b, d): both must
  // face the way the pair did, and neither may be degenerate. Neither may span a feature line
  // at a or b either (spans_line).
  bool flip_keeps_orientation(VertexHandle a, VertexHandle b, VertexHandle c,
                              VertexHandle d) const {
    if (feature_count_ > 0 && (spans_line(a, c, d) || spans_line(b, c, d))) return false;
    const Vec3 pa = mesh_.point(a), pb = mesh_.point(b), pc = mesh_.point(c), pd = mesh_.point(d);
    const Vec3 n_old = OpenMesh::cross(pa - pb, pc - pb) + OpenMesh::cross(pb - pa, pd - pa);
    const Vec3 n1 = OpenMesh::cross(pc - pa, pd - pa);
    const Vec3 n2 = OpenMesh::cross(pb - pc, pd - pc);
    // No new face flat by the repair's measure (flat_cross_): where boundary vertices of a
    // thinned input coincide to 1e-4 l, a flip made a face whose corners all sat there (19 of
    // 3,000 thinned meshes at 12 cycles, 1 at 7; 1e-12 × (4/3 l)² let them through).
    if (n1.norm() <= flat_cross_ || n2.norm() <= flat_cross_) return false;
    return OpenMesh::dot(n1, n_old) > 0 && OpenMesh::dot(n2, n_old) > 0 &&
           OpenMesh::dot(n1, n2) > 0.5 * n1.norm() * n2.norm();
  }

  // Would the triangle (v, c, d) have both of v's feature edges, v a vertex inside a line? The
  // smoothing along the line puts v at the midpoint of c and d: on a straight line the triangle
  // goes flat (the bunny at 45 degrees had 7 flat faces so).
  bool spans_line(VertexHandle v, VertexHandle c, VertexHandle d) const {
    if (kind(v) != Kind::Curve || mesh_.is_boundary(v)) return false;
    int both = 0;
    for (auto h : mesh_.voh_range(v)) {
      const VertexHandle w = mesh_.to_vertex_handle(h);
      if ((w == c || w == d) && feature(mesh_.edge_handle(h))) ++both;
    }
    return both == 2;
  }

  // Area-weighted vertex normal (zero for a vertex whose faces all have zero area).
  Vec3 vertex_normal(VertexHandle v) const {
    Vec3 n(0, 0, 0);
    for (auto h : mesh_.voh_range(v)) {
      if (mesh_.is_boundary(h)) continue;
      const Vec3 p = mesh_.point(v);
      const Vec3 q = mesh_.point(mesh_.to_vertex_handle(h));
      const Vec3 r = mesh_.point(mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h)));
      n += OpenMesh::cross(q - p, r - p);
    }
    const double len = n.norm();
    return len > 0 ? n / len : Vec3(0, 0, 0);
  }

  // Moves every vertex by `update(v)` (tangential for interior vertices, along the boundary for
  // boundary ones), then back onto the input. One data-parallel loop computes each target from
  // the current positions and places it on the input (a relocation reads and writes only its
  // own vertex's location); the new positions are applied after it.
  template <class Target>
  void move_vertices(Target&& target) {
    move_vertices_placing([&](VertexHandle v, Vec3& out) {
      Vec3 g;
      if (!target(v, g)) return Placed::No;
      if (kind(v) != Kind::Curve) {
        out = relocate(v, g, v);
        return Placed::Moved;
      }
      // A curve vertex slides along its curve, which may run back along itself: the two sides
      // of a crack in the input, which meet at a pinched vertex the loader split. Slid onto
      // the other side, its faces spanned the crack and went flat (randomly thinned grids: 15
      // of 300 had flat output faces). It stays where a face of its ring would go flat or turn
      // over; placed on its curve there (a split or a collapse may have left it at a chord's
      // midpoint, for the smoothing to place).
      const SurfacePoint before = loc(v);
      const HalfedgeHandle before_curve = bloc(v);
      out = relocate(v, g, v);
      if (ring_keeps_faces(v, out)) return Placed::Moved;
      loc(v) = before;
      bloc(v) = before_curve;
      out = relocate(v, mesh_.point(v), v);
      return Placed::Moved;
    });
  }

  // Would moving v to q keep each face around it from going flat or turning over (against its
  // normal now, where it has one)?
  bool ring_keeps_faces(VertexHandle v, const Vec3& q) const {
    const Vec3 p = mesh_.point(v);
    const double tiny = 1e-12 * hi2_;
    for (auto h : mesh_.voh_range(v)) {
      if (mesh_.is_boundary(h)) continue;
      const Vec3& a = mesh_.point(mesh_.to_vertex_handle(h));
      const Vec3& b = mesh_.point(mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h)));
      const Vec3 n_new = OpenMesh::cross(a - q, b - q);
      if (n_new.norm() <= tiny) return false;
      const Vec3 n_old = OpenMesh::cross(a - p, b - p);
      if (n_old.norm() > tiny && !(OpenMesh::dot(n_new, n_old) > 0)) return false;
    }
    return true;
  }

  // What a placing target did with its vertex.
  enum class Placed : char { No, Moved, Shortened, Dropped };

  // The same loop for a target that places its vertex on the input itself (`out`), so that it
  // can test the placed position (the fine-tuning's sliver guard).
  template <class Place>
  void move_vertices_placing(Place&& place) {
    const std::size_t n = mesh_.n_vertices();
    std::vector<Vec3>& placed = placed_; // kept between calls: no fresh pages each time
    std::vector<Placed>& moves = moves_;
    placed.resize(n);
    moves.assign(n, Placed::No);
    parallel_for(n, options_.threads, [&](std::size_t i) {
      const VertexHandle v(static_cast<int>(i));
      if (mesh_.status(v).deleted() || kind(v) == Kind::Corner || mesh_.is_isolated(v)) return;
      moves[i] = place(v, placed[i]);
    });
    for (std::size_t i = 0; i < n; ++i) {
      if (moves[i] == Placed::Moved || moves[i] == Placed::Shortened)
        mesh_.set_point(VertexHandle(static_cast<int>(i)), placed[i]);
      guarded_ += moves[i] == Placed::Shortened || moves[i] == Placed::Dropped ? 1 : 0;
    }
    reproject_points();
  }

  // A vertex's one-ring as the fine-tuning reads it: ring[j] = to(h_j) for its outgoing
  // halfedges h_j, face j = (v, ring[j], ring[third[j]]) when face[j] is valid.
  struct Ring {
    static constexpr int kMax = 64;
    VertexHandle ring[kMax];
    FaceHandle face[kMax];
    int third[kMax];
    int k = 0;
    bool boundary_band = false; // keep the edges to the ring's boundary vertices in the band
  };

  // Is the cosine of the smallest angle of every face of `r`, with its centre at q, at most
  // `limit` (in [0, 1])? No square root: the cosine opposite the shortest side s,
  // (e1 + e2 - s) / (2 sqrt(e1 e2)) in squared lengths, has a non-negative numerator.
  bool ring_within(const Ring& r, const Vec3& q, double limit) const {
    const double limit2 = 4 * limit * limit;
    for (int j = 0; j < r.k; ++j) {
      if (!r.face[j].is_valid()) continue;
      const Vec3& a = mesh_.point(r.ring[j]);
      const Vec3& b = mesh_.point(r.ring[r.third[j]]);
      const double x = (a - q).sqrnorm(), y = (b - q).sqrnorm(), z = (a - b).sqrnorm();
      double s = x, e1 = y, e2 = z;
      if (e1 < s) std::swap(s, e1);
      if (e2 < s) std::swap(s, e2);
      const double numerator = e1 + e2 - s;
      if (numerator * numerator > limit2 * e1 * e2) return false;
    }
    return true;
  }

  // The sliver guard (equalize_guard_deg): places v at `goal`, or halfway back, twice at most,
  // so that no face of its ring falls below the guard angle, nor below the ring's smallest angle
  // where that is smaller already; else v stays. Tested after the placement on the input: on a
  // part about four edges around (the smoothed fertility's arm) the projection, not the
  // tangential step, is what squeezed an edge to 0.31 l. Next to the boundary the same holds for
  // the length of each edge to a boundary vertex: at most 4/3 l, or its length now if longer
  // (equalize_boundary pulls these vertices inwards, to grow the boundary cells).
  Placed guarded_place(VertexHandle v, Vec3 goal, const Ring& r, Vec3& out) {
    const Vec3 p = mesh_.point(v);
    // The ring's smallest angle now (face_data_[f][3], from the iteration's face loop), how far v
    // may move before any angle of its ring can reach the limit: moving v by δ turns each angle
    // of a face (v, a, b) by at most 2|δ| / (r − |δ|), r the shorter of |va| and |vb|.
    double worst = -1, shortest2 = std::numeric_limits<double>::max();
    for (int j = 0; j < r.k; ++j) {
      shortest2 = std::min(shortest2, (mesh_.point(r.ring[j]) - p).sqrnorm());
      if (r.face[j].is_valid())
        worst = std::max(worst, face_data_[static_cast<std::size_t>(r.face[j].idx())][3]);
    }
    const double limit = std::max(worst, cos_guard_);
    const double margin = std::acos(std::clamp(worst, -1.0, 1.0)) - guard_rad_;
    const double safe = margin > 0 ? margin * std::sqrt(shortest2) / (2 + margin) : 0.0;
    // Next to the boundary: every edge of the ring stays in the band [4/5 l, 4/3 l], or no
    // further out of it than it is now.
    double reach2 = hi2_, short2 = lo2_;
    if (r.boundary_band)
      for (int j = 0; j < r.k; ++j) {
        const double d2 = (mesh_.point(r.ring[j]) - p).sqrnorm();
        reach2 = std::max(reach2, d2);
        short2 = std::min(short2, d2);
      }
    auto edges_within = [&](const Vec3& q) {
      if (!r.boundary_band) return true;
      for (int j = 0; j < r.k; ++j) {
        const double d2 = (mesh_.point(r.ring[j]) - q).sqrnorm();
        if (d2 > reach2 || d2 < short2) return false;
      }
      return true;
    };
    // A goal that would stretch an edge to a boundary vertex beyond the band is first pulled
    // back into it: alternating projections onto the balls of radius √reach2 around the ring's
    // boundary vertices, whose intersection is convex and holds p. The vertex then slides along
    // the band's limit, centring itself between its two boundary neighbours, instead of stopping
    // at the first edge that reaches it (halving the step, below).
    if (r.boundary_band) {
      const double reach = std::sqrt(reach2) * (1 - 1e-9);
      for (int pass = 0; pass < 4; ++pass)
        for (int j = 0; j < r.k; ++j) {
          if (!mesh_.is_boundary(r.ring[j])) continue;
          const Vec3& a = mesh_.point(r.ring[j]);
          const double d = (goal - a).norm();
          if (d > reach) goal = a + (goal - a) * (reach / d);
        }
    }
    const SurfacePoint before = loc(v);
    for (int tries = 0; tries < 3; ++tries, goal = (p + goal) * 0.5) {
      out = relocate(v, goal, v);
      if (!edges_within(out)) continue;
      if ((out - p).sqrnorm() <= safe * safe || ring_within(r, out, limit))
        return tries == 0 ? Placed::Moved : Placed::Shortened;
    }
    loc(v) = before;
    return Placed::Dropped;
  }

  // Where a curve vertex goes: the midpoint of its two neighbours along the curve, relaxed by
  // `weight`.
  bool curve_target(VertexHandle v, double weight, Vec3& goal) const {
    VertexHandle next, prev;
    const HalfedgeHandle out = boundary_out(mesh_, v);
    if (out.is_valid()) {
      next = mesh_.to_vertex_handle(out);
      prev = mesh_.from_vertex_handle(mesh_.prev_halfedge_handle(out));
      // An ear (v's only face is (prev, v, next)) would flatten that face by moving towards the
      // midpoint of its other corners: a thinned input's islands, collapsed to one triangle,
      // went flat so after 12 cycles (2 of 3,000). It stays.
      if (mesh_.valence(v) == 2) {
        goal = mesh_.point(v);
        return true;
      }
    } else {
      int n = 0;
      for (auto h : mesh_.voh_range(v))
        if (feature(mesh_.edge_handle(h))) (n++ == 0 ? next : prev) = mesh_.to_vertex_handle(h);
      // Where the line is not a simple path through v (a repair merged two lines), or a face
      // (prev, v, next) would go flat on a straight line (spans_line), v stays where it is; it
      // is still placed on its line: a split may have left it at a chord's midpoint.
      bool stays = n != 2;
      for (auto h : mesh_.voh_range(v))
        stays = stays || (!mesh_.is_boundary(h) &&
                          spans_line(v, mesh_.to_vertex_handle(h),
                                     mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h))));
      if (stays) {
        goal = mesh_.point(v);
        return true;
      }
    }
    const Vec3 mid = (mesh_.point(next) + mesh_.point(prev)) * 0.5;
    goal = mesh_.point(v) + (mid - mesh_.point(v)) * weight;
    return true;
  }

  // The working mesh's boundary loops cut at their corners into runs u_0 ... u_m (u_0 and u_m
  // corners; a loop without corners is one run with u_m = u_0).
  std::vector<std::vector<VertexHandle>> boundary_runs() const {
    std::vector<std::vector<VertexHandle>> runs;
    std::vector<char> seen(mesh_.n_halfedges(), 0);
    for (auto h0 : mesh_.halfedges()) {
      if (!mesh_.is_boundary(h0) || seen[static_cast<std::size_t>(h0.idx())]) continue;
      std::vector<VertexHandle> loop;
      HalfedgeHandle h = h0;
      do {
        seen[static_cast<std::size_t>(h.idx())] = 1;
        loop.push_back(mesh_.from_vertex_handle(h));
        h = mesh_.next_halfedge_handle(h);
      } while (h != h0 && loop.size() <= mesh_.n_vertices());
      const auto corner = std::find_if(loop.begin(), loop.end(),
                                       [&](VertexHandle v) { return kind(v) == Kind::Corner; });
      if (corner != loop.end()) std::rotate(loop.begin(), corner, loop.end());
      loop.push_back(loop.front());
      std::vector<VertexHandle> run{loop.front()};
      for (std::size_t i = 1; i < loop.size(); ++i) {
        run.push_back(loop[i]);
        if (kind(loop[i]) == Kind::Corner || i + 1 == loop.size()) {
          runs.push_back(run);
          run = {loop[i]};
        }
      }
    }
    return runs;
  }

  // boundary_spacing: collapses evenly chosen vertices of each run whose spacing is below
  // boundary_spacing × l, then spaces the run's vertices evenly along it (by chord length, then
  // placed on the input boundary). Returns the number of collapses.
  std::size_t resample_boundary() {
    if (!has_boundary_) return 0;
    const double spacing = options_.boundary_spacing * length_;
    std::size_t collapsed = 0;
    for (const auto& run : boundary_runs()) {
      const std::size_t m = run.size() - 1;
      double length = 0;
      for (std::size_t i = 0; i < m; ++i)
        length += (mesh_.point(run[i + 1]) - mesh_.point(run[i])).norm();
      const auto wanted = static_cast<std::size_t>(std::max(1.0, std::ceil(length / spacing)));
      if (wanted >= m || m < 3) continue;
      const std::size_t remove = std::min(m - wanted, m - 2);
      for (std::size_t j = 0; j < remove; ++j) {
        const std::size_t i =
            1 + static_cast<std::size_t>((static_cast<double>(j) + 0.5) *
                                         static_cast<double>(m - 1) / static_cast<double>(remove));
        const VertexHandle v = run[std::min(i, m - 1)];
        if (mesh_.status(v).deleted() || kind(v) != Kind::Curve) continue;
        const HalfedgeHandle out = boundary_out(mesh_, v);
        if (!out.is_valid()) continue;
        collapsed += try_collapse(mesh_.edge_handle(out), Collapse::Boundary) ? 1 : 0;
      }
    }
    // Even spacing along each run, by arc length of its chords.
    std::vector<Vec3> goal(mesh_.n_vertices());
    std::vector<char> has(mesh_.n_vertices(), 0);
    for (const auto& run : boundary_runs()) {
      const std::size_t m = run.size() - 1;
      if (m < 2) continue;
      std::vector<double> at(m + 1, 0.0);
      for (std::size_t i = 0; i < m; ++i)
        at[i + 1] = at[i] + (mesh_.point(run[i + 1]) - mesh_.point(run[i])).norm();
      std::size_t k = 0;
      for (std::size_t i = 1; i < m; ++i) {
        const double s = at[m] * static_cast<double>(i) / static_cast<double>(m);
        while (k + 1 < m && at[k + 1] < s) ++k;
        const double span = at[k + 1] - at[k];
        const double t = span > 0 ? (s - at[k]) / span : 0.0;
        goal[static_cast<std::size_t>(run[i].idx())] =
            mesh_.point(run[k]) * (1 - t) + mesh_.point(run[k + 1]) * t;
        has[static_cast<std::size_t>(run[i].idx())] = kind(run[i]) == Kind::Curve;
      }
    }
    move_vertices([&](VertexHandle v, Vec3& g) {
      if (!has[static_cast<std::size_t>(v.idx())]) return false;
      g = goal[static_cast<std::size_t>(v.idx())];
      return true;
    });
    return collapsed;
  }

  void tangential_smoothing() {
    move_vertices([&](VertexHandle v, Vec3& goal) {
      if (kind(v) == Kind::Curve) return curve_target(v, 0.5, goal);
      return centroid_target(v, goal);
    });
  }

  // v's one-ring centroid, the move to it projected into v's tangent plane; false for an
  // isolated vertex.
  bool centroid_target(VertexHandle v, Vec3& goal) const {
    Vec3 centroid(0, 0, 0);
    int k = 0;
    for (auto w : mesh_.vv_range(v)) {
      centroid += mesh_.point(w);
      ++k;
    }
    if (k == 0) return false;
    const Vec3 p = mesh_.point(v);
    Vec3 u = centroid / k - p;
    const Vec3 n = vertex_normal(v);
    u -= n * OpenMesh::dot(n, u);
    goal = p + u;
    return true;
  }

  // One fine-tuning iteration; returns the number of Delaunay flips it made.
  std::size_t equalize_areas() {
    if (options_.equalization == Equalization::Gravity)
      equalize_areas_gravity();
    else
      equalize_areas_newton();
    return options_.equalize_flips ? delaunay_flips() : 0;
  }

  // Flips every interior edge whose opposite angles sum to more than π (cot α + cot β < 0),
  // where the flip keeps the mesh manifold and the faces' orientation. The test runs on all
  // edges at once, data-parallel; the flips of the marked edges follow in edge order, each
  // tested again on the mesh as the earlier flips left it.
  std::size_t delaunay_flips() {
    const std::size_t n = mesh_.n_edges();
    std::vector<char>& marked = marked_; // kept between iterations
    marked.assign(n, 0);
    parallel_for(n, options_.threads, [&](std::size_t i) {
      const EdgeHandle e(static_cast<int>(i));
      if (mesh_.status(e).deleted() || on_curve(e)) return;
      marked[i] = violates_delaunay(e) ? 1 : 0;
    });
    std::size_t count = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!marked[i]) continue;
      const EdgeHandle e(static_cast<int>(i));
      if (!violates_delaunay(e) || !mesh_.is_flip_ok(e)) continue;
      const HalfedgeHandle h0 = mesh_.halfedge_handle(e, 0), h1 = mesh_.halfedge_handle(e, 1);
      const VertexHandle a = mesh_.to_vertex_handle(h0), b = mesh_.to_vertex_handle(h1);
      const VertexHandle c = mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h0));
      const VertexHandle d = mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h1));
      if (!flip_keeps_orientation(a, b, c, d)) continue;
      mesh_.flip(e);
      ++count;
    }
    return count;
  }

  // Do the two angles opposite interior edge e sum to more than π?
  bool violates_delaunay(EdgeHandle e) const {
    const HalfedgeHandle h0 = mesh_.halfedge_handle(e, 0), h1 = mesh_.halfedge_handle(e, 1);
    const Vec3& a = mesh_.point(mesh_.to_vertex_handle(h0));
    const Vec3& b = mesh_.point(mesh_.to_vertex_handle(h1));
    const Vec3& c = mesh_.point(mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h0)));
    const Vec3& d = mesh_.point(mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h1)));
    // cot of the angle at c (between c->a and c->b) and at d; their sum is negative exactly when
    // the angles sum to more than π.
    const Vec3 ca = a - c, cb = b - c, da = a - d, db = b - d;
    const double dc = OpenMesh::dot(ca, cb), dd = OpenMesh::dot(da, db);
    if (dc >= 0 && dd >= 0) return false; // two angles of at most 90 degrees: most edges
    const double sc = OpenMesh::cross(ca, cb).norm(), sd = OpenMesh::cross(da, db).norm();
    if (!(sc > 0) || !(sd > 0)) return false; // degenerate: the repair's business
    return dc * sd + dd * sc < 0;
  }

  // §4: p_i += λ (I − n nᵀ)(g_i − p_i), g_i the area-weighted centroid of the one-ring.
  void equalize_areas_gravity() {
    const Eigen::VectorXd area = vertex_areas_mixed(mesh_);
    move_vertices([&](VertexHandle v, Vec3& goal) {
      if (kind(v) == Kind::Curve) return false; // curve vertices keep their spacing
      Vec3 g(0, 0, 0);
      double w = 0;
      for (auto u : mesh_.vv_range(v)) {
        g += mesh_.point(u) * area[u.idx()];
        w += area[u.idx()];
      }
      if (!(w > 0)) return false;
      const Vec3 p = mesh_.point(v);
      Vec3 d = g / w - p;
      const Vec3 n = vertex_normal(v);
      d -= n * OpenMesh::dot(n, d);
      goal = p + d * options_.lambda;
      return true;
    });
  }

  // A regularized Gauss-Newton step per vertex on the residuals r_j = A_j − Ā (mixed areas) of
  // the interior vertices of its closed one-ring, in the tangent plane:
  //   δ_i = −λ (J_iᵀ J_i + μ I)⁻¹ (J_iᵀ r + μ (p_i − c_i)),
  // J_i = ∂A_j/∂p_i by forward differences of the incident faces' mixed-area parts (only those
  // depend on p_i), c_i the one-ring centroid; the μ term is the tangential smoothing of the
  // cycles, which keeps triangles well shaped while the areas are pulled to their mean. Unlike
  // the gravity update, whose fixed point is not an equal-area mesh, r = 0 is (up to μ) this
  // iteration's fixed point. Jacobi-style (all vertices at once), hence the damping λ.
  void equalize_areas_newton() {
    // The mixed-area parts of every face at the current positions (face_vertices order), and the
    // vertex areas they sum to.
    const std::size_t nf = mesh_.n_faces();
    // Per face: its three mixed-area parts and, for the guard, the cosine of its smallest angle
    // (one cache line's worth for both readers).
    std::vector<std::array<double, 4>>& face_parts = face_data_; // kept between iterations
    face_parts.resize(nf);
    const bool guard = options_.equalize_guard_deg > 0;

    parallel_for(nf, options_.threads, [&](std::size_t i) {
      const FaceHandle f(static_cast<int>(i));
      if (mesh_.status(f).deleted()) return;
      const auto fv = face_vertices(mesh_, f);
      const Vec3 &a = mesh_.point(fv[0]), &b = mesh_.point(fv[1]), &c = mesh_.point(fv[2]);
      const auto parts = triangle_mixed_areas(a, b, c);
      face_parts[i] = {parts[0], parts[1], parts[2], guard ? smallest_angle_cos(a, b, c) : 1.0};
    });
    std::vector<double>& area = vertex_areas_;
    area.assign(mesh_.n_vertices(), 0.0);
    for (std::size_t i = 0; i < nf; ++i) {
      const FaceHandle f(static_cast<int>(i));
      if (mesh_.status(f).deleted()) continue;
      const auto fv = face_vertices(mesh_, f);
      for (int c = 0; c < 3; ++c) area[static_cast<std::size_t>(fv[c].idx())] += face_parts[i][c];
    }
    double sum = 0;
    std::size_t count = 0;
    for (auto v : mesh_.vertices())
      if (!mesh_.is_boundary(v) && !mesh_.is_isolated(v)) {
        sum += area[static_cast<std::size_t>(v.idx())];
        ++count;
      }
    if (count == 0) return;
    const double target = sum / static_cast<double>(count);
    const double eps = 1e-4 * length_;
    // Heavy-ball momentum (equalize_momentum): the positions at the start of the previous
    // iteration give each vertex's last move. Vertices are neither added nor removed between
    // iterations (the Delaunay flips only reconnect them).
    const double beta = options_.equalize_momentum;
    const bool momentum = beta > 0 && previous_points_.size() == mesh_.n_vertices();
    if (beta > 0) { // no copy when the momentum is off
      current_points_.resize(mesh_.n_vertices());
      for (auto v : mesh_.vertices())
        current_points_[static_cast<std::size_t>(v.idx())] = mesh_.point(v);
    }
    auto newton_goal = [&](VertexHandle v, Vec3& goal, Ring& r) {
      if (kind(v) != Kind::Interior) return false;
      const Vec3 p = mesh_.point(v);
      // The one-ring: ring[j] = to(h_j); face j = (v, ring[j], ring[third[j]]) when it exists.
      constexpr int kMax = Ring::kMax;
      VertexHandle* ring = r.ring;
      FaceHandle* face = r.face;
      int* third = r.third;
      int& k = r.k;
      k = 0;
      for (auto h : mesh_.voh_range(v)) {
        if (k == kMax) return false;
        ring[k] = mesh_.to_vertex_handle(h);
        face[k] = mesh_.face_handle(h);
        ++k;
      }
      if (k < 3) return false;
      // Next to the boundary (which does not move here) the vertex either takes the Newton step
      // on residuals that include the boundary vertices' (equalize_boundary; its placement then
      // keeps the edges to them in the band), or plain tangential smoothing.
      bool near_boundary = false;
      for (int j = 0; j < k; ++j) near_boundary |= mesh_.is_boundary(ring[j]);
      r.boundary_band = near_boundary && options_.equalize_boundary;
      // The circulator turns one way: the third corner of face j is ring[j + 1] or ring[j - 1].
      const HalfedgeHandle h0 = *mesh_.cvoh_begin(v);
      const VertexHandle c0 = mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h0));
      const int turn = c0 == ring[1] ? 1 : k - 1;
      Vec3 centroid(0, 0, 0), normal(0, 0, 0);
      for (int j = 0; j < k; ++j) {
        third[j] = (j + turn) % k;
        centroid += mesh_.point(ring[j]);
        if (face[j].is_valid())
          normal += OpenMesh::cross(mesh_.point(ring[j]) - p, mesh_.point(ring[third[j]]) - p);
      }
      centroid /= k;
      const double normal_length = normal.norm();
      if (!(normal_length > 0)) return false;
      const Vec3 n = normal / normal_length;
      if (near_boundary && !options_.equalize_boundary) {
        Vec3 u = centroid - p;
        u -= n * OpenMesh::dot(n, u);
        goal = p + u * options_.lambda;
        return true;
      }
      // Mixed-area parts of v (index k) and of each ring vertex from the faces around v: at the
      // current position from face_parts, for v moved to q recomputed.
      double base[kMax + 1] = {}, moved[kMax + 1], d1[kMax + 1], d2[kMax + 1];
      for (int j = 0; j < k; ++j) {
        if (!face[j].is_valid()) continue;
        const auto fv = face_vertices(mesh_, face[j]);
        const auto& part = face_parts[static_cast<std::size_t>(face[j].idx())];
        for (int c = 0; c < 3; ++c)
          base[fv[c] == v ? k : fv[c] == ring[j] ? j : third[j]] += part[c];
      }
      auto parts = [&](const Vec3& q, double* out) {
        for (int j = 0; j <= k; ++j) out[j] = 0;
        for (int j = 0; j < k; ++j) {
          if (!face[j].is_valid()) continue;
          const auto m = triangle_mixed_areas(q, mesh_.point(ring[j]), mesh_.point(ring[third[j]]));
          out[k] += m[0];
          out[j] += m[1];
          out[third[j]] += m[2];
        }
      };
      Vec3 t1 = OpenMesh::cross(n, std::abs(n[0]) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0));
      t1.normalize();
      const Vec3 t2 = OpenMesh::cross(n, t1);
      for (int axis = 0; axis < 2; ++axis) {
        const Vec3 t = axis == 0 ? t1 : t2;
        double* d = axis == 0 ? d1 : d2;
        parts(p + t * eps, moved);
        for (int j = 0; j <= k; ++j) d[j] = (moved[j] - base[j]) / eps;
      }
      // Residuals: v itself (index k) and the ring's interior vertices (on feature lines too),
      // with equalize_boundary its boundary vertices too, corners included (their cells are the
      // smallest; with them the raw bunny's full defect went 0.068 -> 0.066).
      Eigen::Matrix2d jtj = Eigen::Matrix2d::Zero();
      Eigen::Vector2d jtr = Eigen::Vector2d::Zero();
      for (int j = 0; j <= k; ++j) {
        const VertexHandle w = j == k ? v : ring[j];
        if (mesh_.is_boundary(w) && !options_.equalize_boundary) continue;
        const Eigen::Vector2d row(d1[j], d2[j]);
        jtj += row * row.transpose();
        jtr += row * (area[static_cast<std::size_t>(w.idx())] - target);
      }
      const Vec3 off = p - (options_.smoothing_target == SmoothingTarget::Odt
                                ? odt_point(p, r, centroid, face_parts)
                                : centroid);
      const double mu = options_.equalize_smoothing * 0.5 * jtj.trace();
      jtj(0, 0) += mu;
      jtj(1, 1) += mu;
      jtr += mu * Eigen::Vector2d(OpenMesh::dot(off, t1), OpenMesh::dot(off, t2));
      if (!(jtj.determinant() > 0)) return false;
      const Eigen::Vector2d step = -jtj.inverse() * jtr * options_.lambda;
      Vec3 d = t1 * step[0] + t2 * step[1];
      if (momentum) { // β × the last move, in today's tangent plane
        Vec3 last = p - previous_points_[static_cast<std::size_t>(v.idx())];
        last -= n * OpenMesh::dot(n, last);
        d += last * beta;
      }
      // Never move by more than a fraction of the target length in one iteration.
      const double cap = 0.2 * length_;
      if (d.norm() > cap) d *= cap / d.norm();
      goal = p + d;
      return true;
    };
    move_vertices_placing([&](VertexHandle v, Vec3& out) {
      Ring r;
      Vec3 goal;
      if (!newton_goal(v, goal, r)) return Placed::No;
      if (!guard && !r.boundary_band) {
        out = relocate(v, goal, v);
        return Placed::Moved;
      }
      return guarded_place(v, goal, r, out);
    });
    std::swap(previous_points_, current_points_);
  }

  // The ODT point of v's closed one-ring `r` (v at p): the circumcentres of its faces weighted
  // by their areas, the vertex update of the optimal Delaunay triangulation energy (Chen & Xu
  // 2004; Alliez et al. 2005). A face's weight × its circumcentre's offset from p is bounded
  // (area × circumradius = the product of its sides / 4), so slivers do not throw it far;
  // `fallback` (the centroid) when the faces have no area. `parts` holds each face's mixed-area
  // parts at the current positions (equalize_areas_newton's face_data_): they sum to its area.
  Vec3 odt_point(const Vec3& p, const Ring& r, const Vec3& fallback,
                 const std::vector<std::array<double, 4>>& parts) const {
    Vec3 sum(0, 0, 0);
    double weight = 0;
    for (int j = 0; j < r.k; ++j) {
      if (!r.face[j].is_valid()) continue;
      const auto& part = parts[static_cast<std::size_t>(r.face[j].idx())];
      const double area = part[0] + part[1] + part[2];
      if (!(area > 0)) continue;
      const Vec3 a = mesh_.point(r.ring[j]) - p, b = mesh_.point(r.ring[r.third[j]]) - p;
      // Circumcentre offset: (|a|² b − |b|² a) × (a × b) / (2 |a × b|²), |a × b| = 2 area;
      // times the area.
      sum += OpenMesh::cross(b * a.sqrnorm() - a * b.sqrnorm(), OpenMesh::cross(a, b)) / (8 * area);
      weight += area;
    }
    return weight > 0 ? p + sum / weight : fallback;
  }

  // The cosine of the smallest angle of the triangle (a, b, c); 1 when degenerate.
  static double smallest_angle_cos(const Vec3& a, const Vec3& b, const Vec3& c) {
    double s = (b - a).sqrnorm(), e1 = (c - b).sqrnorm(), e2 = (a - c).sqrnorm();
    if (e1 < s) std::swap(s, e1);
    if (e2 < s) std::swap(s, e2);
    const double denominator = 2 * std::sqrt(e1 * e2);
    return denominator > 0 ? std::min(1.0, (e1 + e2 - s) / denominator) : 1.0;
  }

  const Mesh& input_;
  const RemeshOptions& options_;
  Mesh mesh_;
  OpenMesh::VPropHandleT<SurfacePoint> loc_prop_;    // where the vertex lies on the input
  OpenMesh::VPropHandleT<HalfedgeHandle> bloc_prop_; // curve vertices: a halfedge of the curve
  OpenMesh::VPropHandleT<Kind> kind_prop_;
  OpenMesh::EPropHandleT<char> feature_prop_; // the edge lies on a feature line of the input
  std::vector<char> input_curve_;             // per input edge: on the boundary or a feature line
  std::size_t feature_count_ = 0;             // feature edges of the input
  // Input -> output (see take_points): per input vertex its location and list neighbours.
  OpenMesh::FPropHandleT<PointList> points_prop_;
  std::vector<SurfacePoint> track_;
  std::vector<int> next_, prev_;
  std::vector<int> displaced_; // scratch: input vertices taken off faces an operation changes
  std::vector<SurfacePoint> reprojected_;              // scratch of reproject_points()
  std::vector<Vec3> placed_;                           // scratch of move_vertices()
  std::vector<Placed> moves_;                          // scratch of move_vertices()
  std::vector<char> marked_;                           // scratch of delaunay_flips()
  std::vector<std::array<double, 4>> face_data_;       // scratch of equalize_areas_newton()
  std::vector<double> vertex_areas_;                   // scratch of equalize_areas_newton()
  std::vector<Vec3> previous_points_, current_points_; // equalize_areas_newton(): momentum
  void add_working_properties() {
    mesh_.add_property(loc_prop_);
    mesh_.add_property(bloc_prop_);
    mesh_.add_property(kind_prop_);
    mesh_.add_property(feature_prop_);
    mesh_.add_property(points_prop_);
  }
  SurfacePoint& loc(VertexHandle v) { return mesh_.property(loc_prop_, v); }
  HalfedgeHandle& bloc(VertexHandle v) { return mesh_.property(bloc_prop_, v); }
  Kind& kind(VertexHandle v) { return mesh_.property(kind_prop_, v); }
  Kind kind(VertexHandle v) const { return mesh_.property(kind_prop_, v); }
  char& feature(EdgeHandle e) { return mesh_.property(feature_prop_, e); }
  char feature(EdgeHandle e) const { return mesh_.property(feature_prop_, e); }
  // Edges that flips leave alone and collapses keep on their curve.
  bool on_curve(EdgeHandle e) const { return mesh_.is_boundary(e) || feature(e); }
  double length_ = 0, lo2_ = 0, hi_ = 0, hi2_ = 0;
  double flat_cross_ = 0; // |cross| of a face at or below this is flat: 1e-6 l² (repair, flips)
  double guard_rad_ = 0, cos_guard_ = 1; // cosine of equalize_guard_deg
  std::size_t guarded_ = 0;              // moves the guard halved or dropped
  std::size_t max_faces_ = 0;
  bool has_boundary_ = false;  // the input has a boundary (mark_corners)
  std::size_t live_faces_ = 0; // faces not deleted (the mesh is compacted only between phases)
};

} // namespace

RemeshResult remesh(const Mesh& input, const RemeshOptions& options) {
  if (input.n_faces() == 0) throw InvalidArgument("remesh: the input mesh has no faces");
  if (options.cycles < 0 || options.max_cycles < 0 || options.equalize_iterations < 0 ||
      options.threads < 0)
    throw InvalidArgument(
        "remesh: cycles, max_cycles, equalize_iterations and threads must be >= 0");
  if (!(options.settle_fraction >= 0 && options.settle_fraction <= 1))
    throw InvalidArgument("remesh: settle_fraction must be in [0, 1] (1 = no extra cycles)");
  if (!std::isfinite(options.target_length) || !(options.length_factor > 0) ||
      !std::isfinite(options.length_factor))
    throw InvalidArgument("remesh: the target length and length factor must be finite, and the "
                          "factor positive");
  if (!(options.lambda > 0 && options.lambda <= 1))
    throw InvalidArgument("remesh: lambda must be in (0, 1]");
  if (!(options.equalize_smoothing >= 0 && std::isfinite(options.equalize_smoothing)))
    throw InvalidArgument("remesh: equalize_smoothing must be finite and >= 0");
  if (!(options.equalize_momentum >= 0 && options.equalize_momentum < 1))
    throw InvalidArgument("remesh: equalize_momentum must be in [0, 1) (0 = off)");
  if (!(options.corner_angle_deg >= 0 && options.corner_angle_deg <= 180))
    throw InvalidArgument("remesh: corner_angle_deg must be in [0, 180] degrees");
  if (!(options.equalize_guard_deg >= 0 && options.equalize_guard_deg < 60))
    throw InvalidArgument("remesh: equalize_guard_deg must be in [0, 60) degrees (0 = off)");
  if (!(options.feature_angle_deg >= 0 && options.feature_angle_deg < 180))
    throw InvalidArgument("remesh: feature_angle_deg must be in [0, 180) degrees (0 = no "
                          "features)");
  if (!(options.boundary_spacing <= 4.0 / 3.0))
    throw InvalidArgument("remesh: boundary_spacing must be at most 4/3 (longer boundary edges "
                          "are split again; <= 1 turns the spacing off)");
  // A large input is remeshed in a spatial order (copy_in_order), its walks and the first cycle
  // then read memory close to what they read before; the correspondence goes back to the
  // caller's numbering at the end. igea_sub4 (1.07M faces, Loop-subdivided): median 9.4 s ->
  // 8.6 s (docs/benchmarks.md, session 8).
  const bool compact =
      input.n_vertices() ==
      static_cast<std::size_t>(std::distance(input.vertices().begin(), input.vertices().end()));
  if (input.n_faces() <= kSpatialOrderFaces || !compact) return Remesher(input, options).run();
  const auto t0 = Clock::now();
  MeshOrder order;
  const Mesh sorted = copy_in_order(input, true, order);
  const double sort_ms = ms_since(t0);
  RemeshResult result = Remesher(sorted, options).run();
  result.report.milliseconds["reorder"] += sort_ms;
  result.report.milliseconds["total"] += sort_ms;
  for (SurfacePoint& p : result.output_on_input)
    if (p.face.is_valid()) p.face = FaceHandle(order.faces[static_cast<std::size_t>(p.face.idx())]);
  if (!result.input_on_output.empty()) {
    std::vector<SurfacePoint> by_input(input.n_vertices());
    for (std::size_t r = 0; r < order.vertices.size(); ++r)
      by_input[static_cast<std::size_t>(order.vertices[r])] = result.input_on_output[r];
    result.input_on_output = std::move(by_input);
  }
  return result;
}

nlohmann::json to_json(const RemeshReport& r) {
  return {{"target_length", r.target_length},
          {"length_from_area", r.length_from_area},
          {"feature_edges", r.feature_edges},
          {"cycles", r.cycles},
          {"input", to_json(r.input)},
          {"after_cycles", to_json(r.after_cycles)},
          {"after_equalization", to_json(r.after_equalization)},
          {"edges_in_band_percent",
           {{"after_cycles", r.edges_in_band_cycles}, {"output", r.edges_in_band_output}}},
          {"symmetry_defect",
           {{"input", r.symmetry_defect_input},
            {"after_cycles", r.symmetry_defect_cycles},
            {"output", r.symmetry_defect_output},
            {"output_interior_rows", r.symmetry_defect_output_interior}}},
          {"distance_to_input",
           {{"vertex_mean", r.vertex_distance_mean},
            {"vertex_max", r.vertex_distance_max},
            {"centroid_mean", r.centroid_distance_mean},
            {"centroid_max", r.centroid_distance_max}}},
          {"correspondence",
           {{"tracked_excess_mean", r.tracked_excess_mean},
            {"tracked_excess_max", r.tracked_excess_max},
            {"tracked_same_face", r.tracked_same_face}}},
          {"splits", r.splits},
          {"collapses", r.collapses},
          {"flips", r.flips},
          {"delaunay_flips", r.delaunay_flips},
          {"guarded_moves", r.guarded_moves},
          {"repairs", r.repairs},
          {"milliseconds", r.milliseconds}};
}

} // namespace remora
