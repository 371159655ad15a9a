// Mesh file reading: the format from the file name, good and broken OBJ, OFF and STL files, and
// the real meshes of ../shared/data. PLY files: test_io_ply.cpp; writing: test_io_write.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
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
