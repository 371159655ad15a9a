// Human-readable forms of the library's reports: short aligned tables.
#pragma once

#include <ostream>
#include <string>

#include "remora/common/text.h"
#include "remora/geometry/quality.h"
#include "remora/mesh/repair.h"

namespace remora::cli {

inline std::string grouped(std::size_t n) {
  return group_thousands(n);
}

void print_load_report(std::ostream& os, const LoadReport& report);
void print_quality(std::ostream& os, const MeshQuality& quality);

} // namespace remora::cli
