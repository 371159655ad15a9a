// Format dispatch, whole-file reading, atomic writing, and the text helpers the parsers share.
#include "remora/mesh/io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <system_error>

#include "remora/common/error.h"
#include "remora/mesh/io_detail.h"

namespace remora {

namespace io_detail {

std::size_t find_control_byte(std::string_view text) {
  const auto* p = reinterpret_cast<const unsigned char*>(text.data());
  const std::size_t n = text.size();
  for (std::size_t i = 0; i < n; ++i) {
    const unsigned char c = p[i];
    if (c >= 0x20 && c != 0x7f) continue;
    if (c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r') continue;
    return i;
  }
  return std::string_view::npos;
}

void check_text(std::string_view text, const std::string& name, std::uint64_t first_line,
                std::uint64_t first_offset) {
  const std::size_t i = find_control_byte(text);
  if (i == std::string_view::npos) return;
  const auto line =
      first_line + static_cast<std::uint64_t>(std::count(text.begin(), text.begin() + i, '\n'));
  char hex[8];
  std::snprintf(hex, sizeof hex, "0x%02x",
                static_cast<unsigned>(static_cast<unsigned char>(text[i])));
  throw IoError(name,
                std::string("not a text file: byte ") + hex + " at offset " +
                    std::to_string(first_offset + i),
                line);
}

bool LineReader::next(std::string_view& line) {
  if (pos_ >= text_.size()) return false;
  const std::size_t end = text_.find('\n', pos_);
  const std::size_t stop = end == std::string_view::npos ? text_.size() : end;
  line = text_.substr(pos_, stop - pos_);
  pos_ = end == std::string_view::npos ? text_.size() : end + 1;
  ++line_;
  return true;
}

bool LineReader::only_blank_left() const {
  for (std::size_t i = pos_; i < text_.size(); ++i)
    if (!is_blank(text_[i]) && text_[i] != '\n') return false;
  return true;
}

std::string_view strip_comment(std::string_view line) {
  const std::size_t hash = line.find('#');
  if (hash != std::string_view::npos) line = line.substr(0, hash);
  while (!line.empty() && is_blank(line.front())) line.remove_prefix(1);
  while (!line.empty() && is_blank(line.back())) line.remove_suffix(1);
  return line;
}

namespace {

enum class ParseStatus { Ok, Bad, Range };

ParseStatus parse_double_status(std::string_view token, double& out) {
  // from_chars rejects a leading '+', which some writers emit ("+1.5e+00").
  if (!token.empty() && token.front() == '+') {
    token.remove_prefix(1);
    if (!token.empty() && (token.front() == '+' || token.front() == '-')) return ParseStatus::Bad;
  }
  if (token.empty()) return ParseStatus::Bad;
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, out);
  if (ptr != end) return ParseStatus::Bad;
  if (ec == std::errc()) return ParseStatus::Ok;
  return ec == std::errc::result_out_of_range ? ParseStatus::Range : ParseStatus::Bad;
}

} // namespace

bool parse_double(std::string_view token, double& out) {
  return parse_double_status(token, out) == ParseStatus::Ok;
}

bool parse_int(std::string_view token, std::int64_t& out) {
  if (!token.empty() && token.front() == '+') {
    token.remove_prefix(1);
    if (!token.empty() && (token.front() == '+' || token.front() == '-')) return false;
  }
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, out);
  return ec == std::errc() && ptr == end;
}

double to_double(std::string_view token, const std::string& name, std::uint64_t line,
                 std::string_view what) {
  double v = 0;
  switch (parse_double_status(token, v)) {
  case ParseStatus::Ok:
    return v;
  case ParseStatus::Range:
    throw IoError(name,
                  "'" + std::string(token) + "' is out of the range of a double (" +
                      std::string(what) + ")",
                  line);
  case ParseStatus::Bad:
    break;
  }
  if (token.empty()) throw IoError(name, "missing number (" + std::string(what) + ")", line);
  throw IoError(name, "'" + std::string(token) + "' is not a number (" + std::string(what) + ")",
                line);
}

std::int64_t to_int(std::string_view token, const std::string& name, std::uint64_t line,
                    std::string_view what) {
  std::int64_t v = 0;
  if (parse_int(token, v)) return v;
  if (token.empty()) throw IoError(name, "missing integer (" + std::string(what) + ")", line);
  throw IoError(name, "'" + std::string(token) + "' is not an integer (" + std::string(what) + ")",
                line);
}

std::string non_finite_problem(const Vec3& p, const std::string& what) {
  static constexpr const char* axis[3] = {"x", "y", "z"};
  int k = 0;
  while (k < 2 && std::isfinite(p[k])) ++k;
  const double c = p[k];
  const char* value = std::isnan(c) ? "NaN" : (c > 0 ? "+infinity" : "-infinity");
  return what + " has a non-finite " + axis[k] + " coordinate (" + value + ")";
}

void throw_non_finite(const Vec3& p, const std::string& what, const std::string& name,
                      std::optional<std::uint64_t> line, std::optional<std::uint64_t> byte_offset) {
  throw IoError(name, non_finite_problem(p, what), line, byte_offset);
}

Vec3 parse_point(std::string_view& rest, std::size_t vertex, const std::string& name,
                 std::uint64_t line) {
  static constexpr const char* what[3] = {"x coordinate", "y coordinate", "z coordinate"};
  Vec3 p;
  for (int k = 0; k < 3; ++k) {
    const std::string_view token = next_token(rest);
    if (token.empty())
      throw IoError(name,
                    "vertex " + std::to_string(vertex) + " has " + std::to_string(k) +
                        " coordinate" + plural(static_cast<std::uint64_t>(k)) +
                        " but needs x, y and z",
                    line);
    if (!parse_double(token, p[k])) to_double(token, name, line, what[k]);
  }
  if (!is_finite(p)) throw_non_finite(p, "vertex " + std::to_string(vertex), name, line, {});
  return p;
}

void append_double(std::string& out, double v) {
  char buf[32];
  const auto res = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 17);
  out.append(buf, res.ptr);
}

void append_uint(std::string& out, std::uint64_t v) {
  char buf[24];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, res.ptr);
}

void append_point_line(std::string& out, const char* prefix, const Vec3& p) {
  out += prefix;
  append_double(out, p[0]);
  out += ' ';
  append_double(out, p[1]);
  out += ' ';
  append_double(out, p[2]);
  out += '\n';
}

void append_triangle_line(std::string& out, const char* prefix, const std::uint32_t* ids,
                          std::uint64_t base) {
  out += prefix;
  for (int k = 0; k < 3; ++k) {
    out += ' ';
    append_uint(out, std::uint64_t{ids[k]} + base);
  }
  out += '\n';
}

void SkipCounter::add(std::string_view keyword) {
  for (auto& [key, count] : counts_) {
    if (key == keyword) {
      ++count;
      return;
    }
  }
  counts_.emplace_back(std::string(keyword), 1);
}

void SkipCounter::report(std::vector<std::string>& out) const {
  for (const auto& [key, count] : counts_)
    out.push_back(std::to_string(count) + " '" + key + "' line" + plural(count));
}

void check_limit(std::uint64_t count, std::uint64_t limit, const std::string& what,
                 const char* unit, const std::string& name, std::optional<std::uint64_t> line,
                 std::optional<std::uint64_t> byte) {
  if (limit == 0 || count <= limit) return;
  throw IoError(name,
                what + ": over the limit of " + std::to_string(limit) + " " + unit +
                    " this program accepts (the memory the editor needs for it; raise it with "
                    "--max-triangles)",
                line, byte);
}

CompactMesh compact(const Mesh& mesh) {
  CompactMesh out;
  std::vector<std::uint32_t> id(mesh.n_vertices(), 0);
  out.points.reserve(mesh.n_vertices());
  for (const VertexHandle v : mesh.vertices()) {
    id[static_cast<std::size_t>(v.idx())] = static_cast<std::uint32_t>(out.points.size());
    out.points.push_back(mesh.point(v));
  }
  out.triangles.reserve(3 * mesh.n_faces());
  for (const FaceHandle f : mesh.faces())
    for (const VertexHandle v : mesh.fv_range(f))
      out.triangles.push_back(id[static_cast<std::size_t>(v.idx())]);
  return out;
}

} // namespace io_detail

namespace {

std::string errno_message(int err) {
  return std::error_code(err, std::generic_category()).message();
}

std::string read_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw IoError(path, "cannot open for reading: " + errno_message(errno));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) throw IoError(path, "cannot read: " + errno_message(errno));
  if (S_ISDIR(st.st_mode)) throw IoError(path, "cannot read: it is a folder, not a file");
  std::string bytes;
  // st_size is a hint (pipes and /proc report 0); read until end of file either way.
  bytes.resize(st.st_size > 0 ? static_cast<std::size_t>(st.st_size) : 65536);
  std::size_t used = 0;
  for (;;) {
    if (used == bytes.size()) bytes.resize(bytes.size() * 2);
    const ssize_t got = ::read(fd, bytes.data() + used, bytes.size() - used);
    if (got < 0) {
      if (errno == EINTR) continue;
      throw IoError(path, "cannot read: " + errno_message(errno), {}, used);
    }
    if (got == 0) break;
    used += static_cast<std::size_t>(got);
  }
  bytes.resize(used);
  return bytes;
}

std::string temporary_name(const std::filesystem::path& target) {
  static std::atomic<unsigned long> counter{0};
  // Built by appending: GCC 12 gives a false -Wrestrict on `"." + std::string`.
  std::string name(1, '.');
  name += target.filename().string();
  name += ".tmp-";
  name += std::to_string(::getpid());
  name += '-';
  name += std::to_string(counter.fetch_add(1));
  return name;
}

// Writes `bytes` to `tmp`, flushed to disk, then renames it over `path`; removes `tmp` on failure.
void write_atomically(const std::string& path, const std::filesystem::path& tmp,
                      std::string_view bytes) {
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0)
    throw IoError(path,
                  "cannot create temporary file '" + tmp.string() + "': " + errno_message(errno));
  const auto fail = [&](const std::string& what, int err, bool close_fd) {
    if (close_fd) ::close(fd);
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw IoError(path, what + ": " + errno_message(err));
  };
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t put = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (put < 0) {
      if (errno == EINTR) continue;
      fail("cannot write after " + std::to_string(done) + " bytes", errno, true);
    }
    done += static_cast<std::size_t>(put);
  }
  // Without fsync a crash after the rename can leave an empty file in place of the old one.
  if (::fsync(fd) != 0 && errno != EINVAL) fail("cannot flush to disk", errno, true);
  if (::close(fd) != 0) fail("cannot close", errno, false);
  std::error_code ec;
  std::filesystem::rename(tmp, std::filesystem::path(path), ec);
  if (ec) fail("cannot rename the temporary file over the target", ec.value(), false);
}

} // namespace

MeshFormat format_from_path(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](char c) {
    return static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
  });
  if (ext == ".obj") return MeshFormat::Obj;
  if (ext == ".off") return MeshFormat::Off;
  if (ext == ".ply") return MeshFormat::Ply;
  if (ext == ".stl") return MeshFormat::Stl;
  const std::string supported = "supported: .obj .off .ply .stl, in any letter case";
  if (ext.empty()) throw IoError(path, "no file extension to tell the format (" + supported + ")");
  throw IoError(path, "unknown extension '" + std::filesystem::path(path).extension().string() +
                          "' (" + supported + ")");
}

SoupFile read_soup(const std::string& path, const ReadLimits& limits) {
  const MeshFormat format = format_from_path(path);
  const std::string bytes = read_file(path);
  return read_soup_from_memory(bytes, format, path, limits);
}

namespace {

SoupFile read_format(std::string_view bytes, MeshFormat format, const std::string& name,
                     const ReadLimits& limits) {
  switch (format) {
  case MeshFormat::Obj:
    return io_detail::read_obj(bytes, name, limits);
  case MeshFormat::Off:
    return io_detail::read_off(bytes, name, limits);
  case MeshFormat::Ply:
    return io_detail::read_ply(bytes, name, limits);
  case MeshFormat::Stl:
    return io_detail::read_stl(bytes, name, limits);
  }
  throw IoError(name, "unknown mesh format");
}

} // namespace

SoupFile read_soup_from_memory(std::string_view bytes, MeshFormat format, const std::string& name,
                               const ReadLimits& limits) {
  SoupFile file = read_format(bytes, format, name, limits);
  // The triangles polygons and strips make, before the repair allocates for them.
  std::uint64_t triangles = 0;
  for (std::size_t f = 0; f < file.soup.num_polygons(); ++f)
    if (file.soup.polygon_size(f) > 2) triangles += file.soup.polygon_size(f) - 2;
  io_detail::check_limit(triangles, limits.max_triangles,
                         "the faces make " + std::to_string(triangles) + " triangles", "triangles",
                         name);
  return file;
}

std::string write_mesh_to_memory(const Mesh& mesh, MeshFormat format, const std::string& name,
                                 const WriteOptions& options) {
  const io_detail::CompactMesh m = io_detail::compact(mesh);
  // A coordinate our readers reject must not reach a file.
  for (std::size_t i = 0; i < m.points.size(); ++i)
    if (!io_detail::is_finite(m.points[i]))
      throw IoError(name,
                    io_detail::non_finite_problem(m.points[i], "vertex " + std::to_string(i)) +
                        "; nothing was written");
  std::string bytes;
  switch (format) {
  case MeshFormat::Obj:
    io_detail::write_obj(m, bytes);
    break;
  case MeshFormat::Off:
    io_detail::write_off(m, bytes);
    break;
  case MeshFormat::Ply:
    io_detail::write_ply(m, options.binary, bytes);
    break;
  case MeshFormat::Stl:
    io_detail::write_stl(m, options.binary, bytes);
    break;
  }
  return bytes;
}

void write_mesh(const std::string& path, const Mesh& mesh, const WriteOptions& options) {
  namespace fs = std::filesystem;
  // Everything that can be checked before touching the disk is checked first.
  const MeshFormat format = format_from_path(path);
  const fs::path target(path);
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw IoError(path, "cannot write: '" + dir.string() + "' is not an existing folder");
  const std::string bytes = write_mesh_to_memory(mesh, format, path, options);
  write_atomically(path, dir / temporary_name(target), bytes);
}

} // namespace remora
