// The input's curves: its boundary and, with feature_angle_deg, its feature lines. Output vertices
// on them slide only along them; corners, where a curve turns sharply at the scale of l or where
// lines end or meet, never move. The boundary's vertices are spaced once after the first cycle.

#include <algorithm>
#include <cmath>
#include <limits>

#include "remora/geometry/closest_point.h"
#include "remora/geometry/measures.h"
#include "remora/mesh/topology.h"

#include "remora/remesh/remesher.h"

namespace remora::remesh_detail {

namespace {

// Closed curves shorter than this many target lengths keep at least three corners
// (keep_three_corners). Longer ones hold six or more vertices at the boundary spacing, and no
// smoothing flattens them.
constexpr double kSmallLoopLengths = 8.0;

// A feature line of the input: its vertices, from an end (a vertex with other than two curve
// edges) to an end, or around a loop (`closed`, the first vertex not repeated).
struct Line {
  std::vector<VertexHandle> vertices;
  std::vector<EdgeHandle> edges;
  bool closed = false;
};

// The number of input curve edges (boundary or feature) at v.
int curve_degree(const Remesher& rm, VertexHandle v) {
  int n = 0;
  for (auto h : rm.input.voh_range(v)) n += rm.input_curve[static_cast<std::size_t>(h.idx() / 2)];
  return n;
}

// The input's feature lines (input_curve without the boundary), each once.
std::vector<Line> feature_lines(const Remesher& rm) {
  std::vector<int> degree(rm.input.n_vertices(), 0);
  for (auto v : rm.input.vertices())
    degree[static_cast<std::size_t>(v.idx())] = curve_degree(rm, v);
  std::vector<char> seen(rm.input.n_edges(), 0);
  std::vector<Line> lines;
  auto trace = [&](HalfedgeHandle h) {
    Line line;
    line.vertices.push_back(rm.input.from_vertex_handle(h));
    while (true) {
      seen[static_cast<std::size_t>(h.idx() / 2)] = 1;
      line.edges.push_back(rm.input.edge_handle(h));
      const VertexHandle v = rm.input.to_vertex_handle(h);
      if (v == line.vertices.front()) {
        line.closed = true;
        break;
      }
      line.vertices.push_back(v);
      if (degree[static_cast<std::size_t>(v.idx())] != 2) break;
      HalfedgeHandle next;
      for (auto g : rm.input.voh_range(v))
        if (rm.input_curve[static_cast<std::size_t>(g.idx() / 2)] &&
            rm.input.edge_handle(g) != rm.input.edge_handle(h))
          next = g;
      h = next;
    }
    lines.push_back(std::move(line));
  };
  // Open lines from their ends first; what is left are loops.
  for (int pass = 0; pass < 2; ++pass)
    for (auto v : rm.input.vertices()) {
      const int d = degree[static_cast<std::size_t>(v.idx())];
      if (d == 0 || (pass == 0 && d == 2)) continue;
      for (auto h : rm.input.voh_range(v)) {
        const std::size_t e = static_cast<std::size_t>(h.idx() / 2);
        if (rm.input_curve[e] && !seen[e] && !rm.input.is_boundary(rm.input.edge_handle(h)))
          trace(h);
      }
    }
  return lines;
}

// Drops the feature lines shorter than l, until none is left: between two corners closer than
// that, no edge can be in the band, and where lines meet at such distances (the teeth of a gear,
// the facets of a coarse cylinder) their corners pin slivers. Features smaller than l are lost
// in the remesh anyway.
void prune_short_lines(Remesher& rm) {
  for (int pass = 0; pass < 16; ++pass) {
    bool pruned = false;
    for (const Line& line : feature_lines(rm)) {
      double length = 0;
      for (EdgeHandle e : line.edges) length += rm.input.calc_edge_length(e);
      if (length >= rm.length) continue;
      for (EdgeHandle e : line.edges) rm.input_curve[static_cast<std::size_t>(e.idx())] = 0;
      pruned = true;
    }
    if (!pruned) break;
  }
}

// A closed curve shorter than kSmallLoopLengths l with fewer than three corners (a small hole,
// or an island of a few triangles: mark_turns keeps one vertex of a small polygon, none of a
// round loop) would be smoothed and collapsed down to a flat triangle. It keeps three: its
// sharpest corner (or its first vertex) and the vertices closest to a third and two thirds of the
// way round.
void keep_three_corners(Remesher& rm, const std::vector<VertexHandle>& vs) {
  const std::size_t n = vs.size();
  std::vector<double> arc(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    arc[i + 1] = arc[i] + (rm.input.point(vs[(i + 1) % n]) - rm.input.point(vs[i])).norm();
  const double perimeter = arc[n];
  if (n < 3 || !(perimeter < kSmallLoopLengths * rm.length)) return;
  std::size_t corners = 0, first = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (rm.kind(vs[i]) == Kind::Corner && corners++ == 0) first = i;
  if (corners >= 3) return;
  rm.kind(vs[first]) = Kind::Corner;
  for (double third : {1.0 / 3.0, 2.0 / 3.0}) {
    const double target = arc[first] + third * perimeter;
    std::size_t best = first;
    double best_gap = std::numeric_limits<double>::max();
    for (std::size_t i = 0; i < n; ++i) {
      if (rm.kind(vs[i]) == Kind::Corner) continue;
      const double s = arc[i] < arc[first] ? arc[i] + perimeter : arc[i];
      if (std::abs(s - target) < best_gap) {
        best_gap = std::abs(s - target);
        best = i;
      }
    }
    rm.kind(vs[best]) = Kind::Corner;
  }
}

// Marks as corners the vertices of `vs` (a curve of the input, closed or open) where it turns
// sharply at the scale of the target length: the turn at v is measured between the chords to
// the curve's points about l/2 before and after it, and again 2 l before and after it; a corner
// turns sharply at both scales. So the zigzag of a scanned hole (sharp at the scale of its own
// edges, or of l/2) is not a corner while a CAD corner is. Of the vertices around one corner
// only the sharpest is kept, and none within l/2 of a vertex where feature lines end or meet
// (which is a corner already; two corners that close pin an edge that cannot go).
void mark_turns(Remesher& rm, const std::vector<VertexHandle>& vs, bool closed, double corner_cos) {
  const std::size_t n = vs.size();
  if (n < 3) return;
  // The cosine of the turn at vs[i] between the chords to the curve's points at least `reach`
  // away before and after it; b and a receive their indices.
  auto turn_at = [&](std::size_t i, double reach, std::size_t& b, std::size_t& a) {
    const double reach2 = reach * reach;
    const Vec3 p = rm.input.point(vs[i]);
    b = (i + n - 1) % n;
    a = (i + 1) % n;
    if (closed) {
      while (b != a && (rm.input.point(vs[b]) - p).sqrnorm() < reach2) b = (b + n - 1) % n;
      while (a != b && (rm.input.point(vs[a]) - p).sqrnorm() < reach2) a = (a + 1) % n;
    } else {
      while (b > 0 && (rm.input.point(vs[b]) - p).sqrnorm() < reach2) --b;
      while (a + 1 < n && (rm.input.point(vs[a]) - p).sqrnorm() < reach2) ++a;
    }
    const Vec3 d_in = p - rm.input.point(vs[b]), d_out = rm.input.point(vs[a]) - p;
    const double len = d_in.norm() * d_out.norm();
    return len > 0 ? OpenMesh::dot(d_in, d_out) / len : 1.0;
  };
  std::vector<double> turn(n, 1.0); // cosine of the turning angle; lower is sharper
  std::vector<std::size_t> before(n), after(n);
  for (std::size_t i = 0; i < n; ++i) {
    before[i] = after[i] = i;
    if (!closed && (i == 0 || i + 1 == n)) continue;
    turn[i] = turn_at(i, 0.5 * rm.length, before[i], after[i]);
    std::size_t b = 0, a = 0;
    if (turn[i] < corner_cos && turn_at(i, 2 * rm.length, b, a) >= corner_cos) turn[i] = 1.0;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (turn[i] >= corner_cos) continue;
    // Non-maximum suppression over the same window (ties go to the lower index).
    bool sharpest = true;
    for (std::size_t j = before[i]; j != after[i] && sharpest; j = (j + 1) % n)
      if (j != i && (turn[j] < turn[i] || (turn[j] == turn[i] && j < i))) sharpest = false;
    if (rm.feature_count > 0)
      for (std::size_t j = before[i]; j != (after[i] + 1) % n && sharpest; j = (j + 1) % n)
        if (curve_degree(rm, vs[j]) != 2) sharpest = false;
    if (sharpest) rm.kind(vs[i]) = Kind::Corner;
  }
  if (closed) keep_three_corners(rm, vs);
}

// The working mesh's boundary loops cut at their corners into runs u_0 ... u_m (u_0 and u_m
// corners; a loop without corners is one run with u_m = u_0).
std::vector<std::vector<VertexHandle>> boundary_runs(const Remesher& rm) {
  std::vector<std::vector<VertexHandle>> runs;
  std::vector<char> seen(rm.mesh.n_halfedges(), 0);
  for (auto h0 : rm.mesh.halfedges()) {
    if (!rm.mesh.is_boundary(h0) || seen[static_cast<std::size_t>(h0.idx())]) continue;
    std::vector<VertexHandle> loop;
    HalfedgeHandle h = h0;
    do {
      seen[static_cast<std::size_t>(h.idx())] = 1;
      loop.push_back(rm.mesh.from_vertex_handle(h));
      h = rm.mesh.next_halfedge_handle(h);
    } while (h != h0 && loop.size() <= rm.mesh.n_vertices());
    const auto corner = std::find_if(loop.begin(), loop.end(),
                                     [&](VertexHandle v) { return rm.kind(v) == Kind::Corner; });
    if (corner != loop.end()) std::rotate(loop.begin(), corner, loop.end());
    loop.push_back(loop.front());
    std::vector<VertexHandle> run{loop.front()};
    for (std::size_t i = 1; i < loop.size(); ++i) {
      run.push_back(loop[i]);
      if (rm.kind(loop[i]) == Kind::Corner || i + 1 == loop.size()) {
        runs.push_back(run);
        run = {loop[i]};
      }
    }
  }
  return runs;
}

} // namespace

// The working mesh starts as a copy of the input, with the same handles.
void find_curves(Remesher& rm) {
  rm.input_curve = rm.options.feature_angle_deg > 0
                       ? feature_edges(rm.input, rm.options.feature_angle_deg)
                       : std::vector<char>(rm.input.n_edges(), 0);
  for (auto e : rm.input.edges())
    if (rm.input.is_boundary(e)) rm.input_curve[static_cast<std::size_t>(e.idx())] = 1;
  if (rm.options.feature_angle_deg > 0) prune_short_lines(rm);
  for (auto e : rm.input.edges()) {
    rm.feature(e) = rm.input_curve[static_cast<std::size_t>(e.idx())] && !rm.input.is_boundary(e);
    rm.feature_count += rm.feature(e);
  }
}

// Corners: where a curve turns sharply (mark_turns), and where feature lines end or meet, each
// other or the boundary (a curve vertex with other than two curve edges).
void mark_corners(Remesher& rm) {
  const double corner_cos = std::cos(rm.options.corner_angle_deg * M_PI / 180.0);
  const auto loops = boundary_loops(rm.input);
  rm.has_boundary = !loops.empty();
  for (const auto& loop : loops) {
    std::vector<VertexHandle> vs(loop.size());
    for (std::size_t i = 0; i < loop.size(); ++i) vs[i] = rm.input.from_vertex_handle(loop[i]);
    mark_turns(rm, vs, true, corner_cos);
  }
  if (rm.feature_count == 0) return;
  for (auto v : rm.input.vertices()) {
    const int degree = curve_degree(rm, v);
    if (degree > 0 && degree != 2) rm.kind(v) = Kind::Corner;
  }
  for (const Line& line : feature_lines(rm)) mark_turns(rm, line.vertices, line.closed, corner_cos);
}

HalfedgeHandle boundary_out(const Mesh& mesh, VertexHandle v) {
  for (auto h : mesh.voh_range(v))
    if (mesh.is_boundary(h)) return h;
  return HalfedgeHandle();
}

// The input curve halfedge leaving corner c's input vertex whose segment is closest to p.
HalfedgeHandle curve_start(const Remesher& rm, VertexHandle c, const Vec3& p) {
  const VertexHandle x = rm.input.from_vertex_handle(rm.curve_loc(c));
  HalfedgeHandle best;
  double best_d2 = std::numeric_limits<double>::max();
  for (auto h : rm.input.voh_range(x)) {
    if (!rm.input_curve[static_cast<std::size_t>(h.idx() / 2)]) continue;
    const double d2 =
        closest_point_on_segment(p, rm.input.point(x), rm.input.point(rm.input.to_vertex_handle(h)))
            .distance2;
    if (d2 < best_d2) {
      best_d2 = d2;
      best = h;
    }
  }
  return best.is_valid() ? best : rm.curve_loc(c);
}

// Would the triangle (v, c, d) have both of v's feature edges, v a vertex inside a line? The
// smoothing along the line puts v at the midpoint of c and d: on a straight line the triangle
// goes flat.
bool spans_line(const Remesher& rm, VertexHandle v, VertexHandle c, VertexHandle d) {
  if (rm.kind(v) != Kind::Curve || rm.mesh.is_boundary(v)) return false;
  int both = 0;
  for (auto h : rm.mesh.voh_range(v)) {
    const VertexHandle w = rm.mesh.to_vertex_handle(h);
    if ((w == c || w == d) && rm.feature(rm.mesh.edge_handle(h))) ++both;
  }
  return both == 2;
}

// Collapses evenly chosen vertices of each run whose spacing is below boundary_spacing × l, then
// spaces the run's vertices evenly along it (by chord length, then placed on the input
// boundary). Longer boundary edges give the boundary vertices larger cells: their Voronoi cells
// end at the boundary.
std::size_t resample_boundary(Remesher& rm) {
  if (!rm.has_boundary) return 0;
  const double spacing = rm.options.boundary_spacing * rm.length;
  std::size_t collapsed = 0;
  for (const auto& run : boundary_runs(rm)) {
    const std::size_t m = run.size() - 1;
    double length = 0;
    for (std::size_t i = 0; i < m; ++i)
      length += (rm.mesh.point(run[i + 1]) - rm.mesh.point(run[i])).norm();
    const auto wanted = static_cast<std::size_t>(std::max(1.0, std::ceil(length / spacing)));
    if (wanted >= m || m < 3) continue;
    const std::size_t remove = std::min(m - wanted, m - 2);
    for (std::size_t j = 0; j < remove; ++j) {
      const std::size_t i =
          1 + static_cast<std::size_t>((static_cast<double>(j) + 0.5) * static_cast<double>(m - 1) /
                                       static_cast<double>(remove));
      const VertexHandle v = run[std::min(i, m - 1)];
      if (rm.mesh.status(v).deleted() || rm.kind(v) != Kind::Curve) continue;
      const HalfedgeHandle out = boundary_out(rm.mesh, v);
      if (!out.is_valid()) continue;
      collapsed += try_collapse(rm, rm.mesh.edge_handle(out), Collapse::Boundary) ? 1 : 0;
    }
  }
  // Even spacing along each run, by arc length of its chords.
  std::vector<Vec3> goal(rm.mesh.n_vertices());
  std::vector<char> has(rm.mesh.n_vertices(), 0);
  for (const auto& run : boundary_runs(rm)) {
    const std::size_t m = run.size() - 1;
    if (m < 2) continue;
    std::vector<double> at(m + 1, 0.0);
    for (std::size_t i = 0; i < m; ++i)
      at[i + 1] = at[i] + (rm.mesh.point(run[i + 1]) - rm.mesh.point(run[i])).norm();
    std::size_t k = 0;
    for (std::size_t i = 1; i < m; ++i) {
      const double s = at[m] * static_cast<double>(i) / static_cast<double>(m);
      while (k + 1 < m && at[k + 1] < s) ++k;
      const double span = at[k + 1] - at[k];
      const double t = span > 0 ? (s - at[k]) / span : 0.0;
      goal[static_cast<std::size_t>(run[i].idx())] =
          rm.mesh.point(run[k]) * (1 - t) + rm.mesh.point(run[k + 1]) * t;
      has[static_cast<std::size_t>(run[i].idx())] = rm.kind(run[i]) == Kind::Curve;
    }
  }
  move_vertices(rm, [&](VertexHandle v, Vec3& g) {
    if (!has[static_cast<std::size_t>(v.idx())]) return false;
    g = goal[static_cast<std::size_t>(v.idx())];
    return true;
  });
  return collapsed;
}

} // namespace remora::remesh_detail
