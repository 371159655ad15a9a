#include "remora/linalg/blas_threads.h"

#include <mutex>

// OpenBLAS's thread count, declared weak: the BLAS is whatever Debian's alternatives chose, and
// only OpenBLAS defines these (they resolve to null otherwise, and with a static libopenblas.a,
// whose members a weak reference does not pull in).
extern "C" {
int openblas_get_num_threads() __attribute__((weak));
void openblas_set_num_threads(int) __attribute__((weak));
int openblas_get_parallel() __attribute__((weak)); // 0 sequential, 1 pthreads, 2 OpenMP
}

namespace remora {

namespace {

std::mutex scope_mutex;
int open_scopes = 0;   // guarded by scope_mutex
int saved_threads = 0; // the count before the first open scope

} // namespace

bool blas_threads_held() {
  return &openblas_get_num_threads != nullptr && &openblas_set_num_threads != nullptr &&
         &openblas_get_parallel != nullptr && openblas_get_parallel() == 1;
}

BlasThreadsScope::BlasThreadsScope() {
  if (!blas_threads_held()) return;
  const std::lock_guard lock(scope_mutex);
  if (open_scopes++ == 0) {
    saved_threads = openblas_get_num_threads();
    if (saved_threads != 1) openblas_set_num_threads(1);
  }
}

BlasThreadsScope::~BlasThreadsScope() {
  if (!blas_threads_held()) return;
  const std::lock_guard lock(scope_mutex);
  // A count changed while scopes were open (no longer 1) stands.
  if (--open_scopes == 0 && saved_threads != 1 && openblas_get_num_threads() == 1)
    openblas_set_num_threads(saved_threads);
}

} // namespace remora
