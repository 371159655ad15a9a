// JSON text for output. nlohmann::json::dump() throws on a string that is not valid UTF-8, and
// such strings reach our output from outside: a file name in another encoding, a path or key a
// client sent. dump_json() writes their bad bytes as U+FFFD instead, so that a report or an error
// answer is always written.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace remora {

/// `j` as JSON text (indented by `indent` spaces per level, or on one line for -1), with every
/// byte of a string that is not valid UTF-8 replaced by U+FFFD. Never throws for bad UTF-8.
std::string dump_json(const nlohmann::json& j, int indent = -1);

} // namespace remora
