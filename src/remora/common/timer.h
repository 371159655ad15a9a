// Wall-clock timing for reports: one clock and one conversion, shared by the library and the apps.
#pragma once

#include <chrono>

namespace remora {

using Clock = std::chrono::steady_clock;

/// Milliseconds of wall time elapsed since `t0` (steady clock: never negative, never jumps).
inline double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

} // namespace remora
