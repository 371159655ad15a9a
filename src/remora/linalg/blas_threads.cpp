#include "remora/linalg/blas_threads.h"

#include <mutex>

// OpenBLAS's thread count, declared weak: the BLAS is whatever Debian's alternatives chose, and
// only OpenBLAS defines these (they resolve to null otherwise). Weak references resolve in the
// linking object's own scope too, so they work in the Python module, which Python loads with
// RTLD_LOCAL (a dlsym(RTLD_DEFAULT) lookup would not find them there).
extern "C" {
int openblas_get_num_threads() __attribute__((weak));
void openblas_set_num_threads(int) __attribute__((weak));
}

namespace remora {

namespace {

bool have_openblas() {
  return &openblas_get_num_threads != nullptr && &openblas_set_num_threads != nullptr;
}

std::mutex scope_mutex;
int open_scopes = 0;   // guarded by scope_mutex
int saved_threads = 0; // the count before the first open scope

} // namespace

BlasThreadsScope::BlasThreadsScope() {
  if (!have_openblas()) return;
  const std::lock_guard lock(scope_mutex);
  if (open_scopes++ == 0) {
    saved_threads = openblas_get_num_threads();
    if (saved_threads != 1) openblas_set_num_threads(1);
  }
}

BlasThreadsScope::~BlasThreadsScope() {
  if (!have_openblas()) return;
  const std::lock_guard lock(scope_mutex);
  if (--open_scopes == 0 && saved_threads != 1) openblas_set_num_threads(saved_threads);
}

} // namespace remora
