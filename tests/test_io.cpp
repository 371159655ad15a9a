// Mesh file reading and writing: good and broken files of every format, round trips, atomic
// writes, and the real meshes of ../shared/data.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "remora/common/error.h"
#include "remora/mesh/io.h"

namespace {

namespace fs = std::filesystem;
using remora::IoError;
using remora::MeshFormat;
using remora::read_soup;
using remora::SoupFile;

// A fresh folder per test, removed afterwards.
class TempDir {
public:
  TempDir() {
    static std::atomic<int> counter{0};
    path_ = fs::temp_directory_path() /
            ("remora_test_io_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const fs::path& path() const { return path_; }

  std::string write(const std::string& name, std::string_view bytes) const {
    const fs::path p = path_ / name;
    std::ofstream out(p, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return p.string();
  }

  std::vector<std::string> listing() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(path_))
      names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

private:
  fs::path path_;
};

// Little- or big-endian binary content.
class Bytes {
public:
  explicit Bytes(bool big_endian = false) : big_(big_endian) {}

  template <class T>
  Bytes& put(T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if (big_ != (std::endian::native == std::endian::big)) std::reverse(b, b + sizeof(T));
    data_.append(b, sizeof(T));
    return *this;
  }
  Bytes& text(std::string_view s) {
    data_ += s;
    return *this;
  }
  const std::string& str() const { return data_; }
  std::size_t size() const { return data_.size(); }

private:
  bool big_;
  std::string data_;
};

std::optional<IoError> read_error(const std::string& path) {
  try {
    read_soup(path);
  } catch (const IoError& e) {
    return e;
  }
  return std::nullopt;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The file's read fails with an IoError that names the file, the line, and `phrase`.
void expect_error_at_line(const std::string& path, std::uint64_t line, const std::string& phrase) {
  SCOPED_TRACE(path);
  const auto e = read_error(path);
  ASSERT_TRUE(e.has_value()) << "no IoError";
  const std::string msg = e->what();
  EXPECT_TRUE(contains(msg, fs::path(path).filename().string())) << msg;
  EXPECT_EQ(e->line(), std::optional<std::uint64_t>(line)) << msg;
  EXPECT_TRUE(contains(msg, ": line " + std::to_string(line) + ": ")) << msg;
  EXPECT_TRUE(contains(msg, phrase)) << msg << "\n  expected: " << phrase;
}

// ... at a byte offset (binary formats).
void expect_error_at_byte(const std::string& path, std::uint64_t offset,
                          const std::string& phrase) {
  SCOPED_TRACE(path);
  const auto e = read_error(path);
  ASSERT_TRUE(e.has_value()) << "no IoError";
  const std::string msg = e->what();
  EXPECT_TRUE(contains(msg, fs::path(path).filename().string())) << msg;
  EXPECT_FALSE(e->line().has_value()) << msg;
  EXPECT_EQ(e->byte_offset(), std::optional<std::uint64_t>(offset)) << msg;
  EXPECT_TRUE(contains(msg, ": byte " + std::to_string(offset) + ": ")) << msg;
  EXPECT_TRUE(contains(msg, phrase)) << msg << "\n  expected: " << phrase;
}

// ... about the file as a whole (no place in it).
void expect_error(const std::string& path, const std::string& phrase) {
  SCOPED_TRACE(path);
  const auto e = read_error(path);
  ASSERT_TRUE(e.has_value()) << "no IoError";
  const std::string msg = e->what();
  EXPECT_TRUE(contains(msg, fs::path(path).filename().string())) << msg;
  EXPECT_TRUE(contains(msg, phrase)) << msg << "\n  expected: " << phrase;
}

std::vector<std::uint32_t> polygon(const remora::PolygonSoup& soup, std::size_t f) {
  return {soup.indices.begin() + soup.offsets[f], soup.indices.begin() + soup.offsets[f + 1]};
}

using Poly = std::vector<std::uint32_t>;

// ------------------------------------------------------------------------------------------------
// Formats and files

TEST(IoFormat, ExtensionsAreCaseInsensitive) {
  EXPECT_EQ(remora::format_from_path("a/b.obj"), MeshFormat::Obj);
  EXPECT_EQ(remora::format_from_path("b.OBJ"), MeshFormat::Obj);
  EXPECT_EQ(remora::format_from_path("b.Off"), MeshFormat::Off);
  EXPECT_EQ(remora::format_from_path("/x.y/b.ply"), MeshFormat::Ply);
  EXPECT_EQ(remora::format_from_path("featuretype.STL"), MeshFormat::Stl);
}

TEST(IoFormat, UnknownExtensionListsTheSupportedOnes) {
  for (const std::string path : {"mesh.xyz", "mesh", "mesh.ply.gz", "folder.obj/"}) {
    try {
      remora::format_from_path(path);
      ADD_FAILURE() << path;
    } catch (const IoError& e) {
      const std::string msg = e.what();
      EXPECT_TRUE(contains(msg, ".obj .off .ply .stl")) << msg;
      EXPECT_TRUE(contains(msg, path)) << msg;
    }
  }
}

TEST(IoFormat, MissingFileSaysWhy) {
  TempDir dir;
  const std::string path = (dir.path() / "missing.ply").string();
  expect_error(path, "No such file or directory");
}

TEST(IoFormat, FolderIsNotAFile) {
  TempDir dir;
  fs::create_directory(dir.path() / "folder.obj");
  expect_error((dir.path() / "folder.obj").string(), "folder");
}

TEST(IoFormat, UnknownExtensionOnRead) {
  TempDir dir;
  expect_error(dir.write("mesh.txt", "v 0 0 0\n"), "unknown extension '.txt'");
}

TEST(IoFormat, FromMemoryUsesTheGivenName) {
  const SoupFile ok = remora::read_soup_from_memory("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
                                                    MeshFormat::Obj, "upload.obj");
  EXPECT_EQ(ok.soup.num_polygons(), 1u);
  try {
    remora::read_soup_from_memory("v 0 0 0\nf 1 2 3\n", MeshFormat::Obj, "upload.obj");
    ADD_FAILURE();
  } catch (const IoError& e) {
    EXPECT_EQ(e.path(), "upload.obj");
    EXPECT_EQ(e.line(), std::optional<std::uint64_t>(2));
  }
}

// ------------------------------------------------------------------------------------------------
// OBJ

TEST(IoObj, QuadsNegativeIndicesAndCornerForms) {
  TempDir dir;
  const std::string path = dir.write("shapes.obj", "# a comment\n"
                                                   "mtllib shapes.mtl\n"
                                                   "o square\n"
                                                   "v 0 0 0\n"
                                                   "v +1 0 0\n"
                                                   "v 1 1.5e0 0 1.0\n"
                                                   "v 0 1 0 0.2 0.3 0.4\n"
                                                   "vt 0 0\n"
                                                   "vt 1 0\n"
                                                   "vn 0 0 1\n"
                                                   "usemtl red\n"
                                                   "s off\n"
                                                   "f 1/1/1 2/2/1 3/2/1 4/1/1\n"
                                                   "v 0.5 0.5 1\r\n"
                                                   "f -4//1 -3//1 -1//1\r\n"
                                                   "f 2/2 3/1 5/2 # trailing comment\n"
                                                   "g part\n"
                                                   "l 1 2\n"
                                                   "vt 0 1\n"
                                                   "\n"
                                                   "f 5 4 3 2 1\n");
  const SoupFile r = read_soup(path);
  EXPECT_EQ(r.info.format, "obj");
  EXPECT_EQ(r.info.encoding, "ascii");
  EXPECT_EQ(r.info.vertices_in_file, 5u);
  EXPECT_EQ(r.info.faces_in_file, 4u);
  ASSERT_EQ(r.soup.points.size(), 5u);
  EXPECT_EQ(r.soup.points[1], remora::Vec3(1, 0, 0));
  EXPECT_EQ(r.soup.points[2], remora::Vec3(1, 1.5, 0));
  EXPECT_EQ(r.soup.points[4], remora::Vec3(0.5, 0.5, 1));
  ASSERT_EQ(r.soup.num_polygons(), 4u);
  EXPECT_EQ(polygon(r.soup, 0), (Poly{0, 1, 2, 3}));
  EXPECT_EQ(polygon(r.soup, 1), (Poly{1, 2, 4}));
  EXPECT_EQ(polygon(r.soup, 2), (Poly{1, 2, 4}));
  EXPECT_EQ(polygon(r.soup, 3), (Poly{4, 3, 2, 1, 0}));
  const std::vector<std::string> skipped{"1 'mtllib' line", "1 'o' line",      "3 'vt' lines",
                                         "1 'vn' line",     "1 'usemtl' line", "1 's' line",
                                         "1 'g' line",      "1 'l' line"};
  EXPECT_EQ(r.info.skipped, skipped);
}

TEST(IoObj, ForwardReferencesAndLineContinuation) {
  TempDir dir;
  const SoupFile r = read_soup(dir.write("forward.obj", "f 1 2 \\\n  3\n"
                                                        "v 0 0 0\nv 1 0 0\nv 0 1 0\n"));
  ASSERT_EQ(r.soup.num_polygons(), 1u);
  EXPECT_EQ(polygon(r.soup, 0), (Poly{0, 1, 2}));
}

TEST(IoObj, Errors) {
  TempDir dir;
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  expect_error_at_line(dir.write("nan.obj", "v 0 0 0\nv 0 nan 0\nv 1 1 1\nf 1 2 3\n"), 2,
                       "vertex 2 has a non-finite y coordinate (NaN)");
  expect_error_at_line(dir.write("inf.obj", "v 0 0 0\nv 0 0 0\nv 1 1 -inf\nf 1 2 3\n"), 3,
                       "vertex 3 has a non-finite z coordinate (-infinity)");
  expect_error_at_line(dir.write("huge.obj", "v 1e999 0 0\n"), 1,
                       "'1e999' is out of the range of a double");
  expect_error_at_line(dir.write("word.obj", tri + "v 0 0 abc\n"), 4, "'abc' is not a number");
  expect_error_at_line(dir.write("short.obj", "v 0 0\n"), 1, "vertex 1 has 2 coordinates");
  expect_error_at_line(dir.write("range.obj", tri + "\nf 1 2 9\n"), 5,
                       "face refers to vertex 9 but the file has 3 vertices");
  expect_error_at_line(dir.write("forward.obj", "f 1 2 4\n" + tri), 1,
                       "face refers to vertex 4 but the file has 3 vertices");
  expect_error_at_line(dir.write("zero.obj", tri + "f 0 1 2\n"), 4, "vertex index 0");
  expect_error_at_line(dir.write("before.obj", tri + "f -1 -2 -4\n"), 4,
                       "relative vertex index -4 points before the first vertex");
  expect_error_at_line(dir.write("two.obj", tri + "f 1 2\n"), 4, "face has 2 corners");
  expect_error_at_line(dir.write("token.obj", tri + "f 1 2 x/1\n"), 4, "'x' is not an integer");
  expect_error_at_line(dir.write("nul.obj", tri + std::string("f 1 2 3\0\n", 9)), 4,
                       "not a text file: byte 0x00 at offset 31");
  expect_error_at_line(dir.write("ctrl.obj", "v 0 0 0\n\x01\n"), 2, "not a text file: byte 0x01");
  expect_error(dir.write("nofaces.obj", tri), "no faces");
  expect_error(dir.write("empty.obj", ""), "no faces");
}

// ------------------------------------------------------------------------------------------------
// OFF

TEST(IoOff, CommentsVariantsColoursAndPolygons) {
  TempDir dir;
  const std::string body = "# vertices\n"
                           "0 0 0 255 0 0\n"
                           "\n"
                           "1 0 0 0 255 0 # red\n"
                           "1 1 0\n"
                           "+0 1 -0.25e1\n"
                           "# faces\n"
                           "4 0 1 2 3 0.1 0.2 0.3\n"
                           "3 0 2 1\n"
                           "\n  \n";
  for (const std::string keyword : {"OFF", "COFF", "NOFF", "CNOFF", "STOFF", "STCNOFF"}) {
    const SoupFile r = read_soup(dir.write("a.off", "# header\n" + keyword + " 4 2 0\n" + body));
    EXPECT_EQ(r.info.format, "off");
    EXPECT_EQ(r.info.encoding, "ascii");
    EXPECT_EQ(r.info.vertices_in_file, 4u);
    EXPECT_EQ(r.info.faces_in_file, 2u);
    ASSERT_EQ(r.soup.points.size(), 4u);
    EXPECT_EQ(r.soup.points[3], remora::Vec3(0, 1, -2.5));
    ASSERT_EQ(r.soup.num_polygons(), 2u);
    EXPECT_EQ(polygon(r.soup, 0), (Poly{0, 1, 2, 3}));
    EXPECT_EQ(polygon(r.soup, 1), (Poly{0, 2, 1}));
  }
  // Counts on their own line, CRLF line ends.
  const SoupFile r = read_soup(dir.write("b.off", "OFF\r\n3 1 0\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n"
                                                  "3 0 1 2\r\n"));
  EXPECT_EQ(r.soup.num_polygons(), 1u);
}

TEST(IoOff, Errors) {
  TempDir dir;
  const std::string head = "OFF\n4 1 0\n";
  const std::string verts = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n";
  expect_error_at_line(dir.write("4off.off", "4OFF\n1 1 0\n0 0 0 0\n"), 1, "unsupported OFF");
  expect_error_at_line(dir.write("noff.off", "nOFF\n3\n1 1 0\n"), 1, "unsupported OFF");
  expect_error_at_line(dir.write("binary.off", "OFF BINARY\n"), 1, "unsupported: binary OFF");
  expect_error_at_line(dir.write("other.off", "# c\nPLY 1 1 0\n"), 2, "not an OFF file");
  expect_error_at_line(dir.write("counts.off", "OFF\n4 x 0\n"), 2, "'x' is not an integer");
  expect_error_at_line(dir.write("verts.off", head + "0 0 0\n1 0 0\n1 1 0\n"), 5,
                       "header declares 4 vertices but the file ends after 3");
  expect_error_at_line(dir.write("faces.off", "OFF\n4 3 0\n" + verts + "3 0 1 2\n# end\n"), 8,
                       "header declares 3 faces but the file ends after 1");
  expect_error_at_line(dir.write("more.off", head + verts + "3 0 1 2\n\n3 0 2 3\n"), 9,
                       "data continues after the 1 face the header declares");
  expect_error_at_line(dir.write("negative.off", head + verts + "3 0 -1 2\n"), 7,
                       "face 0 refers to vertex -1 (negative)");
  expect_error_at_line(dir.write("range.off", head + verts + "3 0 1 4\n"), 7,
                       "face 0 refers to vertex 4 but the file has 4 vertices");
  expect_error_at_line(dir.write("two.off", head + verts + "2 0 1\n"), 7, "face 0 has 2 corners");
  expect_error_at_line(dir.write("few.off", head + verts + "4 0 1 2\n"), 7,
                       "face 0 declares 4 corners but the line has only 3 vertex indices");
  expect_error_at_line(dir.write("nan.off", head + "0 0 0\n1 0 NaN\n1 1 0\n0 1 0\n3 0 1 2\n"), 4,
                       "vertex 1 has a non-finite z coordinate (NaN)");
  expect_error_at_line(dir.write("number.off", head + "0 0 0\n1 1.2.3 0\n"), 4,
                       "'1.2.3' is not a number");
  expect_error_at_line(dir.write("nul.off", head + "0 0 0\n1 0 0\n1 1\x7f 0\n"), 5,
                       "not a text file: byte 0x7f");
  expect_error_at_line(dir.write("zero.off", "OFF\n4 0 0\n" + verts), 2, "no faces");
  expect_error(dir.write("empty.off", "\n# nothing\n"), "no faces");
}

// ------------------------------------------------------------------------------------------------
// PLY

const std::string kPlyXyzFace = "element vertex 3\n"
                                "property float x\n"
                                "property float y\n"
                                "property float z\n"
                                "element face 1\n"
                                "property list uchar int vertex_indices\n"
                                "end_header\n";

std::string ascii_ply(const std::string& body, const std::string& elements = kPlyXyzFace) {
  return "ply\nformat ascii 1.0\n" + elements + body;
}

TEST(IoPly, AsciiWithCameraAndExtraProperties) {
  TempDir dir;
  const std::string path = dir.write("camera.ply", "ply\n"
                                                   "format ascii 1.0\n"
                                                   "comment made by hand\n"
                                                   "obj_info nothing\n"
                                                   "element camera 1\n"
                                                   "property float view_px\n"
                                                   "property list uchar float k\n"
                                                   "element vertex 4\n"
                                                   "property float x\n"
                                                   "property float y\n"
                                                   "property float z\n"
                                                   "property uchar confidence\n"
                                                   "property list uchar int ignored\n"
                                                   "element face 2\n"
                                                   "property uchar flags\n"
                                                   "property list uchar int vertex_indices\n"
                                                   "property float quality\n"
                                                   "end_header\n"
                                                   "1.5 2 0.25 0.5\n"
                                                   "0 0 0 7 0\n"
                                                   "1 0 0 7 2 5 6\n"
                                                   "1 1 0 7 0 \n"
                                                   "0 1 -2.5 7 1 9\n"
                                                   "0 3 0 1 2 0.5\n"
                                                   "0 4 3 2 1 0 1e-3\n"
                                                   "\n \t\n");
  const SoupFile r = read_soup(path);
  EXPECT_EQ(r.info.format, "ply");
  EXPECT_EQ(r.info.encoding, "ascii");
  EXPECT_EQ(r.info.vertices_in_file, 4u);
  EXPECT_EQ(r.info.faces_in_file, 2u);
  EXPECT_EQ(r.info.skipped, std::vector<std::string>{"element camera (1)"});
  ASSERT_EQ(r.soup.points.size(), 4u);
  EXPECT_EQ(r.soup.points[3], remora::Vec3(0, 1, -2.5));
  ASSERT_EQ(r.soup.num_polygons(), 2u);
  EXPECT_EQ(polygon(r.soup, 0), (Poly{0, 1, 2}));
  EXPECT_EQ(polygon(r.soup, 1), (Poly{3, 2, 1, 0}));
}

TEST(IoPly, BinaryLittleEndianWithCamera) {
  TempDir dir;
  Bytes b;
  b.text("ply\n"
         "format binary_little_endian 1.0\n"
         "element camera 2\n"
         "property float view_px\n"
         "property list uchar float k\n"
         "property int viewport\n"
         "element vertex 3\n"
         "property float x\n"
         "property float y\n"
         "property float z\n"
         "property int flags\n"
         "element face 1\n"
         "property list uchar int vertex_indices\n"
         "property float quality\n"
         "element material 1\n"
         "property uchar red\n"
         "end_header\n");
  // Two camera records with lists of 2 and 0 entries.
  b.put(1.5f).put(std::uint8_t{2}).put(0.1f).put(0.2f).put(std::int32_t{640});
  b.put(2.5f).put(std::uint8_t{0}).put(std::int32_t{480});
  const float xyz[3][3] = {{0.1f, 0.2f, 0.3f}, {1, 0, 0}, {0, 1, -7.25f}};
  for (const auto& p : xyz) b.put(p[0]).put(p[1]).put(p[2]).put(std::int32_t{-1});
  b.put(std::uint8_t{3}).put(std::int32_t{2}).put(std::int32_t{0}).put(std::int32_t{1}).put(0.5f);
  b.put(std::uint8_t{200});
  const SoupFile r = read_soup(dir.write("camera.ply", b.str()));
  EXPECT_EQ(r.info.encoding, "binary_little_endian");
  EXPECT_EQ(r.info.skipped,
            (std::vector<std::string>{"element camera (2)", "element material (1)"}));
  ASSERT_EQ(r.soup.points.size(), 3u);
  EXPECT_EQ(r.soup.points[0], remora::Vec3(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(r.soup.points[2], remora::Vec3(0, 1, -7.25));
  ASSERT_EQ(r.soup.num_polygons(), 1u);
  EXPECT_EQ(polygon(r.soup, 0), (Poly{2, 0, 1}));
}

TEST(IoPly, BinaryBigEndianWithMixedTypes) {
  TempDir dir;
  Bytes b(true);
  b.text("ply\n"
         "format binary_big_endian 1.0\n"
         "element vertex 3\n"
         "property double x\n"
         "property float32 y\n"
         "property short z\n"
         "property uchar red\n"
         "element face 1\n"
         "property list ushort uint vertex_indices\n"
         "end_header\n");
  b.put(1.0 / 3).put(0.25f).put(std::int16_t{-300}).put(std::uint8_t{1});
  b.put(-2.5e-7).put(1.0f).put(std::int16_t{2}).put(std::uint8_t{2});
  b.put(4.0).put(-8.0f).put(std::int16_t{0}).put(std::uint8_t{3});
  b.put(std::uint16_t{3}).put(std::uint32_t{0}).put(std::uint32_t{1}).put(std::uint32_t{2});
  const SoupFile r = read_soup(dir.write("big.ply", b.str()));
  EXPECT_EQ(r.info.encoding, "binary_big_endian");
  ASSERT_EQ(r.soup.points.size(), 3u);
  EXPECT_EQ(r.soup.points[0], remora::Vec3(1.0 / 3, 0.25, -300));
  EXPECT_EQ(r.soup.points[1], remora::Vec3(-2.5e-7, 1, 2));
  EXPECT_EQ(r.soup.points[2], remora::Vec3(4, -8, 0));
  ASSERT_EQ(r.soup.num_polygons(), 1u);
  EXPECT_EQ(polygon(r.soup, 0), (Poly{0, 1, 2}));
}

const std::string kStripElements = "element vertex 5\n"
                                   "property float x\n"
                                   "property float y\n"
                                   "property float z\n"
                                   "element tristrips 1\n"
                                   "property list int int vertex_indices\n"
                                   "end_header\n";

// Strip [0 1 2 3] gives (0 1 2) (2 1 3); strip [0 1 2 2 3 4] gives (0 1 2), the swap triangles
// (2 1 2) and (2 2 3), then (3 2 4).
const std::vector<Poly> kStripTriangles{{0, 1, 2}, {2, 1, 3}, {0, 1, 2},
                                        {2, 1, 2}, {2, 2, 3}, {3, 2, 4}};

TEST(IoPly, TristripsAscii) {
  TempDir dir;
  const SoupFile r = read_soup(dir.write(
      "strips.ply",
      ascii_ply("0 0 0\n1 0 0\n0 1 0\n1 1 0\n2 1 0\n11 0 1 2 3 -1 0 1 2 2 3 4\n", kStripElements)));
  EXPECT_EQ(r.info.faces_in_file, 6u);
  ASSERT_EQ(r.soup.num_polygons(), 6u);
  for (std::size_t f = 0; f < 6; ++f) EXPECT_EQ(polygon(r.soup, f), kStripTriangles[f]) << f;
}

std::string binary_strips(const std::vector<std::int32_t>& list) {
  Bytes b;
  b.text("ply\nformat binary_little_endian 1.0\n" + kStripElements);
  for (int i = 0; i < 5; ++i) b.put(static_cast<float>(i)).put(0.0f).put(0.0f);
  b.put(static_cast<std::int32_t>(list.size()));
  for (const std::int32_t i : list) b.put(i);
  return b.str();
}

TEST(IoPly, TristripsBinaryWithTrailingSeparator) {
  TempDir dir;
  const SoupFile r =
      read_soup(dir.write("strips.ply", binary_strips({0, 1, 2, 3, -1, 0, 1, 2, 2, 3, 4, -1})));
  EXPECT_EQ(r.info.faces_in_file, 6u);
  ASSERT_EQ(r.soup.num_polygons(), 6u);
  for (std::size_t f = 0; f < 6; ++f) EXPECT_EQ(polygon(r.soup, f), kStripTriangles[f]) << f;

  // Only -1 separates strips; indices must name a vertex.
  const std::string good = binary_strips({0, 1, 2});
  const std::size_t list = good.size() - 12; // the first index, after the 4-byte length
  expect_error_at_byte(dir.write("minus2.ply", binary_strips({0, 1, -2})), list + 8,
                       "'tristrips' record 0 has the negative vertex index -2 (only -1");
  expect_error_at_byte(dir.write("range.ply", binary_strips({0, 5, 1})), list + 4,
                       "'tristrips' record 0 refers to vertex 5 but the file has 5 vertices");
}

TEST(IoPly, HeaderErrors) {
  TempDir dir;
  const std::string xyz = "property float x\nproperty float y\nproperty float z\n";
  const std::string face = "element face 1\nproperty list uchar int vertex_indices\n";
  expect_error_at_line(dir.write("order.ply", "ply\nformat ascii 1.0\n" + face +
                                                  "element vertex 3\n" + xyz + "end_header\n"),
                       3, "element face comes before element vertex");
  expect_error_at_line(
      dir.write("noz.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                           "property float y\n" +
                               face + "end_header\n"),
      3, "element vertex has no property 'z'");
  expect_error_at_line(dir.write("type.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"
                                             "property int64 x\n"),
                       4, "unknown property type 'int64'");
  expect_error_at_line(dir.write("format.ply", "ply\nformat binary_middle_endian 1.0\n"), 2,
                       "unknown PLY format 'binary_middle_endian'");
  expect_error_at_line(dir.write("version.ply", "ply\nformat ascii 2.0\n"), 2,
                       "unsupported format line");
  expect_error_at_line(dir.write("noend.ply", "ply\nformat ascii 1.0\nelement vertex 0\n"), 3,
                       "the header has no 'end_header' line");
  expect_error_at_line(dir.write("magic.ply", "plyx\nformat ascii 1.0\n"), 1, "not a PLY file");
  expect_error_at_line(dir.write("keyword.ply", "ply\nformat ascii 1.0\nelephant 3\n"), 3,
                       "unknown header line starting with 'elephant'");
  expect_error_at_line(dir.write("early.ply", "ply\nformat ascii 1.0\nproperty float x\n"), 3,
                       "'property' before any 'element' line");
  expect_error_at_line(dir.write("findex.ply", "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz +
                                                   "element face 1\n"
                                                   "property list uchar float vertex_indices\n"
                                                   "end_header\n"),
                       7, "must be a list of integers");
  expect_error_at_line(dir.write("fcount.ply", "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz +
                                                   "element face 1\n"
                                                   "property list float int vertex_indices\n"
                                                   "end_header\n"),
                       8, "list length type 'float' is not an integer type");
  expect_error_at_line(
      dir.write("nofmt.ply", "ply\nelement vertex 3\n" + xyz + face + "end_header\n"), 8,
      "no 'format' line");
  expect_error_at_line(dir.write("binhead.ply", "ply\nformat ascii 1.0\ncomment \x02\n"), 3,
                       "not a text file: byte 0x02");
  expect_error(dir.write("noface.ply", "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz +
                                           "end_header\n0 0 0\n1 0 0\n0 1 0\n"),
               "no faces");
  expect_error(dir.write("zero.ply", "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz +
                                         "element face 0\n"
                                         "property list uchar int vertex_indices\n"
                                         "end_header\n0 0 0\n1 0 0\n0 1 0\n"),
               "no faces");
  expect_error(dir.write("empty.ply", ""), "no faces");
}

TEST(IoPly, AsciiBodyErrors) {
  TempDir dir;
  // Header lines 1-9; vertices on lines 10-12, the face on 13.
  const std::string verts = "0 0 0\n1 0 0\n0 1 0\n";
  expect_error_at_line(dir.write("nan.ply", ascii_ply("0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n")), 11,
                       "vertex 1 has a non-finite y coordinate (NaN)");
  expect_error_at_line(dir.write("range.ply", ascii_ply(verts + "3 0 1 3\n")), 13,
                       "face 0 refers to vertex 3 but the file has 3 vertices");
  expect_error_at_line(dir.write("negative.ply", ascii_ply(verts + "3 0 -1 2\n")), 13,
                       "face 0 has the negative vertex index -1");
  expect_error_at_line(dir.write("two.ply", ascii_ply(verts + "2 0 1\n")), 13,
                       "face 0 has 2 corners");
  expect_error_at_line(
      dir.write(
          "truncated.ply",
          ascii_ply(verts + "3 0 1 2\n",
                    std::string(kPlyXyzFace).replace(kPlyXyzFace.find("face 1"), 6, "face 2"))),
      13, "header declares 2 faces but the file ends after 1");
  expect_error_at_line(dir.write("midline.ply", ascii_ply(verts + "3 0 1")), 13,
                       "the file ends in the middle of face 0 (property 'vertex_indices'");
  expect_error_at_line(dir.write("vtrunc.ply", ascii_ply("0 0 0\n1 0 0\n")), 11,
                       "header declares 3 vertices but the file ends after 2");
  expect_error_at_line(dir.write("more.ply", ascii_ply(verts + "3 0 1 2\n\n3 2 1 0\n")), 15,
                       "data continues after the 1 face the header declares");
  expect_error_at_line(
      dir.write("nul.ply", ascii_ply(std::string("0 0 0\n1 0 0\n0 1 0\0\n3 0 1 2\n", 27))), 12,
      "not a text file: byte 0x00");
  expect_error_at_line(dir.write("number.ply", ascii_ply("0 zz 0\n1 0 0\n0 1 0\n3 0 1 2\n")), 10,
                       "'zz' is not a number (property 'y' of vertex 0)");
  expect_error_at_line(dir.write("index.ply", ascii_ply(verts + "3 0 1 2.0\n")), 13,
                       "'2.0' is not an integer");
  expect_error_at_line(dir.write("few.ply", ascii_ply("0 0\n1 0 0\n0 1 0\n3 0 1 2\n")), 10,
                       "vertex 0 has too few values: property 'z' is missing");
  expect_error_at_line(dir.write("many.ply", ascii_ply("0 0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")), 10,
                       "vertex 0 has more values than its 3 properties");
  expect_error_at_line(dir.write("strip.ply", ascii_ply("0 0 0\n1 0 0\n0 1 0\n1 1 0\n2 1 0\n"
                                                        "5 0 1 2 -2 3\n",
                                                        kStripElements)),
                       15, "'tristrips' record 0 has the negative vertex index -2 (only -1");
  // Trailing whitespace is fine.
  EXPECT_EQ(read_soup(dir.write("ok.ply", ascii_ply(verts + "3 0 1 2\n  \n\n\t"))).soup.indices,
            (Poly{0, 1, 2}));
}

// Header + 3 float vertices + 1 triangle; the offsets the tests below point into.
struct BinaryPly {
  std::string bytes;
  std::size_t header = 0; ///< bytes before the first vertex
  std::size_t faces = 0;  ///< offset of the first face record
};

BinaryPly binary_ply(const std::array<float, 9>& xyz, const std::array<std::int32_t, 3>& tri,
                     std::uint8_t corners = 3, const std::string& extra_elements = "") {
  Bytes b;
  b.text("ply\nformat binary_little_endian 1.0\ncomment test\n" +
         kPlyXyzFace.substr(0, kPlyXyzFace.size() - 11) + extra_elements + "end_header\n");
  BinaryPly out;
  out.header = b.size();
  for (const float v : xyz) b.put(v);
  out.faces = b.size();
  b.put(corners);
  for (std::uint8_t k = 0; k < corners && k < 3; ++k) b.put(tri[k]);
  out.bytes = b.str();
  return out;
}

TEST(IoPly, BinaryBodyErrors) {
  TempDir dir;
  const std::array<float, 9> xyz{0, 0, 0, 1, 0, 0, 0, 1, 0};
  const BinaryPly good = binary_ply(xyz, {0, 1, 2});
  EXPECT_EQ(read_soup(dir.write("good.ply", good.bytes)).soup.num_polygons(), 1u);
  const std::size_t h = good.header;

  expect_error_at_byte(
      dir.write(
          "nan.ply",
          binary_ply({0, 0, 0, std::numeric_limits<float>::quiet_NaN(), 0, 0, 0, 1, 0}, {0, 1, 2})
              .bytes),
      h + 12, "vertex 1 has a non-finite x coordinate (NaN)");
  expect_error_at_byte(dir.write("inf.ply", binary_ply({0, 0, 0, 0, 0, 0, 0, 1,
                                                        std::numeric_limits<float>::infinity()},
                                                       {0, 1, 2})
                                                .bytes),
                       h + 24, "vertex 2 has a non-finite z coordinate (+infinity)");
  expect_error_at_byte(dir.write("range.ply", binary_ply(xyz, {0, 1, 7}).bytes), good.faces + 1 + 8,
                       "face 0 refers to vertex 7 but the file has 3 vertices");
  expect_error_at_byte(dir.write("negative.ply", binary_ply(xyz, {0, -5, 1}).bytes),
                       good.faces + 1 + 4, "face 0 has the negative vertex index -5");
  expect_error_at_byte(dir.write("two.ply", binary_ply(xyz, {0, 1, 2}, 2).bytes), good.faces,
                       "face 0 has 2 corners");

  // Cut inside vertex 2: the face needs at least its 1-byte corner count.
  expect_error_at_byte(dir.write("vcut.ply", good.bytes.substr(0, h + 30)), h + 24,
                       "file ends at byte " + std::to_string(h + 30) +
                           " but the header's counts need at least " + std::to_string(h + 37) +
                           " bytes (vertex 2 of 3 is cut off)");
  // Cut after the first index of the face.
  expect_error_at_byte(dir.write("fcut.ply", good.bytes.substr(0, good.faces + 5)), good.faces,
                       "file ends at byte " + std::to_string(good.faces + 5) +
                           " but the header's counts need at least " +
                           std::to_string(good.faces + 9) + " bytes (face 0 of 1 is cut off)");
  // A fixed-size element last: the count is exact.
  const BinaryPly cam = binary_ply(xyz, {0, 1, 2}, 3, "element camera 2\nproperty double f\n");
  const std::string cam_bytes = cam.bytes + std::string(12, '\0');
  expect_error_at_byte(
      dir.write("ccut.ply", cam_bytes), cam.faces + 13 + 8,
      "file ends at byte " + std::to_string(cam_bytes.size()) + " but the header's counts need " +
          std::to_string(cam.bytes.size() + 16) + " bytes ('camera' record 1 of 2 is cut off)");
  expect_error_at_byte(dir.write("more.ply", good.bytes + "abcd"), good.bytes.size(),
                       "data continues after the 1 face the header declares (4 extra bytes)");
  // A count that claims far more than the file holds.
  std::string lying = good.bytes;
  lying.replace(lying.find("vertex 3"), 8, "vertex 9");
  // Vertex 3 reads the face's 13 bytes; vertex 4 is cut off.
  expect_error_at_byte(dir.write("lying.ply", lying), h + 48,
                       "but the header's counts need at least");
}

// ------------------------------------------------------------------------------------------------
// STL

std::string binary_stl(const std::string& header, const std::vector<std::array<float, 9>>& tris,
                       std::optional<std::uint32_t> count = {}) {
  Bytes b;
  std::string h = header;
  h.resize(80, '\0');
  b.text(h).put(count.value_or(static_cast<std::uint32_t>(tris.size())));
  for (const auto& t : tris) {
    b.put(0.0f).put(0.0f).put(1.0f);
    for (const float v : t) b.put(v);
    b.put(std::uint16_t{0});
  }
  return b.str();
}

TEST(IoStl, BinaryBeginningWithSolid) {
  TempDir dir;
  const SoupFile r = read_soup(dir.write(
      "solid.stl", binary_stl("solid but binary", {{0, 0, 0, 1, 0, 0, 0, 1, 0},
                                                   {0.1f, 0.2f, 0.3f, 1, 1, 1, -1, -2, -3e-5f}})));
  EXPECT_EQ(r.info.format, "stl");
  EXPECT_EQ(r.info.encoding, "binary_little_endian");
  EXPECT_EQ(r.info.vertices_in_file, 6u);
  EXPECT_EQ(r.info.faces_in_file, 2u);
  ASSERT_EQ(r.soup.points.size(), 6u);
  EXPECT_EQ(r.soup.points[3], remora::Vec3(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(r.soup.points[5], remora::Vec3(-1, -2, -3e-5f));
  ASSERT_EQ(r.soup.num_polygons(), 2u);
  EXPECT_EQ(polygon(r.soup, 1), (Poly{3, 4, 5}));
}

TEST(IoStl, AsciiSeveralSolidsAndPolygonLoops) {
  TempDir dir;
  const SoupFile r = read_soup(dir.write("two.STL", "  solid one\r\n"
                                                    "  facet normal 0 0 1\r\n"
                                                    "    outer loop\r\n"
                                                    "      vertex 0 0 0\r\n"
                                                    "      vertex 1 0 0\r\n"
                                                    "      vertex 0 1 +2.5e-1\r\n"
                                                    "    endloop\r\n"
                                                    "  endfacet\r\n"
                                                    "endsolid one\r\n"
                                                    "SOLID two\n"
                                                    " FACET NORMAL 0 0 0\n"
                                                    "  OUTER LOOP\n"
                                                    "   VERTEX 0 0 1\n"
                                                    "   VERTEX 1 0 1\n"
                                                    "   VERTEX 1 1 1\n"
                                                    "   VERTEX 0 1 1\n"
                                                    "  ENDLOOP\n"
                                                    " ENDFACET\n"
                                                    "ENDSOLID\n\n"));
  EXPECT_EQ(r.info.encoding, "ascii");
  EXPECT_EQ(r.info.vertices_in_file, 7u);
  EXPECT_EQ(r.info.faces_in_file, 2u);
  ASSERT_EQ(r.soup.points.size(), 7u);
  EXPECT_EQ(r.soup.points[2], remora::Vec3(0, 1, 0.25));
  ASSERT_EQ(r.soup.num_polygons(), 2u);
  EXPECT_EQ(polygon(r.soup, 0), (Poly{0, 1, 2}));
  EXPECT_EQ(polygon(r.soup, 1), (Poly{3, 4, 5, 6}));
}

// Text editors on Windows start a file with a UTF-8 byte-order mark; every text reader skips it.
TEST(IoStl, AsciiWithAByteOrderMark) {
  const std::string facet = "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                            "vertex 0 1 0\nendloop\nendfacet\nendsolid s\n";
  for (const std::string& bytes : {"\xEF\xBB\xBF" + facet, "\xEF\xBB\xBF\n  " + facet}) {
    const SoupFile r = remora::read_soup_from_memory(bytes, MeshFormat::Stl, "bom.stl");
    EXPECT_EQ(r.info.encoding, "ascii");
    EXPECT_EQ(r.soup.num_polygons(), 1u);
  }
}

TEST(IoStl, Errors) {
  TempDir dir;
  const std::array<float, 9> tri{0, 0, 0, 1, 0, 0, 0, 1, 0};
  expect_error_at_byte(dir.write("size.stl", binary_stl("binary", {tri, tri}) + "xyz"), 80,
                       "binary STL header declares 2 triangles (84+50*2 = 184 bytes) but the "
                       "file has 187 bytes");
  expect_error_at_byte(dir.write("lying.stl", binary_stl("binary", {tri}, 1000)), 80,
                       "declares 1000 triangles");
  expect_error_at_byte(dir.write("cut.stl", binary_stl("solid looks ascii", {tri, tri}, 3)), 80,
                       "declares 3 triangles (84+50*3 = 234 bytes) but the file has 184 bytes "
                       "(it begins with 'solid' but is not text");
  expect_error(dir.write("short.stl", "abc"), "too short for a binary STL");
  expect_error(dir.write("empty.stl", ""), "no faces");
  expect_error_at_byte(dir.write("zero.stl", binary_stl("binary", {})), 80, "no faces");
  expect_error_at_byte(
      dir.write("nan.stl", binary_stl("b", {tri, {0, 0, 0, 1, 0, 0, 0, std::nanf(""), 0}})),
      84 + 50 + 12 + 24, "triangle 1 (vertex 2) has a non-finite y coordinate (NaN)");

  const std::string start = "solid s\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n";
  const std::string end = "   vertex 1 0 0\n   vertex 0 1 0\n  endloop\n endfacet\n";
  expect_error_at_line(dir.write("cut.stl", start + "   vertex 1 0 0\n"), 5,
                       "the file ends inside a facet");
  expect_error_at_line(dir.write("noend.stl", start + end), 8, "the file ends inside a solid");
  expect_error_at_line(dir.write("two.stl", start + "   vertex 1 0 0\n  endloop\n"), 6,
                       "facet loop has 2 vertices");
  expect_error_at_line(dir.write("nan.STL", start + "   vertex inf 0 0\n"), 5,
                       "vertex 1 has a non-finite x coordinate (+infinity)");
  expect_error_at_line(dir.write("number.stl", start + "   vertex 1 x1 0\n"), 5,
                       "'x1' is not a number");
  expect_error_at_line(dir.write("order.stl", "solid s\n facet normal 0 0 1\n  vertex 0 0 0\n"), 3,
                       "expected 'outer loop' but found 'vertex'");
  expect_error_at_line(dir.write("after.stl", start + end + "endsolid s\ngarbage\n"), 10,
                       "data continues after 'endsolid'");
  expect_error_at_line(dir.write("nul.stl", start + std::string("\0", 1) + end), 5,
                       "not a text file: byte 0x00");
  expect_error(dir.write("nofacet.stl", "solid s\nendsolid s\n"), "no faces");
}

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

// ------------------------------------------------------------------------------------------------
// The real meshes of ../shared/data (MANIFEST.md)

fs::path shared_data() {
  if (const char* env = std::getenv("REMORA_DATA")) return env;
  return REMORA_SHARED_DATA;
}

struct DataFile {
  std::string encoding;
  std::size_t vertices;       ///< in the file (STL: 3 per triangle)
  std::size_t faces;          ///< in the file (tristrips: triangles the strips encode)
  std::size_t referenced = 0; ///< vertices some face uses, when checked
};

const std::map<std::string, DataFile>& known_data() {
  static const std::map<std::string, DataFile> files{
      {"cad/conrod.stl", {"binary_little_endian", 19326, 6442}},
      {"cad/fandisk.obj", {"ascii", 6475, 12946, 6475}},
      {"cad/featuretype.STL", {"binary_little_endian", 10428, 3476}},
      {"cad/gears.stl", {"ascii", 58278, 19426}},
      {"genus/fertility.off", {"ascii", 4494, 9000, 4494}},
      {"heightfield/AcrossRiver.stl", {"ascii", 61560, 20520}},
      {"open/camelhead.off", {"ascii", 11381, 22704, 11381}},
      {"scans/bunny.ply", {"ascii", 35947, 69451, 34834}},
      {"scans/lucy.ply", {"binary_little_endian", 49987, 99970, 49987}},
      {"cad/blade.off", {"ascii", 8231, 16222, 8231}},
      {"open/lato000.ply", {"binary_little_endian", 44461, 86766, 44269}},
      {"scans/armadillo.obj", {"ascii", 43243, 86482, 43243}},
      {"scans/decimated-max.obj", {"ascii", 5272, 10540, 5272}},
      {"scans/igea.ply", {"binary_little_endian", 134345, 268686, 134345}},
      {"derived/igea_sub4.ply", {"binary_little_endian", 537374, 1074744, 537374}},
  };
  return files;
}

std::vector<std::string> manifest_paths(const fs::path& manifest) {
  std::ifstream in(manifest);
  std::vector<std::string> paths;
  std::string line;
  while (std::getline(in, line)) {
    if (!line.starts_with("| `")) continue;
    const std::size_t end = line.find('`', 3);
    if (end != std::string::npos) paths.push_back(line.substr(3, end - 3));
  }
  return paths;
}

TEST(IoSharedData, EveryManifestMeshReadsWithItsCounts) {
  const fs::path data = shared_data();
  if (!fs::exists(data / "MANIFEST.md"))
    GTEST_SKIP() << "no shared data at " << data << " (set REMORA_DATA to its folder)";
  const std::vector<std::string> paths = manifest_paths(data / "MANIFEST.md");
  EXPECT_GE(paths.size(), 15u);
  for (const std::string& rel : paths) {
    SCOPED_TRACE(rel);
    const auto known = known_data().find(rel);
    ASSERT_NE(known, known_data().end()) << "add the counts of " << rel << " to this test";
    const SoupFile r = read_soup((data / rel).string());
    const DataFile& want = known->second;
    EXPECT_EQ(r.info.encoding, want.encoding);
    EXPECT_EQ(r.info.vertices_in_file, want.vertices);
    EXPECT_EQ(r.soup.points.size(), want.vertices);
    EXPECT_EQ(r.info.faces_in_file, want.faces);
    EXPECT_EQ(r.soup.num_polygons(), want.faces);
    if (want.referenced != 0) {
      std::vector<bool> used(r.soup.points.size(), false);
      for (const std::uint32_t i : r.soup.indices) used[i] = true;
      EXPECT_EQ(static_cast<std::size_t>(std::count(used.begin(), used.end(), true)),
                want.referenced);
    }
  }
}

TEST(IoSharedData, LatoSkipsItsCamera) {
  const fs::path path = shared_data() / "open/lato000.ply";
  if (!fs::exists(path)) GTEST_SKIP() << "no " << path;
  EXPECT_EQ(read_soup(path.string()).info.skipped, std::vector<std::string>{"element camera (1)"});
}

TEST(IoSharedData, IgeaStripsEncodeTheWholeSurface) {
  const fs::path path = shared_data() / "scans/igea.ply";
  if (!fs::exists(path)) GTEST_SKIP() << "no " << path;
  const SoupFile r = read_soup(path.string());
  std::size_t proper = 0;
  for (std::size_t f = 0; f < r.soup.num_polygons(); ++f) {
    const Poly t = polygon(r.soup, f);
    ASSERT_EQ(t.size(), 3u);
    proper += (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) ? 1 : 0;
  }
  EXPECT_EQ(proper, 268686u);
}

} // namespace
