// Remora's exceptions. Every message names the problem and, where it can, what to do about it.
// Apps catch remora::Error at their boundary: the CLI prints one line and exits non-zero, the
// server answers 4xx with a JSON body.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

namespace remora {

/// Base of every exception Remora throws on purpose.
class Error : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

/// The caller passed something unusable (an empty selection, an out-of-range id, a NaN).
class InvalidArgument : public Error {
public:
  using Error::Error;
};

/// A numerical method failed: a factorization met a non-positive pivot, an iteration did not
/// converge. what() names the method and the figure (pivot, iterations, residual).
class NumericalError : public Error {
public:
  using Error::Error;
};

/// The caller asked a long call to stop (a std::stop_token was triggered); nothing was changed.
class Cancelled : public Error {
public:
  using Error::Error;
};

/// A file could not be read or written, or its content is malformed. what() reads
/// "<path>: line <n>: <problem>" or "<path>: byte <offset>: <problem>" when the place is known.
class IoError : public Error {
public:
  IoError(std::string path, std::string problem, std::optional<std::uint64_t> line = {},
          std::optional<std::uint64_t> byte_offset = {});

  const std::string& path() const { return path_; }
  const std::string& problem() const { return problem_; }
  std::optional<std::uint64_t> line() const { return line_; }
  std::optional<std::uint64_t> byte_offset() const { return byte_offset_; }

private:
  std::string path_;
  std::string problem_;
  std::optional<std::uint64_t> line_;
  std::optional<std::uint64_t> byte_offset_;
};

} // namespace remora
