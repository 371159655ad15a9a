#include "remora/common/cpu.h"

#include <atomic>
#include <cstdlib>
#include <cstring>

namespace remora {

namespace {

bool processor_has_avx2() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
  return false;
#endif
}

bool baseline_asked() {
  const char* v = std::getenv("REMORA_BASELINE_CODE");
  return v != nullptr && std::strcmp(v, "1") == 0;
}

std::atomic<bool>& baseline() {
  static std::atomic<bool> value{baseline_asked()};
  return value;
}

} // namespace

bool use_avx2() {
  static const bool has = processor_has_avx2();
  return has && !baseline().load(std::memory_order_relaxed);
}

void set_baseline_code(bool baseline_only) {
  baseline().store(baseline_only, std::memory_order_relaxed);
}

} // namespace remora
