// run_edit_request() of harness.h.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness.h"
#include "remora/common/error.h"
#include "remora/mesh/primitives.h"
#include "remora/multires/edit_request.h"

namespace remora::fuzz {

namespace {

void check(bool ok, const char* what) {
  if (!ok) throw CheckFailed(what);
}

/// 162 vertices; the file ids of a load that dropped file vertex 10 and split vertex 5 in two.
struct Fixture {
  Mesh mesh = make_icosphere(2, 1.0);
  std::vector<std::uint32_t> source_vertex;
  Fixture() {
    for (std::size_t v = 0; v + 1 < mesh.n_vertices(); ++v)
      source_vertex.push_back(static_cast<std::uint32_t>(v < 10 ? v : v + 1));
    source_vertex.push_back(5);
  }
};

/// The region's vertices (or none when it is refused), checked.
std::vector<int> select(const Fixture& f, const RegionSpec& region) {
  RegionSpec mapped = region;
  try {
    map_file_vertex_ids(mapped, f.source_vertex);
  } catch (const InvalidArgument&) {
  }
  try {
    const std::vector<int> ids = select_region(f.mesh, region);
    for (std::size_t i = 0; i < ids.size(); ++i) {
      check(ids[i] >= 0 && ids[i] < static_cast<int>(f.mesh.n_vertices()), "an id out of range");
      check(i == 0 || ids[i - 1] < ids[i], "a region that is not sorted and unique");
    }
    return ids;
  } catch (const InvalidArgument&) {
    return {};
  }
}

} // namespace

void run_edit_request(std::string_view input) {
  static const Fixture fixture;
  const nlohmann::json j = nlohmann::json::parse(input.begin(), input.end(), nullptr, false);
  if (j.is_discarded()) return;
  EditRequest request;
  try {
    request = parse_edit_request(j);
  } catch (const InvalidArgument&) {
    return;
  }
  EditorOptions options;
  try {
    apply_request_options(request, options);
  } catch (const InvalidArgument&) {
  }
  select(fixture, request.support);
  for (const HandleSpec& h : request.handles) {
    const std::vector<int> ids = select(fixture, h.region);
    Eigen::Vector3d center(0, 0, 0);
    for (const int v : ids) {
      const Vec3& p = fixture.mesh.point(VertexHandle(v));
      center += Eigen::Vector3d(p[0], p[1], p[2]) / double(ids.size());
    }
    resolve_transform(h.transform, center);
  }
}

} // namespace remora::fuzz
