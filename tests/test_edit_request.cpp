// Edit requests as data (multires/edit_request.h) and the vertex selections behind them
// (geometry/selection.h).
#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "remora/common/error.h"
#include "remora/geometry/selection.h"
#include "remora/mesh/primitives.h"
#include "remora/multires/edit_request.h"

namespace remora {
namespace {

using nlohmann::json;

std::string error_of(const json& j) {
  try {
    parse_edit_request(j);
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "";
}

TEST(EditRequest, ParsesEveryRegionAndTransformForm) {
  const json j = json::parse(R"({
    "k": 3, "solver": "ldlt", "areas": "mixed-symmetric", "details": "none", "method": "nonlinear",
    "energy": "blended-motions", "remesh": false, "refine_support": true,
    "base_smoothing": 1.5, "base_feature_cap": 0.5,
    "support": {"union": [[1, 2, 3], {"box": {"min": [0, 0, 0], "max": [1, 1, 1]}},
                          {"geodesic": {"vertex": 5, "radius": 0.5}}]},
    "handles": [
      {"region": {"sphere": {"center": [0, 0, 1], "radius": 0.2}},
       "transform": {"scale": {"factors": [2, 2, 2]}, "rotate": {"axis": [0, 0, 1], "degrees": 90},
                     "translate": [1, 0, 0]}},
      {"region": {"vertices": [7]}, "transform": {"matrix": [[1,0,0,1],[0,1,0,2],[0,0,1,3]]}},
      {"region": [8]}
    ]})");
  const EditRequest r = parse_edit_request(j);
  EXPECT_EQ(*r.k, 3);
  EXPECT_EQ(*r.solver, "ldlt");
  EXPECT_FALSE(*r.remesh);
  EXPECT_TRUE(*r.refine_support);
  EXPECT_FALSE(
      parse_edit_request({{"support", {1}}, {"handles", json::parse(R"([{"region": [1]}])")}})
          .refine_support.has_value());
  EXPECT_EQ(r.support.kind, RegionSpec::Kind::Union);
  ASSERT_EQ(r.support.parts.size(), 3u);
  EXPECT_EQ(r.support.parts[2].vertex, 5);
  ASSERT_EQ(r.handles.size(), 3u);
  EditorOptions o;
  apply_request_options(r, o);
  EXPECT_EQ(o.system.k, 3);
  EXPECT_EQ(o.system.areas, AreaWeights::MixedSymmetric);
  EXPECT_EQ(o.details, DetailMode::None);
  EXPECT_EQ(o.method, EditMethod::Nonlinear);
  EXPECT_EQ(o.nonlinear.energy, NonlinearEnergy::BlendedMotions);
  EXPECT_FALSE(o.remesh);
  EXPECT_EQ(o.base.smoothing, 1.5);
  EXPECT_EQ(o.base.feature_cap, 0.5);
  // Scale 2 about the center c = (1, 0, 0), then 90° about z through c, then +x: the point
  // (2, 0, 0) -> (3, 0, 0) -> (1, 2, 0) -> (2, 2, 0).
  const Transform t = resolve_transform(r.handles[0].transform, Eigen::Vector3d(1, 0, 0));
  const Eigen::Vector3d p = t.leftCols<3>() * Eigen::Vector3d(2, 0, 0) + t.col(3);
  EXPECT_LT((p - Eigen::Vector3d(2, 2, 0)).norm(), 1e-12);
  const Transform m = resolve_transform(r.handles[1].transform, Eigen::Vector3d::Zero());
  EXPECT_EQ(m.col(3), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(resolve_transform(r.handles[2].transform, Eigen::Vector3d(5, 5, 5)),
            identity_transform());
}

TEST(EditRequest, ErrorsNameTheJsonPath) {
  const json handles = json::parse(R"([{"region": [1]}])");
  EXPECT_NE(error_of({{"handles", handles}}).find("edit: missing 'support'"), std::string::npos);
  EXPECT_NE(error_of({{"support", {1}}, {"handles", json::array()}}).find("edit.handles"),
            std::string::npos);
  EXPECT_NE(error_of({{"support", {1}}, {"handles", handles}, {"colour", 1}})
                .find("unknown key 'colour'"),
            std::string::npos);
  EXPECT_NE(error_of({{"support", {1}}, {"handles", handles}, {"k", 4}}).find("edit.k"),
            std::string::npos);
  EXPECT_NE(error_of({{"support", {1}}, {"handles", handles}, {"refine_support", 1}})
                .find("edit.refine_support: expected true or false"),
            std::string::npos);
  EXPECT_NE(error_of({{"support", {{"sphere", {{"center", {0, 0}}, {"radius", 1}}}}},
                      {"handles", handles}})
                .find("edit.support.sphere.center: expected an array of 3 numbers"),
            std::string::npos);
  EXPECT_NE(error_of({{"support", {1, -2}}, {"handles", handles}}).find("edit.support[1]"),
            std::string::npos);
  const json bad_axis = json::parse(
      R"([{"region": [1], "transform": {"rotate": {"axis": [0, 0, 0], "degrees": 5}}}])");
  EXPECT_NE(error_of({{"support", {1}}, {"handles", bad_axis}})
                .find("edit.handles[0].transform.rotate.axis: must not be zero"),
            std::string::npos);
  const json mixed = json::parse(
      R"([{"region": [1], "transform": {"matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,0]], "translate": [1,1,1]}}])");
  EXPECT_NE(error_of({{"support", {1}}, {"handles", mixed}}).find("cannot be combined"),
            std::string::npos);
  EXPECT_NE(error_of({{"support", {{"areas", "mean"}}}, {"handles", handles}}).find("unknown key"),
            std::string::npos);
  EXPECT_NE(error_of({{"support", {1}}, {"handles", handles}, {"areas", "median"}})
                .find("unknown value 'median' (allowed: mean, mixed, mixed-symmetric)"),
            std::string::npos);
  EXPECT_NE(error_of({{"support", {1}}, {"handles", handles}, {"method", "arap"}})
                .find("edit.method: unknown value 'arap' (allowed: linear, nonlinear)"),
            std::string::npos);
  EXPECT_NE(error_of({{"support", {1}}, {"handles", handles}, {"energy", "screw"}})
                .find("edit.energy: unknown nonlinear energy 'screw': use rotated-laplacian, "
                      "propagated, blended-motions or arap"),
            std::string::npos);
  EXPECT_NE(error_of({{"support", {{"sphere", {{"center", {0, 0, 0}}, {"radius", -1}}}}},
                      {"handles", handles}})
                .find("edit.support.sphere.radius: must be >= 0"),
            std::string::npos);
  EXPECT_NE(error_of({{"support", {{"geodesic", {{"vertex", 3}, {"radius", -0.5}}}}},
                      {"handles", handles}})
                .find("edit.support.geodesic.radius: must be >= 0"),
            std::string::npos);
  EXPECT_NE(
      error_of({{"support", {{"box", {{"min", {0, 0, 0}}, {"size", 1}}}}}, {"handles", handles}})
          .find("unknown key 'size' (allowed: min, max)"),
      std::string::npos);
  // Transforms that mirror or collapse the handle are refused before any work.
  const json mirror = json::parse(
      R"([{"region": [1], "transform": {"matrix": [[-1,0,0,0],[0,1,0,0],[0,0,1,0]]}}])");
  EXPECT_NE(error_of({{"support", {1}}, {"handles", mirror}}).find("mirrors or collapses"),
            std::string::npos);
  const json flat =
      json::parse(R"([{"region": [1], "transform": {"scale": {"factors": [1, 0, 1]}}}])");
  EXPECT_NE(error_of({{"support", {1}}, {"handles", flat}}).find("factors: must be > 0"),
            std::string::npos);
}

TEST(Selection, SpheresBoxesAndGeodesicDiscs) {
  const Mesh grid = make_grid(10, 10, 1.0, 1.0); // vertex (i, j) at (i/10, j/10), id 11 j + i
  const auto sphere = select_sphere(grid, Vec3(0.5, 0.5, 0), 0.1001);
  EXPECT_EQ(sphere, (std::vector<int>{49, 59, 60, 61, 71}));
  const auto box = select_box(grid, Vec3(0, 0, -1), Vec3(0.15, 0.15, 1));
  EXPECT_EQ(box, (std::vector<int>{0, 1, 11, 12}));
  EXPECT_THROW(select_box(grid, Vec3(1, 0, 0), Vec3(0, 1, 1)), InvalidArgument);
  EXPECT_THROW(select_sphere(grid, Vec3(0, 0, 0), -1), InvalidArgument);
  // Edge paths: along the axes a geodesic disc of radius 0.2 reaches 2 steps.
  const auto disc = select_geodesic_disc(grid, VertexHandle(60), 0.2001);
  EXPECT_TRUE(std::find(disc.begin(), disc.end(), 62) != disc.end());
  EXPECT_TRUE(std::find(disc.begin(), disc.end(), 63) == disc.end());
  const auto order = geodesic_order(grid, VertexHandle(60), 5);
  ASSERT_EQ(order.size(), 5u);
  EXPECT_EQ(order[0], 60);
  EXPECT_THROW(geodesic_order(grid, VertexHandle(1000)), InvalidArgument);
  EXPECT_EQ(nearest_vertex(grid, Vec3(0.31, 0.69, 5)).idx(), 7 * 11 + 3);
  EXPECT_EQ(central_vertex(grid).idx(), 60); // (0.5, 0.5)
  EXPECT_THROW(nearest_vertex(Mesh(), Vec3(0, 0, 0)), InvalidArgument);
}

TEST(EditRequest, SelectsRegionsAndMapsFileIds) {
  const Mesh grid = make_grid(4, 4, 1.0, 1.0);
  RegionSpec u;
  u.kind = RegionSpec::Kind::Union;
  RegionSpec a;
  a.vertices = {3, 1, 3};
  RegionSpec b;
  b.kind = RegionSpec::Kind::Sphere;
  b.center = {0, 0, 0};
  b.radius = 0.01;
  u.parts = {a, b};
  EXPECT_EQ(select_region(grid, u), (std::vector<int>{0, 1, 3}));
  a.vertices = {99};
  EXPECT_THROW(select_region(grid, a), InvalidArgument);
  // File ids: loaded vertex v came from file vertex source[v]; file vertex 1 was dropped and file
  // vertex 2 split in two.
  const std::vector<std::uint32_t> source{0, 2, 3, 2};
  RegionSpec ids;
  ids.vertices = {2, 3};
  map_file_vertex_ids(ids, source);
  std::sort(ids.vertices.begin(), ids.vertices.end());
  EXPECT_EQ(ids.vertices, (std::vector<int>{1, 2, 3}));
  RegionSpec dropped;
  dropped.vertices = {1};
  EXPECT_THROW(map_file_vertex_ids(dropped, source), InvalidArgument);
}

} // namespace
} // namespace remora
