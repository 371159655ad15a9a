// Small text helpers shared by reports and apps.
#pragma once

#include <cstddef>
#include <string>

namespace remora {

/// 12888 -> "12,888"
std::string group_thousands(std::size_t n);

} // namespace remora
