// Steps 1 and 2 of the soup repair: unreferenced vertices are dropped, coincident ones merged
// (bit-identical ones first, then those closer than the tolerance).
#include <cmath>
#include <cstring>
#include <unordered_map>

#include "remora/mesh/repair_detail.h"

namespace remora::repair_detail {

namespace {

struct PointKey {
  double x, y, z;
  bool operator==(const PointKey& o) const { return x == o.x && y == o.y && z == o.z; }
};

struct PointKeyHash {
  std::size_t operator()(const PointKey& k) const {
    auto h = [](double d) {
      std::uint64_t u;
      static_assert(sizeof(u) == sizeof(d));
      std::memcpy(&u, &d, sizeof(u));
      return u;
    };
    std::uint64_t s = h(k.x) * 0x9E3779B97F4A7C15ULL;
    s ^= h(k.y) + 0x7F4A7C159E3779B9ULL + (s << 6) + (s >> 2);
    s ^= h(k.z) + 0x94D049BB133111EBULL + (s << 6) + (s >> 2);
    return static_cast<std::size_t>(s ^ (s >> 31));
  }
};

// -0.0 and +0.0 are the same point.
PointKey key_of(const Vec3& p) {
  return {p[0] + 0.0, p[1] + 0.0, p[2] + 0.0};
}

// The survivors of the near weld in cells of 64 tolerances: a point looks into a neighbouring
// cell only when it lies within reach of that cell's face, so almost every point costs one
// lookup.
class SurvivorGrid {
public:
  SurvivorGrid(const std::vector<Vec3>& points, const Vec3& lo, double tol)
      : points_(points), lo_(lo), tol_(tol), cell_(64 * tol), next_(points.size(), kNone) {
    head_.reserve(points.size());
  }

  /// The smallest survivor within the tolerance of points[v], or kNone.
  std::uint32_t find(std::uint32_t v) const {
    const Vec3 q = (points_[v] - lo_) / cell_;
    const Cell c = cell_of(q);
    // Per axis: this cell, and the neighbour whose face lies within reach.
    std::array<std::array<int, 2>, 3> offsets{};
    std::array<int, 3> count{};
    const std::int64_t base[3] = {c.i, c.j, c.k};
    for (int a = 0; a < 3; ++a) {
      const double frac = (q[a] - static_cast<double>(base[a])) * cell_;
      offsets[a][count[a]++] = 0;
      if (frac < tol_)
        offsets[a][count[a]++] = -1;
      else if (cell_ - frac < tol_)
        offsets[a][count[a]++] = 1;
    }
    std::uint32_t found = kNone;
    for (int x = 0; x < count[0]; ++x)
      for (int y = 0; y < count[1]; ++y)
        for (int z = 0; z < count[2]; ++z) {
          const auto it =
              head_.find({c.i + offsets[0][x], c.j + offsets[1][y], c.k + offsets[2][z]});
          if (it == head_.end()) continue;
          for (std::uint32_t s = it->second; s != kNone; s = next_[s])
            if (s < found && (points_[s] - points_[v]).sqrnorm() <= tol_ * tol_) found = s;
        }
    return found;
  }

  /// Makes points[v] a survivor.
  void add(std::uint32_t v) {
    const auto [it, inserted] = head_.try_emplace(cell_of((points_[v] - lo_) / cell_), v);
    if (!inserted) {
      next_[v] = it->second;
      it->second = v;
    }
  }

private:
  struct Cell {
    std::int64_t i, j, k;
    bool operator==(const Cell& o) const { return i == o.i && j == o.j && k == o.k; }
  };
  struct CellHash {
    std::size_t operator()(const Cell& c) const {
      std::uint64_t s = std::uint64_t(c.i) * 0x9E3779B97F4A7C15ULL;
      s ^= std::uint64_t(c.j) * 0xBF58476D1CE4E5B9ULL + (s << 6) + (s >> 2);
      s ^= std::uint64_t(c.k) * 0x94D049BB133111EBULL + (s << 6) + (s >> 2);
      return static_cast<std::size_t>(s ^ (s >> 31));
    }
  };
  static Cell cell_of(const Vec3& q) {
    return {static_cast<std::int64_t>(std::floor(q[0])),
            static_cast<std::int64_t>(std::floor(q[1])),
            static_cast<std::int64_t>(std::floor(q[2]))};
  }

  const std::vector<Vec3>& points_;
  Vec3 lo_;
  double tol_, cell_;
  std::unordered_map<Cell, std::uint32_t, CellHash> head_; // cell -> its last survivor
  std::vector<std::uint32_t> next_;                        // survivors of a cell, newest first
};

// Step 2, second half, on the distinct points: each joins the first earlier survivor within
// weld_tolerance × the bounding-box diagonal.
void weld_near(Welded& w, double weld_tolerance) {
  const std::size_t n = w.points.size();
  if (n < 2) return;
  Vec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (const Vec3& p : w.points) {
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) return;
    lo.minimize(p);
    hi.maximize(p);
  }
  const double tol = weld_tolerance * (hi - lo).norm();
  if (!(tol > 0)) return;
  SurvivorGrid grid(w.points, lo, tol);
  std::vector<std::uint32_t> remap(n);
  std::vector<std::uint32_t> kept_index(n, kNone); // survivor (old index) -> new index
  std::vector<Vec3> kept_points;
  std::vector<std::uint32_t> kept_source;
  kept_points.reserve(n);
  kept_source.reserve(n);
  for (std::uint32_t v = 0; v < n; ++v) {
    const std::uint32_t found = grid.find(v);
    if (found != kNone) {
      remap[v] = kept_index[found];
      ++w.near_welded;
      continue;
    }
    grid.add(v);
    kept_index[v] = static_cast<std::uint32_t>(kept_points.size());
    remap[v] = kept_index[v];
    kept_points.push_back(w.points[v]);
    kept_source.push_back(w.source[v]);
  }
  if (kept_points.size() == n) return;
  for (std::uint32_t& m : w.vertex_of)
    if (m != kNone) m = remap[m];
  w.points = std::move(kept_points);
  w.source = std::move(kept_source);
}

} // namespace

Welded weld_vertices(const PolygonSoup& soup, const RepairOptions& options) {
  const std::size_t nv = soup.points.size();
  Welded w;
  std::vector<char> used(nv, 0);
  for (std::uint32_t i : soup.indices) used[i] = 1;
  w.vertex_of.assign(nv, kNone);
  std::unordered_map<PointKey, std::uint32_t, PointKeyHash> first;
  if (options.weld) first.reserve(nv);
  for (std::size_t i = 0; i < nv; ++i) {
    if (!used[i]) {
      ++w.unreferenced;
      continue;
    }
    if (options.weld) {
      const auto [it, inserted] =
          first.try_emplace(key_of(soup.points[i]), static_cast<std::uint32_t>(w.points.size()));
      if (!inserted) {
        w.vertex_of[i] = it->second;
        ++w.welded;
        continue;
      }
    }
    w.vertex_of[i] = static_cast<std::uint32_t>(w.points.size());
    w.points.push_back(soup.points[i]);
    w.source.push_back(static_cast<std::uint32_t>(i));
  }
  if (options.weld && options.weld_tolerance > 0) weld_near(w, options.weld_tolerance);
  return w;
}

} // namespace remora::repair_detail
