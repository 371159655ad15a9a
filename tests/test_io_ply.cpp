// PLY file reading: ASCII and binary of either byte order, extra elements and properties,
// triangle strips, and broken headers and bodies (the error names the line or the byte).
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <limits>
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

} // namespace
