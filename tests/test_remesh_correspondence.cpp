// The remesher's correspondence (the mutual parameterization of §4): output -> input locations
// on their points, input vertices tracked through every operation to their closest output
// point, in the caller's numbering.
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

TEST(Remesh, CorrespondenceRoundTripOnAFlatMesh) {
  const Mesh input = needle_grid();
  RemeshOptions opt;
  opt.target_length = 0.12;
  const RemeshResult r = remesh(input, opt);
  const double diag = bounding_box_diagonal(input);
  for (auto v : input.vertices()) {
    // input vertex -> location on the output -> back onto the input.
    const SurfacePoint& on_out = r.input_on_output[v.idx()];
    const Vec3 q = evaluate(r.mesh, on_out);
    const VertexHandle w = face_vertices(r.mesh, on_out.face)[0];
    const SurfacePoint back = walk_to_closest(input, q, r.output_on_input[w.idx()].face);
    EXPECT_LT((evaluate(input, back) - input.point(v)).norm(), 1e-6 * diag);
  }
}

TEST(Remesh, InputVerticesFindTheirClosestOutputPoint) {
  const Mesh input = make_icosphere(3);
  RemeshOptions opt;
  opt.target_length = 0.15;
  const RemeshResult r = remesh(input, opt);
  for (int i = 0; i < 100; ++i) {
    const VertexHandle v(static_cast<int>(i * input.n_vertices() / 100));
    const Vec3 q = evaluate(r.mesh, r.input_on_output[v.idx()]);
    EXPECT_NEAR((q - input.point(v)).norm(), distance_to(r.mesh, input.point(v)), 1e-12);
  }
}

// The input -> output locations are carried through every split, collapse, flip and move (not
// searched for at the end): the final walk that makes each one the input vertex's closest point
// on the output finds them all but exact already. Dropping the update after the moves, or the
// redistribution after a split or collapse, leaves them far behind.
TEST(Remesh, TracksInputVerticesThroughEveryOperation) {
  for (int shape = 0; shape < 2; ++shape) {
    const Mesh input = shape == 0 ? make_icosphere(4) : needle_grid();
    RemeshOptions opt;
    opt.target_length = shape == 0 ? 0.15 : 0.12;
    const RemeshReport rep = remesh(input, opt).report;
    EXPECT_GT(rep.tracked_same_face, 0.97) << "shape " << shape;
    EXPECT_LT(rep.tracked_excess_mean, 1e-4) << "shape " << shape;
    EXPECT_LT(rep.tracked_excess_max, 0.05) << "shape " << shape;
  }
}

// A large input is remeshed in a spatial order of its own; the correspondence must come back
// in the caller's numbering. The grid's vertices and faces are shuffled (no spatial order left)
// and it is flat, so every input vertex lies exactly on the output.
TEST(Remesh, LargeShuffledInputGetsItsCorrespondenceInItsOwnNumbering) {
  const Mesh grid = make_grid(130, 130, 1.0, 1.0); // 33,800 faces: above the spatial threshold
  std::mt19937 rng(7);
  std::vector<int> vorder(grid.n_vertices());
  std::iota(vorder.begin(), vorder.end(), 0);
  std::shuffle(vorder.begin(), vorder.end(), rng);
  std::vector<int> where(vorder.size());
  Mesh input;
  for (std::size_t i = 0; i < vorder.size(); ++i) {
    where[static_cast<std::size_t>(vorder[i])] = static_cast<int>(i);
    input.add_vertex(grid.point(VertexHandle(vorder[i])));
  }
  std::vector<FaceHandle> faces(grid.faces().begin(), grid.faces().end());
  std::shuffle(faces.begin(), faces.end(), rng);
  for (FaceHandle f : faces) {
    const auto fv = face_vertices(grid, f);
    input.add_face(VertexHandle(where[fv[0].idx()]), VertexHandle(where[fv[1].idx()]),
                   VertexHandle(where[fv[2].idx()]));
  }
  ASSERT_GT(input.n_faces(), 32768u);
  RemeshOptions opt;
  opt.target_length = 0.02;
  const RemeshResult r = remesh(input, opt);
  expect_sound_output(r, input);
  for (auto v : input.vertices())
    ASSERT_LT((evaluate(r.mesh, r.input_on_output[v.idx()]) - input.point(v)).norm(), 1e-9)
        << "input vertex " << v.idx();
}

} // namespace
} // namespace remora
