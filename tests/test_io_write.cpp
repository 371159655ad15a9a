// Mesh file writing: round trips through every format and encoding, the memory writer, and atomic
// writes that leave nothing behind when they fail.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "io_support.h"
#include "remora/common/error.h"
#include "remora/mesh/io.h"

namespace {

namespace fs = std::filesystem;
using remora::IoError;
using remora::MeshFormat;
using remora::read_soup;
using remora::SoupFile;
using namespace remora::io_testing;

// ------------------------------------------------------------------------------------------------
// Round trips

// An octahedron with coordinates that do not print in few digits.
remora::Mesh octahedron() {
  remora::Mesh mesh;
  const remora::Vec3 c(0.1, 1.0 / 3, -2.5e-7);
  const double r = 1.0 / 7;
  const remora::VertexHandle px = mesh.add_vertex(c + remora::Vec3(r, 1e-9, 0));
  const remora::VertexHandle nx = mesh.add_vertex(c - remora::Vec3(1.1 * r, 0, 3e-12));
  const remora::VertexHandle py = mesh.add_vertex(c + remora::Vec3(0, r * std::numbers::pi, 0));
  const remora::VertexHandle ny = mesh.add_vertex(c - remora::Vec3(1e-300, r, 0));
  const remora::VertexHandle pz = mesh.add_vertex(c + remora::Vec3(0, 0, std::sqrt(2.0)));
  const remora::VertexHandle nz = mesh.add_vertex(c - remora::Vec3(0, 0, 12345.678901234567));
  mesh.add_face(px, py, pz);
  mesh.add_face(py, nx, pz);
  mesh.add_face(nx, ny, pz);
  mesh.add_face(ny, px, pz);
  mesh.add_face(py, px, nz);
  mesh.add_face(nx, py, nz);
  mesh.add_face(ny, nx, nz);
  mesh.add_face(px, ny, nz);
  return mesh;
}

struct Expected {
  std::vector<remora::Vec3> points;
  std::vector<Poly> triangles;
};

// The mesh's live vertices in order, with compact ids.
Expected expected_of(const remora::Mesh& mesh) {
  Expected e;
  std::map<int, std::uint32_t> id;
  for (const remora::VertexHandle v : mesh.vertices()) {
    id[v.idx()] = static_cast<std::uint32_t>(e.points.size());
    e.points.push_back(mesh.point(v));
  }
  for (const remora::FaceHandle f : mesh.faces()) {
    Poly t;
    for (const remora::VertexHandle v : mesh.fv_range(f)) t.push_back(id.at(v.idx()));
    e.triangles.push_back(t);
  }
  return e;
}

void check_round_trip(const remora::Mesh& mesh, const std::string& path, bool binary) {
  SCOPED_TRACE(path + (binary ? " binary" : " ascii"));
  remora::write_mesh(path, mesh, {.binary = binary});
  const SoupFile r = read_soup(path);
  const Expected e = expected_of(mesh);
  const bool stl = remora::format_from_path(path) == MeshFormat::Stl;
  ASSERT_EQ(r.soup.num_polygons(), e.triangles.size());
  if (!stl) {
    ASSERT_EQ(r.soup.points.size(), e.points.size());
    for (std::size_t i = 0; i < e.points.size(); ++i)
      for (int k = 0; k < 3; ++k) EXPECT_EQ(r.soup.points[i][k], e.points[i][k]) << i << " " << k;
    for (std::size_t f = 0; f < e.triangles.size(); ++f)
      EXPECT_EQ(polygon(r.soup, f), e.triangles[f]) << f;
    return;
  }
  // STL shares no vertices and stores floats: compare each corner's position.
  ASSERT_EQ(r.soup.points.size(), 3 * e.triangles.size());
  for (std::size_t f = 0; f < e.triangles.size(); ++f) {
    const Poly got = polygon(r.soup, f);
    ASSERT_EQ(got.size(), 3u);
    for (std::size_t k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a)
        EXPECT_EQ(r.soup.points[got[k]][a],
                  static_cast<double>(static_cast<float>(e.points[e.triangles[f][k]][a])))
            << f << " " << k << " " << a;
  }
}

TEST(IoRoundTrip, EveryFormat) {
  TempDir dir;
  const remora::Mesh mesh = octahedron();
  check_round_trip(mesh, (dir.path() / "octa.obj").string(), false);
  check_round_trip(mesh, (dir.path() / "octa.off").string(), false);
  check_round_trip(mesh, (dir.path() / "octa.ply").string(), true);
  check_round_trip(mesh, (dir.path() / "octa_ascii.PLY").string(), false);
  check_round_trip(mesh, (dir.path() / "octa.stl").string(), true);
  check_round_trip(mesh, (dir.path() / "octa_ascii.stl").string(), false);
  EXPECT_EQ(read_soup((dir.path() / "octa.ply").string()).info.encoding, "binary_little_endian");
  EXPECT_EQ(read_soup((dir.path() / "octa_ascii.PLY").string()).info.encoding, "ascii");
  EXPECT_EQ(read_soup((dir.path() / "octa.stl").string()).info.encoding, "binary_little_endian");
  EXPECT_EQ(read_soup((dir.path() / "octa_ascii.stl").string()).info.encoding, "ascii");
}

// The file writer is the memory writer plus the file: the same bytes for every format and
// encoding, and the bytes read back as the mesh.
TEST(IoRoundTrip, MemoryWriterGivesTheFileBytes) {
  TempDir dir;
  const remora::Mesh mesh = octahedron();
  for (const std::string name : {"octa.obj", "octa.off", "octa.ply", "octa.stl"}) {
    for (const bool binary : {true, false}) {
      SCOPED_TRACE(name + (binary ? " binary" : " ascii"));
      const std::string path = (dir.path() / name).string();
      const MeshFormat format = remora::format_from_path(path);
      const std::string bytes =
          remora::write_mesh_to_memory(mesh, format, name, {.binary = binary});
      remora::write_mesh(path, mesh, {.binary = binary});
      std::ifstream in(path, std::ios::binary);
      const std::string file((std::istreambuf_iterator<char>(in)),
                             std::istreambuf_iterator<char>());
      EXPECT_EQ(bytes, file);
      const SoupFile soup = remora::read_soup_from_memory(bytes, format, name);
      EXPECT_EQ(soup.soup.num_polygons(), 8u);
      EXPECT_EQ(soup.soup.points.size(), format == MeshFormat::Stl ? 24u : 6u);
    }
  }
}

TEST(IoRoundTrip, MemoryWriterRefusesNonFiniteCoordinates) {
  remora::Mesh mesh = octahedron();
  mesh.point(remora::VertexHandle(5))[2] = -std::numeric_limits<double>::infinity();
  try {
    remora::write_mesh_to_memory(mesh, MeshFormat::Obj, "upload.obj");
    ADD_FAILURE();
  } catch (const IoError& e) {
    EXPECT_TRUE(contains(e.what(), "upload.obj")) << e.what();
    EXPECT_TRUE(contains(e.what(), "vertex 5 has a non-finite z coordinate (-infinity)"))
        << e.what();
  }
}

TEST(IoRoundTrip, DeletedElementsAreLeftOut) {
  TempDir dir;
  remora::Mesh mesh = octahedron();
  // Deleting the +z apex removes it and its 4 faces; without garbage collection they stay in the
  // arrays, marked deleted.
  mesh.delete_vertex(remora::VertexHandle(4), false);
  ASSERT_EQ(mesh.n_vertices(), 6u);
  ASSERT_EQ(expected_of(mesh).points.size(), 5u);
  ASSERT_EQ(expected_of(mesh).triangles.size(), 4u);
  for (const std::string name : {"open.obj", "open.off", "open.ply", "open.stl"})
    check_round_trip(mesh, (dir.path() / name).string(), true);
}

// ------------------------------------------------------------------------------------------------
// Atomic writing

TEST(IoWrite, MissingFolderCreatesNothing) {
  TempDir dir;
  const fs::path target = dir.path() / "no" / "such" / "mesh.obj";
  try {
    remora::write_mesh(target.string(), octahedron());
    ADD_FAILURE();
  } catch (const IoError& e) {
    EXPECT_TRUE(contains(e.what(), "mesh.obj")) << e.what();
    EXPECT_TRUE(contains(e.what(), "is not an existing folder")) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir.path() / "no"));
  EXPECT_TRUE(dir.listing().empty());
}

TEST(IoWrite, UnknownExtensionCreatesNothing) {
  TempDir dir;
  EXPECT_THROW(remora::write_mesh((dir.path() / "mesh.xyz").string(), octahedron()), IoError);
  EXPECT_THROW(remora::write_mesh((dir.path() / "mesh").string(), octahedron()), IoError);
  EXPECT_TRUE(dir.listing().empty());
}

TEST(IoWrite, NonFiniteCoordinateWritesNothing) {
  TempDir dir;
  remora::Mesh mesh = octahedron();
  mesh.point(remora::VertexHandle(2))[1] = std::numeric_limits<double>::quiet_NaN();
  try {
    remora::write_mesh((dir.path() / "nan.ply").string(), mesh);
    ADD_FAILURE();
  } catch (const IoError& e) {
    EXPECT_TRUE(contains(e.what(), "vertex 2 has a non-finite y coordinate (NaN)")) << e.what();
  }
  EXPECT_TRUE(dir.listing().empty());
}

TEST(IoWrite, OverwritesAndLeavesNoTemporaryFiles) {
  TempDir dir;
  const std::string path = dir.write("mesh.off", "old content that is not a mesh");
  remora::write_mesh(path, octahedron());
  EXPECT_EQ(read_soup(path).soup.num_polygons(), 8u);
  remora::write_mesh((dir.path() / "mesh.stl").string(), octahedron());
  remora::write_mesh((dir.path() / "mesh.stl").string(), octahedron(), {.binary = false});
  EXPECT_EQ(read_soup((dir.path() / "mesh.stl").string()).info.encoding, "ascii");
  EXPECT_EQ(dir.listing(), (std::vector<std::string>{"mesh.off", "mesh.stl"}));
}

TEST(IoWrite, TargetIsAFolder) {
  TempDir dir;
  fs::create_directory(dir.path() / "taken.ply");
  EXPECT_THROW(remora::write_mesh((dir.path() / "taken.ply").string(), octahedron()), IoError);
  EXPECT_EQ(dir.listing(), std::vector<std::string>{"taken.ply"});
  EXPECT_TRUE(fs::is_directory(dir.path() / "taken.ply"));
}

TEST(IoWrite, RelativePathInTheWorkingFolder) {
  TempDir dir;
  struct Cwd {
    fs::path old = fs::current_path();
    ~Cwd() { fs::current_path(old); }
  } restore;
  fs::current_path(dir.path());
  remora::write_mesh("here.obj", octahedron());
  EXPECT_EQ(dir.listing(), std::vector<std::string>{"here.obj"});
}

} // namespace
