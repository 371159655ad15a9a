// The regions the solver benchmarks share (bench_solvers.cpp, bench_modify.cpp): the bundled
// bunny remeshed with the defaults, a geodesic disc around the vertex nearest the centroid with
// its inner 5 % as the handle and N free vertices, the rest fixed; thin plate (k = 2), mean areas
// (SPD). Each is built once per size and kept for the process.
#pragma once

#include <algorithm>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "remora/geometry/selection.h"
#include "remora/linalg/kharmonic.h"
#include "remora/mesh/io.h"
#include "remora/remesh/remesh.h"

namespace remora_bench {

using remora::KHarmonicSystem;

inline const remora::Mesh& remeshed_bunny() {
  static const remora::Mesh mesh = [] {
    remora::RemeshOptions options;
    options.compute_report = false;
    return remora::remesh(remora::read_mesh(std::string(REMORA_REPO_DATA) + "/bunny.ply").mesh,
                          options)
        .mesh;
  }();
  return mesh;
}

struct Disc {
  remora::Region region; ///< label 0: the handle
  KHarmonicSystem system;
};

// The disc whose handle is its first `handle` vertices by distance and whose free vertices are
// the next `free_count`.
inline Disc disc(std::size_t handle, std::size_t free_count) {
  const remora::Mesh& mesh = remeshed_bunny();
  const std::vector<int> order =
      remora::geodesic_order(mesh, remora::central_vertex(mesh), handle + free_count);
  Disc out{remora::Region::all_fixed(mesh.n_vertices()), {}};
  for (std::size_t i = 0; i < order.size(); ++i)
    out.region.label[static_cast<std::size_t>(order[i])] = i < handle ? 0 : remora::Region::kFree;
  out.system = remora::assemble_kharmonic(mesh, out.region, {.k = 2});
  return out;
}

struct Problem {
  KHarmonicSystem system;
  Eigen::MatrixXd rhs; ///< x, y, z of a handle translation
};

// The system with `free_count` free vertices and a handle of 5 % of the disc.
inline const Problem& problem(int free_count) {
  static std::map<int, std::unique_ptr<Problem>> cache;
  auto& slot = cache[free_count];
  if (slot) return *slot;
  const remora::Mesh& mesh = remeshed_bunny();
  const auto handle = static_cast<std::size_t>(free_count) / 19;
  Disc d = disc(handle, static_cast<std::size_t>(free_count));
  slot = std::make_unique<Problem>();
  slot->system = std::move(d.system);
  Eigen::MatrixXd constrained = slot->system.gather_constrained(remora::positions_matrix(mesh));
  for (std::size_t c = 0; c < slot->system.constrained_vertices.size(); ++c)
    if (d.region.label[static_cast<std::size_t>(slot->system.constrained_vertices[c])] == 0)
      constrained.row(static_cast<Eigen::Index>(c)) += Eigen::RowVector3d(0.01, 0.005, -0.008);
  slot->rhs = slot->system.rhs(constrained);
  return *slot;
}

// A region grown by a stroke: the disc's 31,000 free vertices and then `added` more (the next
// ones by distance, as a brush's crescent adds them), with the handle kept. A principal
// submatrix: the grown region's rows and columns of the old free vertices are the old system's.
struct Grown {
  const Problem* old = nullptr;
  KHarmonicSystem system;
  std::vector<Eigen::Index> old_rows, added_rows; ///< rows of the grown system: F's, the added
  Eigen::MatrixXd rhs7;                           ///< 7 right-hand sides of the grown system
};

inline constexpr int kGrownFrom = 31000;

inline const Grown& grown(int added) {
  static std::map<int, std::unique_ptr<Grown>> cache;
  auto& slot = cache[added];
  if (slot) return *slot;
  slot = std::make_unique<Grown>();
  slot->old = &problem(kGrownFrom);
  const auto handle = static_cast<std::size_t>(kGrownFrom) / 19;
  slot->system = disc(handle, static_cast<std::size_t>(kGrownFrom + added)).system;
  for (std::size_t r = 0; r < slot->system.free_vertices.size(); ++r) {
    const int v = slot->system.free_vertices[r];
    (slot->old->system.row_of[static_cast<std::size_t>(v)] >= 0 ? slot->old_rows : slot->added_rows)
        .push_back(static_cast<Eigen::Index>(r));
  }
  slot->rhs7 = Eigen::MatrixXd::Random(slot->system.matrix.rows(), 7);
  return *slot;
}

} // namespace remora_bench
