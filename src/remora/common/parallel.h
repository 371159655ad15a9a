// Data-parallel loops (OpenMP underneath). Each index must write only its own outputs; results
// are then independent of the number of threads.
#pragma once

#include <cstddef>
#include <exception>

#include <omp.h>

namespace remora {

/// Runs body(i) for i in [0, n) on `threads` threads (0 = all hardware threads). Small loops run
/// on the calling thread. Indices are handed out in chunks of 64 as threads become free, because
/// the remesher's costly items cluster (walks on curved parts) and equal halves would leave one
/// thread idle at the end of every loop.
template <class Body>
void parallel_for(std::size_t n, int threads, Body&& body) {
  const long count = static_cast<long>(n);
  const int team = threads > 0 ? threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic, 64) num_threads(team) if (team > 1 && n > 1024)
  for (long i = 0; i < count; ++i) body(static_cast<std::size_t>(i));
}

/// Runs body(i) for i in [0, n) on `threads` threads (0 = all hardware threads), each thread over
/// one contiguous range of about n / threads indices; small loops run on the calling thread. For
/// loops of equal, memory-bound items (a frame's steps), where each thread then streams through
/// its own part of the arrays and no index is handed out at run time.
template <class Body>
void parallel_for_static(std::size_t n, int threads, Body&& body) {
  const long count = static_cast<long>(n);
  const int team = threads > 0 ? threads : omp_get_max_threads();
#pragma omp parallel for schedule(static) num_threads(team) if (team > 1 && n > 1024)
  for (long i = 0; i < count; ++i) body(static_cast<std::size_t>(i));
}

/// Runs body(b) for b in [0, n) on `threads` threads (0 = all), one index at a time as threads
/// become free, however small n is: for loops over a few large blocks of work.
template <class Body>
void parallel_blocks(std::size_t n, int threads, Body&& body) {
  const long count = static_cast<long>(n);
  const int team = threads > 0 ? threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic, 1) num_threads(team) if (team > 1 && n > 1)
  for (long i = 0; i < count; ++i) body(static_cast<std::size_t>(i));
}

/// Runs body() so that the OpenMP parallel regions it opens run on one thread, for a library whose
/// regions we cannot size: body() runs as the master of an active two-thread region, and libgomp
/// runs the regions nested in it on one thread while its max-active-levels is 1 (the default;
/// OMP_MAX_ACTIVE_LEVELS, OMP_NESTED or a list in OMP_NUM_THREADS raise it, and then body() runs
/// as it is, as it does inside an active region already). The other thread waits at the region's
/// end, asleep after a short spin (all along with OMP_WAIT_POLICY=active). A BLAS built on
/// OpenMP also runs on one thread inside. What body() throws is rethrown here.
template <class Body>
void with_serial_openmp(Body&& body) {
  if (omp_get_active_level() > 0 || omp_get_max_active_levels() > 1) {
    body();
    return;
  }
  std::exception_ptr error;
#pragma omp parallel num_threads(2)
  {
#pragma omp master
    {
      try {
        body();
      } catch (...) {
        error = std::current_exception();
      }
    }
  }
  if (error) std::rethrow_exception(error);
}

} // namespace remora
