// Human-readable forms of the library's reports: short aligned tables.
#pragma once

#include <cstdio>
#include <ostream>
#include <string>
#include <string_view>

#include <unistd.h>

#include "remora/common/text.h"
#include "remora/geometry/quality.h"
#include "remora/mesh/repair.h"

namespace remora::cli {

inline std::string grouped(std::size_t n) {
  return group_thousands(n);
}

// A one-line progress display on stderr, only when stderr is a terminal.
class ProgressLine {
public:
  ProgressLine() : enabled_(::isatty(STDERR_FILENO) == 1) {}
  ~ProgressLine() { finish(); }
  void update(std::string_view phase, int step, int steps) {
    if (!enabled_) return;
    const int width = 30;
    const int filled = steps > 0 ? width * step / steps : width;
    std::fprintf(stderr, "\r%-15.*s [%s%s] %d/%d", static_cast<int>(phase.size()), phase.data(),
                 std::string(static_cast<std::size_t>(filled), '#').c_str(),
                 std::string(static_cast<std::size_t>(width - filled), '.').c_str(), step, steps);
    std::fflush(stderr);
    shown_ = true;
  }
  void finish() {
    if (shown_) std::fprintf(stderr, "\r%60s\r", "");
    shown_ = false;
  }

private:
  bool enabled_;
  bool shown_ = false;
};

void print_load_report(std::ostream& os, const LoadReport& report);
void print_quality(std::ostream& os, const MeshQuality& quality);

/// What the base filter's feature cap did (multires/base_surface.h), e.g. "sigma lowered at 868
/// vertices of thin parts (down to 0.00084) and on 3 small boundary loops".
std::string capped_sigma_line(std::size_t vertices, double sigma_min, std::size_t loops);

} // namespace remora::cli
