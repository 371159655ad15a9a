#include "remora/common/error.h"

namespace remora {

namespace {
std::string format_io_message(const std::string& path, const std::string& problem,
                              std::optional<std::uint64_t> line,
                              std::optional<std::uint64_t> byte_offset) {
  std::string msg = path;
  if (line)
    msg += ": line " + std::to_string(*line);
  else if (byte_offset)
    msg += ": byte " + std::to_string(*byte_offset);
  msg += ": " + problem;
  return msg;
}
} // namespace

IoError::IoError(std::string path, std::string problem, std::optional<std::uint64_t> line,
                 std::optional<std::uint64_t> byte_offset)
    : Error(format_io_message(path, problem, line, byte_offset)), path_(std::move(path)),
      problem_(std::move(problem)), line_(line), byte_offset_(byte_offset) {}

} // namespace remora
