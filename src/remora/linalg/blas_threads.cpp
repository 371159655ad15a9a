#include "remora/linalg/blas_threads.h"

#include <dlfcn.h>

#include <mutex>

namespace remora {

namespace {

using GetThreads = int (*)();
using SetThreads = void (*)(int);

// OpenBLAS's entry points, looked up at run time: the BLAS is whatever Debian's alternatives
// chose, and only OpenBLAS has them.
struct OpenBlas {
  GetThreads get = nullptr;
  SetThreads set = nullptr;
  OpenBlas() {
    get = reinterpret_cast<GetThreads>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
    set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
    if (get == nullptr || set == nullptr) get = nullptr, set = nullptr;
  }
};

const OpenBlas& openblas() {
  static const OpenBlas blas;
  return blas;
}

std::mutex scope_mutex;
int open_scopes = 0;  // guarded by scope_mutex
int saved_threads = 0; // the count before the first open scope

} // namespace

BlasThreadsScope::BlasThreadsScope() {
  const OpenBlas& blas = openblas();
  if (blas.set == nullptr) return;
  const std::lock_guard lock(scope_mutex);
  if (open_scopes++ == 0) {
    saved_threads = blas.get();
    if (saved_threads != 1) blas.set(1);
  }
}

BlasThreadsScope::~BlasThreadsScope() {
  const OpenBlas& blas = openblas();
  if (blas.set == nullptr) return;
  const std::lock_guard lock(scope_mutex);
  if (--open_scopes == 0 && saved_threads != 1) blas.set(saved_threads);
}

} // namespace remora
