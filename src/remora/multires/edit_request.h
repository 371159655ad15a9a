// An edit as data: what `remora edit --edit EDIT.json` reads and what the server receives. The
// format is documented with examples in docs/editing.md (a test runs those examples):
//
//   { "k": 2, "solver": "cholmod", "areas": "mean", "details": "normal", "method": "linear",
//     "remesh": true, "refine_support": false,
//     "base_smoothing": 2.0, "base_feature_cap": 1.0,
//     "support": <region>,
//     "handles": [ { "region": <region>, "transform": <transform> }, ... ] }
//
//   <region>:    [ids...] | {"vertices": [ids...]} | {"sphere": {"center": [x,y,z], "radius": r}}
//                | {"box": {"min": [x,y,z], "max": [x,y,z]}}
//                | {"geodesic": {"vertex": id, "radius": r}} | {"union": [<region>, ...]}
//   <transform>: {"matrix": [[4 numbers] x 3]}, or any of
//                {"scale": {"factors": [sx,sy,sz], "center": [x,y,z]},
//                 "rotate": {"axis": [x,y,z], "degrees": a, "center": [x,y,z]},
//                 "translate": [dx,dy,dz]}
//                applied in that order (scale, then rotate, then translate); a missing center is
//                the handle's centroid.
// Every key but "support" and "handles" is optional. Unknown keys are errors, so that a typo is
// not silently ignored; messages name the JSON path ("handles[1].transform.rotate.axis: ...").
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "remora/mesh/mesh.h"
#include "remora/multires/editor.h"

namespace remora {

struct RegionSpec {
  enum class Kind { Vertices, Sphere, Box, Geodesic, Union } kind = Kind::Vertices;
  std::vector<int> vertices;                  ///< Vertices
  Eigen::Vector3d center{0, 0, 0};            ///< Sphere
  double radius = 0.0;                        ///< Sphere, Geodesic
  Eigen::Vector3d min{0, 0, 0}, max{0, 0, 0}; ///< Box
  int vertex = -1;                            ///< Geodesic: the seed
  std::vector<RegionSpec> parts;              ///< Union
};

struct TransformSpec {
  std::optional<Transform> matrix;
  std::optional<Eigen::Vector3d> scale, scale_center;
  std::optional<Eigen::Vector3d> rotate_axis, rotate_center;
  double rotate_degrees = 0.0;
  std::optional<Eigen::Vector3d> translate;
};

struct HandleSpec {
  RegionSpec region;
  TransformSpec transform;
};

struct EditRequest {
  std::optional<int> k;
  std::optional<std::string> solver, areas, details, method, energy;
  std::optional<bool> remesh;
  std::optional<bool> refine_support; ///< the caller's: refine_region() before the editor
  std::optional<double> base_smoothing, base_feature_cap;
  RegionSpec support;
  std::vector<HandleSpec> handles;
};

/// Parses and validates the structure (types, counts, finite numbers, known names; unions nest at
/// most 32 deep). Throws InvalidArgument with the JSON path of the first problem.
EditRequest parse_edit_request(const nlohmann::json& json);
RegionSpec parse_region(const nlohmann::json& json, const std::string& path = "region");
TransformSpec parse_transform(const nlohmann::json& json, const std::string& path = "transform");

/// The vertices of `mesh` a region selects, sorted and unique. Throws InvalidArgument for ids or
/// seeds out of range.
std::vector<int> select_region(const Mesh& mesh, const RegionSpec& region);

/// Rewrites the vertex ids of a region (lists and geodesic seeds, unions included) from the ids of
/// a file to those of the mesh loaded from it: source_vertex[v] is the file vertex of loaded
/// vertex v (LoadResult::source_vertex). A file vertex split on load (a non-manifold one) maps to
/// all its copies. Throws InvalidArgument for a file id that no loaded vertex comes from (an
/// unreferenced vertex the loader dropped, or one beyond the file's count).
void map_file_vertex_ids(RegionSpec& region, const std::vector<std::uint32_t>& source_vertex);

/// The affine map of a transform spec; `center` stands in for missing centers.
Transform resolve_transform(const TransformSpec& spec, const Eigen::Vector3d& center);

/// Applies the request's options over `options` (fields the request leaves out stay).
void apply_request_options(const EditRequest& request, EditorOptions& options);

} // namespace remora
