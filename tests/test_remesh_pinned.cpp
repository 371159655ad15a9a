// The remesher's output, pinned: a hash of the mesh as our own writer writes it (binary PLY) and
// of the correspondence both ways, for procedural meshes and the bundled bunny under the main
// option sets. A change that alters any output bit fails here; when the change is meant to alter
// the output, check the figures (bench/remesh_goals.py, docs/remesh.md), then replace the hash
// with the one the failure prints and say so in the commit.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "remora/mesh/io.h"
#include "remora/mesh/primitives.h"
#include "remora/remesh/remesh.h"

namespace remora {
namespace {

// FNV-1a, 64 bits: stable across platforms and runs.
struct Fnv {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  void add(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 0x100000001b3ULL;
  }
};

// The hash of `result`: the bytes of its mesh written as binary PLY, then every location of the
// correspondence (face index and barycentrics).
std::string output_hash(const RemeshResult& result, const std::string& name) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("remora_pinned_" + name + ".ply");
  write_mesh(path.string(), result.mesh);
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::filesystem::remove(path);
  Fnv fnv;
  fnv.add(bytes.data(), bytes.size());
  for (const auto* side : {&result.output_on_input, &result.input_on_output})
    for (const SurfacePoint& sp : *side) {
      const int face = sp.face.idx();
      fnv.add(&face, sizeof face);
      fnv.add(sp.bary.data(), sizeof(double) * 3);
    }
  return fmt::format("{:016x}", fnv.h);
}

struct Pinned {
  const char* name;
  std::function<Mesh()> mesh;
  std::function<void(RemeshOptions&)> options;
  const char* hash;
};

Mesh bunny() {
  return read_mesh(std::string(REMORA_REPO_DATA) + "/bunny.ply").mesh;
}

// A flat grid whose columns are squeezed towards x = 0: needles everywhere on the left.
Mesh needle_grid() {
  Mesh m = make_grid(40, 20, 4.0, 2.0);
  for (auto v : m.vertices()) {
    Vec3 p = m.point(v);
    p[0] = 4.0 * p[0] * p[0] * p[0] / 16.0;
    m.set_point(v, p);
  }
  return m;
}

const Pinned kPinned[] = {
    {"icosphere", [] { return make_icosphere(3); }, [](RemeshOptions&) {}, "856cf7f48b2b5208"},
    {"icosphere_gravity", [] { return make_icosphere(3); },
     [](RemeshOptions& o) {
       o.equalization = Equalization::Gravity;
       o.equalize_iterations = 6;
     },
     "56f952493e29921a"},
    {"needle_grid", needle_grid, [](RemeshOptions&) {}, "02acf03110821240"},
    {"needle_grid_centroid_no_project", needle_grid,
     [](RemeshOptions& o) {
       o.smoothing_target = SmoothingTarget::Centroid;
       o.equalize_smoothing = 1.5;
       o.project = false;
     },
     "c296ae98fba27d8d"},
    {"annulus", [] { return make_annulus(6, 48, 0.5, 1.0); }, [](RemeshOptions&) {},
     "890c6cd43115c918"},
    {"cube_features", [] { return make_cube(6, 1.0); },
     [](RemeshOptions& o) { o.feature_angle_deg = 45; }, "05d40e37ff01e3b6"},
    {"torus", [] { return make_torus(48, 16, 1.0, 0.3); }, [](RemeshOptions&) {},
     "3b4dceae341c069a"},
    {"bunny", bunny, [](RemeshOptions&) {}, "3e3c251e84418d9c"},
    {"bunny_features", bunny, [](RemeshOptions& o) { o.feature_angle_deg = 45; },
     "1d65770351ac7aca"},
};

void PrintTo(const Pinned& p, std::ostream* os) {
  *os << p.name;
}

class RemeshPinned : public ::testing::TestWithParam<Pinned> {};

TEST_P(RemeshPinned, OutputIsBitwiseUnchanged) {
  const Pinned& p = GetParam();
  RemeshOptions options;
  p.options(options);
  const RemeshResult result = remesh(p.mesh(), options);
  EXPECT_EQ(output_hash(result, p.name), p.hash)
      << p.name << ": the remesher's output changed (" << result.mesh.n_vertices() << " vertices, "
      << result.mesh.n_faces() << " faces)";
}

INSTANTIATE_TEST_SUITE_P(Meshes, RemeshPinned, ::testing::ValuesIn(kPinned),
                         [](const ::testing::TestParamInfo<Pinned>& param) {
                           return std::string(param.param.name);
                         });

} // namespace
} // namespace remora
