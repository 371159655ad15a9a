// Helpers shared by the mesh file tests (tests/test_io_*.cpp): a temporary folder, binary
// content of either byte order, and the checks that a read fails with an IoError naming the file,
// the place in it and the problem.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <gtest/gtest.h>

#include "remora/common/error.h"
#include "remora/mesh/io.h"

namespace remora::io_testing {

namespace fs = std::filesystem;

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

inline std::optional<IoError> read_error(const std::string& path) {
  try {
    read_soup(path);
  } catch (const IoError& e) {
    return e;
  }
  return std::nullopt;
}

inline bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The file's read fails with an IoError that names the file, the line, and `phrase`.
inline void expect_error_at_line(const std::string& path, std::uint64_t line,
                                 const std::string& phrase) {
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
inline void expect_error_at_byte(const std::string& path, std::uint64_t offset,
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
inline void expect_error(const std::string& path, const std::string& phrase) {
  SCOPED_TRACE(path);
  const auto e = read_error(path);
  ASSERT_TRUE(e.has_value()) << "no IoError";
  const std::string msg = e->what();
  EXPECT_TRUE(contains(msg, fs::path(path).filename().string())) << msg;
  EXPECT_TRUE(contains(msg, phrase)) << msg << "\n  expected: " << phrase;
}

inline std::vector<std::uint32_t> polygon(const remora::PolygonSoup& soup, std::size_t f) {
  return {soup.indices.begin() + soup.offsets[f], soup.indices.begin() + soup.offsets[f + 1]};
}

using Poly = std::vector<std::uint32_t>;

} // namespace remora::io_testing
