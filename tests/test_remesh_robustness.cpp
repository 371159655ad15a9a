// The remesher on randomly thinned meshes: islands, strips, holes, cracks and pinches. Every
// output is sound: no flat face, every location on its point.
#include <cmath>
#include <filesystem>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <type_traits>

#include <gtest/gtest.h>

#include "remesh_support.h"

#include "remora/common/error.h"
#include "remora/geometry/closest_point.h"
#include "remora/geometry/laplacian.h"
#include "remora/geometry/locate.h"
#include "remora/geometry/measures.h"
#include "remora/geometry/quality.h"
#include "remora/linalg/kharmonic.h"
#include "remora/mesh/build.h"
#include "remora/mesh/io.h"
#include "remora/mesh/primitives.h"
#include "remora/mesh/repair.h"
#include "remora/mesh/soup.h"
#include "remora/mesh/topology.h"
#include "remora/multires/base_surface.h"
#include "remora/remesh/remesh.h"

namespace remora {
namespace {

using namespace remesh_testing;

// A portable linear congruential generator, in [0, 1): the fuzz tests below draw the same
// meshes on every platform.
struct Lcg {
  std::uint64_t state;
  double operator()() {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / 9007199254740992.0;
  }
};

// The faces of `base` kept with probability `keep` each (one draw per face, in face order), as a
// soup over `points`, through the loader's repair (islands, strips, holes, cracks whose pinches
// it splits).
Mesh thinned(const Mesh& base, const std::vector<Vec3>& points, double keep, Lcg& next) {
  PolygonSoup soup;
  soup.points = points;
  for (auto f : base.faces()) {
    const auto fv = face_vertices(base, f);
    if (next() < keep)
      soup.add_triangle(static_cast<std::uint32_t>(fv[0].idx()),
                        static_cast<std::uint32_t>(fv[1].idx()),
                        static_cast<std::uint32_t>(fv[2].idx()));
  }
  return repair_soup(soup).mesh;
}

// Remeshes `trials` random thinnings and checks every output: no flat face, every location on
// its point. Trial t thins make(t) = {mesh, cells across}, its points moved by move(p) (drawn
// first), each face kept with probability keep_min + (1 - keep_min) × a draw, after the
// loader's repair (islands, strips, holes, and cracks whose pinches it splits); the target
// length is (0.3 + length_span × a draw) / cells, and every features_every-th trial keeps
// feature lines at 30 degrees.
template <class Make, class Move>
void expect_sound_thinnings(Lcg& next, int trials, Make make, Move move, double keep_min,
                            double length_span, int features_every) {
  for (int trial = 0; trial < trials; ++trial) {
    const auto [base, cells] = make(trial);
    std::vector<Vec3> points;
    for (auto v : base.vertices()) points.push_back(move(base.point(v)));
    const Mesh input = thinned(base, points, keep_min + (1 - keep_min) * next(), next);
    RemeshOptions opt;
    opt.target_length = (0.3 + length_span * next()) / cells;
    opt.feature_angle_deg = trial % features_every == 0 ? 30 : 0;
    if (input.n_faces() == 0) continue;
    SCOPED_TRACE("trial " + std::to_string(trial));
    expect_sound_output(remesh(input, opt), input);
  }
}

// Random thinnings of a wavy grid: islands, strips one triangle wide, holes, and cracks whose two
// sides meet at vertices the loader splits (pinches). A boundary vertex sliding along such a
// crack can reach its other side, and the faces between the two sides would go flat. Every
// output is sound: no flat face, every location on its point.
TEST(Remesh, ThinnedGridsWithCracksGiveNoFlatFaces) {
  Lcg next{12345};
  expect_sound_thinnings(
      next, 60,
      [](int trial) {
        const int n = 6 + trial % 15;
        return std::pair{make_grid(n, n, 1.0, 1.0), n};
      },
      [&next](Vec3 p) {
        p[2] = 0.1 * std::sin(7 * p[0]) * std::cos(5 * p[1]) + 0.02 * next();
        return p;
      },
      0.3, 3.0, 3);
}

// Noisy cubes with random faces removed: cracks, pinches split by the loader, feature lines on
// every other one. The smoothing moves every vertex at once, so two of them can land on the same
// input vertex or crack tip: such a cluster must collapse under the kinds and the manifold rule
// alone (with the geometric rules each collapse leaves a flat face). And an island of three
// faces around an interior vertex pressed onto the line of two boundary vertices must collapse
// into one triangle (the tetrahedron rule). Without these rules, trials 4, 24 and 148 below keep
// flat faces.
TEST(Remesh, ThinnedCubesGiveNoFlatFaces) {
  Lcg next{24};
  expect_sound_thinnings(
      next, 150,
      [](int trial) {
        const int n = 3 + trial % 5;
        return std::pair{make_cube(n, 1.0), n};
      },
      [&next](Vec3 p) {
        for (int k = 0; k < 3; ++k) p[k] += 0.003 * (next() - 0.5);
        return p;
      },
      0.4, 2.5, 2);
}

// Thinned noisy grids, spheres and cubes (the fuzz run of docs/remesh.md) at 12 cycles. A flip
// (the repair's, a Delaunay or a valence flip) can make a face whose three corners, boundary
// vertices of the thinned input, sit within 1e-4 l of each other; and the curve smoothing would
// move the corners of a one-triangle island (ears) towards each other's midpoints until it lay
// flat. Flips refuse faces flat by the repair's measure, and ears stay. These are the trials
// that need both rules; the others are drawn (the generator's state must match) but not
// remeshed.
TEST(Remesh, ThinnedMeshesGiveNoFlatFacesAfterTheExtraCycles) {
  Lcg next{987654321};
  const std::set<int> failed = {49, 349, 353, 441, 837};
  for (int trial = 0; trial <= *failed.rbegin(); ++trial) {
    const int type = trial % 3;
    const Mesh base = type == 0   ? make_grid(8 + trial % 13, 8 + trial % 11, 1.0, 1.0)
                      : type == 1 ? make_icosphere(2 + trial % 2, 1.0)
                                  : make_cube(3 + trial % 5, 1.0);
    const double noise = 0.03 * next();
    std::vector<Vec3> points;
    for (auto v : base.vertices()) {
      Vec3 p = base.point(v);
      if (type == 0) p[2] = 0.1 * std::sin(7 * p[0]) * std::cos(5 * p[1]);
      for (int k = 0; k < 3; ++k) p[k] += noise * (next() - 0.5) * 0.1;
      points.push_back(p);
    }
    const Mesh input = thinned(base, points, 0.4 + 0.6 * next(), next);
    if (input.n_faces() == 0) continue; // no length drawn then
    RemeshOptions opt;
    opt.target_length = mean_edge_length(input) * (0.3 + 2.5 * next());
    opt.feature_angle_deg = type == 2 ? 30 : 0;
    if (!failed.count(trial)) continue;
    SCOPED_TRACE("trial " + std::to_string(trial));
    expect_sound_output(remesh(input, opt), input);
  }
}

} // namespace
} // namespace remora
