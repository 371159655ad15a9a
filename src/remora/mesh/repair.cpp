// repair_soup(): the steps of repair.h in order, on one SoupRepairer; steps 1-3 are in
// repair_weld.cpp and repair_triangulate.cpp.
#include "remora/mesh/repair.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "remora/common/error.h"
#include "remora/mesh/build.h"
#include "remora/mesh/repair_detail.h"

namespace remora {

namespace {

using repair_detail::kNone;
using repair_detail::Tri;

struct DisjointSets {
  std::vector<std::uint32_t> parent;
  explicit DisjointSets(std::size_t n) : parent(n) {
    std::iota(parent.begin(), parent.end(), std::uint32_t{0});
  }
  std::uint32_t find(std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

// One side of an undirected edge: triangle t uses the edge starting at its corner k, i.e. the
// directed edge tri[t][k] -> tri[t][(k+1)%3].
struct EdgeSide {
  std::uint64_t key; // (min << 32) | max
  std::uint32_t tri;
  std::uint8_t corner;
};

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
  return a < b ? (std::uint64_t(a) << 32 | b) : (std::uint64_t(b) << 32 | a);
}

class SoupRepairer {
public:
  SoupRepairer(const PolygonSoup& soup, const RepairOptions& options)
      : soup_(soup), options_(options) {}

  RepairResult run() {
    report_.vertices_in = soup_.points.size();
    report_.polygons_in = soup_.num_polygons();
    check_indices();
    weld();
    triangulate();
    drop_degenerate_and_duplicates();
    count_components();
    build_edge_sides();
    if (options_.orient) orient();
    split_nonmanifold();
    detach_conflicts_and_resplit();
    return build();
  }

private:
  void check_indices() {
    const std::size_t nv = soup_.points.size();
    for (std::size_t f = 0; f < soup_.num_polygons(); ++f)
      for (std::uint32_t i = soup_.offsets[f]; i < soup_.offsets[f + 1]; ++i)
        if (soup_.indices[i] >= nv)
          throw InvalidArgument("polygon " + std::to_string(f) + " references vertex " +
                                std::to_string(soup_.indices[i]) + " but the soup has only " +
                                std::to_string(nv) + " vertices");
  }

  // Steps 1 and 2 (repair_weld.cpp). vmap_ maps soup vertex -> welded vertex (kNone when
  // unreferenced).
  void weld() {
    repair_detail::Welded w = repair_detail::weld_vertices(soup_, options_);
    vmap_ = std::move(w.vertex_of);
    points_ = std::move(w.points);
    source_ = std::move(w.source);
    report_.unreferenced_vertices += w.unreferenced;
    report_.welded_vertices += w.welded;
    report_.near_welded_vertices += w.near_welded;
  }

  // Step 3.
  void triangulate() {
    tris_.reserve(soup_.indices.size() / 3 + 1);
    std::vector<std::uint32_t> poly;
    for (std::size_t f = 0; f < soup_.num_polygons(); ++f) {
      const std::size_t n = soup_.polygon_size(f);
      if (n < 3) {
        ++report_.dropped_degenerate_polygon;
        continue;
      }
      poly.clear();
      for (std::uint32_t i = soup_.offsets[f]; i < soup_.offsets[f + 1]; ++i)
        poly.push_back(vmap_[soup_.indices[i]]);
      if (n > 3) {
        ++report_.polygons_triangulated;
        report_.triangles_added_by_triangulation += n - 3;
      }
      repair_detail::triangulate_polygon(points_, poly, tris_);
    }
  }

  // Step 4. A triangle listed more than once keeps one copy, unless it is a zero-thickness flap:
  // copies glued to the surface along a single edge (CAD exports carry them), of which one copy
  // kept would still be a fin on a non-manifold edge.
  void drop_degenerate_and_duplicates() {
    std::size_t out = 0;
    for (const Tri& t : tris_) {
      if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) {
        ++report_.dropped_repeated_vertex;
        continue;
      }
      tris_[out++] = t;
    }
    tris_.resize(out);
    // Group equal vertex triples by sorting (faster than hashing at a million triangles).
    struct Keyed {
      Tri key;
      std::uint32_t tri;
    };
    std::vector<Keyed> keyed(tris_.size());
    for (std::uint32_t t = 0; t < tris_.size(); ++t) keyed[t] = {sorted(tris_[t]), t};
    std::sort(keyed.begin(), keyed.end(), [](const Keyed& a, const Keyed& b) {
      return a.key != b.key ? a.key < b.key : a.tri < b.tri;
    });
    std::vector<std::pair<std::size_t, std::size_t>> runs; // [begin, end) of repeated triples
    for (std::size_t i = 0; i < keyed.size();) {
      std::size_t j = i + 1;
      while (j < keyed.size() && keyed[j].key == keyed[i].key) ++j;
      if (j - i > 1) runs.emplace_back(i, j);
      i = j;
    }
    if (runs.empty()) return;
    // Edge use by the distinct triangles, for the edges of repeated triples only.
    std::unordered_map<std::uint64_t, std::uint32_t> edge_use;
    for (const auto& [b, e] : runs)
      for (int k = 0; k < 3; ++k) {
        const Tri& t = keyed[b].key;
        edge_use[edge_key(t[k], t[(k + 1) % 3])] = 0;
      }
    for (std::size_t i = 0; i < keyed.size(); ++i) {
      if (i > 0 && keyed[i].key == keyed[i - 1].key) continue; // count each triple once
      const Tri& t = keyed[i].key;
      for (int k = 0; k < 3; ++k) {
        auto it = edge_use.find(edge_key(t[k], t[(k + 1) % 3]));
        if (it != edge_use.end()) ++it->second;
      }
    }
    // A flap hangs by one edge that two other triangles already share (one copy kept would
    // make it non-manifold) and has no other neighbour.
    auto is_flap = [&](const Tri& t) {
      int hinges = 0, free_edges = 0;
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t others = edge_use[edge_key(t[k], t[(k + 1) % 3])] - 1;
        hinges += others >= 2 ? 1 : 0;
        free_edges += others == 0 ? 1 : 0;
      }
      return hinges == 1 && free_edges == 2;
    };
    std::vector<char> drop(tris_.size(), 0);
    for (const auto& [b, e] : runs) {
      const bool flap = is_flap(keyed[b].key);
      for (std::size_t i = flap ? b : b + 1; i < e; ++i) drop[keyed[i].tri] = 1;
      (flap ? report_.dropped_flap : report_.dropped_duplicate) += flap ? e - b : e - b - 1;
    }
    out = 0;
    for (std::uint32_t t = 0; t < tris_.size(); ++t)
      if (!drop[t]) tris_[out++] = tris_[t];
    tris_.resize(out);
  }

  static Tri sorted(Tri t) {
    std::sort(t.begin(), t.end());
    return t;
  }

  // The welded triangles' connected components through shared vertices (before any split).
  void count_components() {
    DisjointSets sets(points_.size());
    for (const Tri& t : tris_) {
      sets.unite(t[0], t[1]);
      sets.unite(t[1], t[2]);
    }
    std::vector<char> root(points_.size(), 0);
    for (const Tri& t : tris_) {
      const std::uint32_t r = sets.find(t[0]);
      if (!root[r]) {
        root[r] = 1;
        ++report_.components_in;
      }
    }
  }

  void build_edge_sides() {
    sides_.clear();
    sides_.reserve(tris_.size() * 3);
    for (std::uint32_t t = 0; t < tris_.size(); ++t)
      for (std::uint8_t k = 0; k < 3; ++k)
        sides_.push_back({edge_key(tris_[t][k], tris_[t][(k + 1) % 3]), t, k});
    std::sort(sides_.begin(), sides_.end(), [](const EdgeSide& a, const EdgeSide& b) {
      return a.key != b.key ? a.key < b.key : a.tri < b.tri;
    });
    group_start_.clear();
    for (std::size_t i = 0; i < sides_.size(); ++i)
      if (i == 0 || sides_[i].key != sides_[i - 1].key)
        group_start_.push_back(static_cast<std::uint32_t>(i));
    group_start_.push_back(static_cast<std::uint32_t>(sides_.size()));
  }

  // Does the side run from the smaller to the larger vertex id (with the current winding)?
  bool forward(const EdgeSide& s) const {
    const Tri& t = tris_[s.tri];
    return t[s.corner] < t[(s.corner + 1) % 3];
  }

  // Step 5: breadth-first propagation over edges shared by exactly two triangles.
  void orient() {
    const std::size_t nt = tris_.size();
    // Adjacency over two-sided edges: for each triangle its up to three neighbours, and whether
    // the neighbour currently runs the shared edge the same way (which calls for a flip).
    std::vector<std::array<std::uint32_t, 3>> nbr(nt, {kNone, kNone, kNone});
    std::vector<std::array<char, 3>> same(nt, {0, 0, 0});
    std::vector<char> open_edge(nt, 0);
    for (std::size_t g = 0; g + 1 < group_start_.size(); ++g) {
      const std::uint32_t b = group_start_[g], e = group_start_[g + 1];
      if (e - b != 2) {
        for (std::uint32_t i = b; i < e; ++i) open_edge[sides_[i].tri] = 1;
        continue;
      }
      const EdgeSide &s0 = sides_[b], &s1 = sides_[b + 1];
      const char sd = forward(s0) == forward(s1);
      nbr[s0.tri][s0.corner] = s1.tri;
      same[s0.tri][s0.corner] = sd;
      nbr[s1.tri][s1.corner] = s0.tri;
      same[s1.tri][s1.corner] = sd;
    }
    std::vector<char> flip(nt, 0), visited(nt, 0);
    std::vector<std::uint32_t> queue, component;
    for (std::uint32_t seed = 0; seed < nt; ++seed) {
      if (visited[seed]) continue;
      component.clear();
      queue.assign(1, seed);
      visited[seed] = 1;
      bool closed = true;
      while (!queue.empty()) {
        const std::uint32_t t = queue.back();
        queue.pop_back();
        component.push_back(t);
        if (open_edge[t]) closed = false;
        for (int k = 0; k < 3; ++k) {
          const std::uint32_t u = nbr[t][k];
          if (u == kNone) {
            closed = false;
            continue;
          }
          if (visited[u]) continue;
          visited[u] = 1;
          flip[u] = static_cast<char>(flip[t] ^ same[t][k]);
          queue.push_back(u);
        }
      }
      // Choose the component's global sign: outward for closed components, the file's majority
      // winding for open ones.
      bool invert;
      if (closed && options_.outward) {
        double volume = 0;
        for (std::uint32_t t : component) {
          const Tri& tri = tris_[t];
          const Vec3 &a = points_[tri[0]], &b = points_[tri[1]], &c = points_[tri[2]];
          const double v = OpenMesh::dot(a, OpenMesh::cross(b, c));
          volume += flip[t] ? -v : v;
        }
        invert = volume < 0;
      } else {
        std::size_t flipped = 0;
        for (std::uint32_t t : component) flipped += flip[t] ? 1 : 0;
        invert = 2 * flipped > component.size();
      }
      for (std::uint32_t t : component) {
        if (invert) flip[t] ^= 1;
        if (flip[t]) {
          std::swap(tris_[t][1], tris_[t][2]);
          ++report_.flipped_faces;
        }
      }
    }
    // Swapping a triangle's corners 1 and 2 moves its edge at corner k to corner 2 - k; the sort
    // order (by edge, then triangle) is unchanged.
    for (EdgeSide& side : sides_)
      if (flip[side.tri]) side.corner = static_cast<std::uint8_t>(2 - side.corner);
  }

  // Step 6: decide which triangle pairs are joined across each edge, then give every fan of
  // joined triangles around a vertex its own copy of that vertex.
  void split_nonmanifold() {
    DisjointSets corners(tris_.size() * 3); // corner id = 3*t + k
    for (std::size_t g = 0; g + 1 < group_start_.size(); ++g) {
      const std::uint32_t b = group_start_[g], e = group_start_[g + 1];
      if (e - b == 1) continue;
      if (e - b > 2) {
        join_around_edge(corners, b, e);
        continue;
      }
      if (forward(sides_[b]) != forward(sides_[b + 1]))
        join(corners, sides_[b], sides_[b + 1]);
      else
        ++report_.orientation_cuts;
    }
    out_points_ = points_;
    out_source_ = source_;
    vertex_taken_.assign(points_.size(), 0);
    assign_vertices(corners);
  }

  // Joins two sides of one edge: the corners of its two vertices in both triangles.
  void join(DisjointSets& corners, const EdgeSide& a, const EdgeSide& b) const {
    auto corner_of = [&](std::uint32_t t, std::uint32_t v) {
      const Tri& tri = tris_[t];
      const std::uint32_t k = tri[0] == v ? 0 : (tri[1] == v ? 1 : 2);
      return 3 * t + k;
    };
    const Tri& ta = tris_[a.tri];
    const std::uint32_t v0 = ta[a.corner], v1 = ta[(a.corner + 1) % 3];
    corners.unite(corner_of(a.tri, v0), corner_of(b.tri, v0));
    corners.unite(corner_of(a.tri, v1), corner_of(b.tri, v1));
  }

  // More than two triangles on one edge (sides_[b, e)): order them by their angle around the
  // edge and join angular neighbours of opposite direction, first across the sectors that lie
  // behind both faces (inside a solid: two closed bodies touching along an edge stay two closed
  // bodies), then any remaining neighbours; the rest are cut apart.
  void join_around_edge(DisjointSets& corners, std::uint32_t b, std::uint32_t e) {
    ++report_.nonmanifold_edges;
    struct Around {
      double angle;       // around the edge, from the first side
      std::uint32_t side; // index into sides_
      bool behind_ccw;    // the sector towards the next side counter-clockwise is behind the face
    };
    const std::uint64_t key = sides_[b].key;
    const std::uint32_t va = static_cast<std::uint32_t>(key >> 32);
    const std::uint32_t vb = static_cast<std::uint32_t>(key & 0xffffffffu);
    const Vec3 axis = points_[vb] - points_[va];
    const double axis2 = OpenMesh::dot(axis, axis);
    Vec3 ref(0, 0, 0);
    std::vector<Around> around;
    for (std::uint32_t i = b; i < e; ++i) {
      const Tri& t = tris_[sides_[i].tri];
      const std::uint32_t apex = t[(sides_[i].corner + 2) % 3];
      Vec3 d = points_[apex] - points_[va];
      if (axis2 > 0) d -= axis * (OpenMesh::dot(d, axis) / axis2);
      if (i == b) ref = d;
      const double angle =
          std::atan2(OpenMesh::dot(OpenMesh::cross(ref, d), axis), OpenMesh::dot(ref, d));
      const Vec3 normal =
          OpenMesh::cross(points_[t[1]] - points_[t[0]], points_[t[2]] - points_[t[0]]);
      const bool behind_ccw = OpenMesh::dot(normal, OpenMesh::cross(axis, d)) < 0;
      around.push_back({angle, i, behind_ccw});
    }
    std::sort(around.begin(), around.end(),
              [](const Around& x, const Around& y) { return x.angle < y.angle; });
    const std::size_t m = around.size();
    std::vector<char> paired(m, 0);
    for (int pass = 0; pass < 2; ++pass)
      for (std::size_t i = 0; i < m; ++i) {
        const std::size_t j = (i + 1) % m;
        if (paired[i] || paired[j] || (pass == 0 && !around[i].behind_ccw)) continue;
        const EdgeSide &si = sides_[around[i].side], &sj = sides_[around[j].side];
        if (forward(si) != forward(sj)) {
          join(corners, si, sj);
          paired[i] = paired[j] = 1;
        }
      }
  }

  // Each class of corners around a vertex becomes one output vertex: the first class keeps the
  // vertex, every further class gets a copy.
  void assign_vertices(DisjointSets& corners) {
    const std::size_t nt = tris_.size();
    std::vector<std::uint32_t> class_vertex(nt * 3, kNone);
    std::fill(vertex_taken_.begin(), vertex_taken_.end(), 0);
    for (std::uint32_t t = 0; t < nt; ++t) {
      for (std::uint32_t k = 0; k < 3; ++k) {
        std::uint32_t& cv = class_vertex[corners.find(3 * t + k)];
        if (cv == kNone) {
          const std::uint32_t v = tris_[t][k];
          if (!vertex_taken_[v]) {
            vertex_taken_[v] = 1;
            cv = v;
          } else {
            cv = add_copy(v);
            vertex_taken_[cv] = 1;
          }
        }
        tris_[t][k] = cv;
      }
    }
  }

  std::uint32_t add_copy(std::uint32_t v) {
    const std::uint32_t copy = static_cast<std::uint32_t>(out_points_.size());
    out_points_.push_back(out_points_[v]);
    out_source_.push_back(out_source_[v]);
    copy_of_.push_back(origin_of(v));
    vertex_taken_.push_back(0);
    return copy;
  }

  // The welded vertex a (possibly copied) vertex stems from.
  std::uint32_t origin_of(std::uint32_t v) const {
    return v < points_.size() ? v : copy_of_[v - points_.size()];
  }

  // A triangle whose directed edge another triangle already runs (possible only in tangled
  // non-manifold configurations) gets vertex copies of its own; then every vertex is split once
  // more into the fans of triangles that now actually share edges, so that each output vertex has
  // exactly one fan and the half-edge structure is well defined.
  void detach_conflicts_and_resplit() {
    // The common case: a manifold soup. No vertex was copied, so the sides are still current and
    // every edge has at most two sides, of opposite directions.
    if (out_points_.size() == points_.size() && report_.nonmanifold_edges == 0 &&
        report_.orientation_cuts == 0)
      return;
    build_edge_sides();
    bool detached = false;
    for (std::size_t g = 0; g + 1 < group_start_.size(); ++g) {
      const std::uint32_t b = group_start_[g], e = group_start_[g + 1];
      bool seen_forward = false, seen_backward = false;
      for (std::uint32_t i = b; i < e; ++i) { // sides in triangle order: the first keeps its edge
        Tri& t = tris_[sides_[i].tri];
        if (t[sides_[i].corner] != static_cast<std::uint32_t>(sides_[i].key >> 32) &&
            t[sides_[i].corner] != static_cast<std::uint32_t>(sides_[i].key & 0xffffffffu))
          continue; // this triangle was detached already
        bool& seen = forward(sides_[i]) ? seen_forward : seen_backward;
        if (!seen) {
          seen = true;
          continue;
        }
        ++report_.faces_detached;
        for (int k = 0; k < 3; ++k) t[k] = add_copy(t[k]);
        detached = true;
      }
    }
    if (detached) build_edge_sides();
    DisjointSets corners(tris_.size() * 3);
    for (std::size_t g = 0; g + 1 < group_start_.size(); ++g) {
      const std::uint32_t b = group_start_[g], e = group_start_[g + 1];
      if (e - b != 2) continue; // directed edges are unique now: two sides are opposite
      const EdgeSide &s0 = sides_[b], &s1 = sides_[b + 1];
      // s1 runs the edge backwards: its corner k+1 holds s0's corner k vertex and vice versa.
      corners.unite(3 * s0.tri + s0.corner, 3 * s1.tri + (s1.corner + 1u) % 3);
      corners.unite(3 * s0.tri + (s0.corner + 1u) % 3, 3 * s1.tri + s1.corner);
    }
    const std::size_t before = out_points_.size();
    assign_vertices(corners);
    // New copies renumber edges: keep the sides current for build().
    if (out_points_.size() != before) build_edge_sides();
  }

  // Builds the half-edge structure directly (every vertex has one fan, every directed edge one
  // triangle), which never fails and is faster than incremental add_face().
  RepairResult build() {
    RepairResult result;
    std::vector<std::uint32_t> index(out_points_.size(), kNone);
    std::vector<Vec3> points;
    std::vector<std::uint32_t> copies(points_.size(), 0); // output vertices per welded vertex
    for (std::size_t v = 0; v < out_points_.size(); ++v) {
      if (!vertex_taken_[v]) continue;
      index[v] = static_cast<std::uint32_t>(points.size());
      points.push_back(out_points_[v]);
      result.source_vertex.push_back(out_source_[v]);
      ++copies[origin_of(static_cast<std::uint32_t>(v))];
    }
    for (std::uint32_t c : copies) {
      if (c == 0) ++report_.orphaned_vertices; // every triangle it had was dropped
      if (c > 1) {
        ++report_.split_vertices;
        report_.vertices_added_by_split += c - 1;
      }
    }
    for (Tri& t : tris_)
      for (std::uint32_t& v : t) v = index[v];
    try {
      result.mesh = build_mesh(points, tris_);
    } catch (const InvalidArgument& e) {
      // The steps above guarantee the precondition.
      throw Error(std::string("internal error in the soup repair: ") + e.what());
    }
    report_.vertices_loaded = result.mesh.n_vertices();
    report_.faces_loaded = result.mesh.n_faces();
    report_.zero_area_faces = count_zero_area_faces(result.mesh);
    result.report = report_;
    return result;
  }

  const PolygonSoup& soup_;
  const RepairOptions& options_;
  RepairReport report_;
  std::vector<std::uint32_t> vmap_;
  std::vector<Vec3> points_;          // welded, referenced vertices
  std::vector<std::uint32_t> source_; // their soup vertex
  std::vector<Tri> tris_;
  std::vector<EdgeSide> sides_;
  std::vector<std::uint32_t> group_start_;
  std::vector<Vec3> out_points_;
  std::vector<std::uint32_t> out_source_;
  std::vector<char> vertex_taken_;     // output vertex used by a triangle
  std::vector<std::uint32_t> copy_of_; // for copies (index - points_.size()): the welded vertex
};

} // namespace

std::size_t count_zero_area_faces(const Mesh& mesh) {
  if (mesh.n_faces() == 0) return 0;
  Vec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (auto v : mesh.vertices()) {
    lo.minimize(mesh.point(v));
    hi.maximize(mesh.point(v));
  }
  const double diag2 = (hi - lo).sqrnorm();
  std::size_t count = 0;
  for (auto f : mesh.faces()) {
    auto h = mesh.halfedge_handle(f);
    const Vec3& a = mesh.point(mesh.from_vertex_handle(h));
    const Vec3& b = mesh.point(mesh.to_vertex_handle(h));
    const Vec3& c = mesh.point(mesh.to_vertex_handle(mesh.next_halfedge_handle(h)));
    const double area = 0.5 * OpenMesh::cross(b - a, c - a).norm();
    if (area <= kZeroAreaRelative * diag2) ++count;
  }
  return count;
}

RepairResult repair_soup(const PolygonSoup& soup, const RepairOptions& options) {
  return SoupRepairer(soup, options).run();
}

} // namespace remora
