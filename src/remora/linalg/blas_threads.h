// The BLAS's own threads, held to one while a small sparse factor or solve runs.
//
// CHOLMOD's supernodal factor calls the BLAS once per supernode; a mesh's supernodes are small,
// and OpenBLAS's pthreads then spend more time waking and spinning (sched_yield) than computing.
// Worse, an idle OpenBLAS thread spins for a while after each call and takes a core from the
// editor's own threads (assembly, Phong encoding) that run next.
//
// Contract: while at least one BlasThreadsScope is alive, in any thread, OpenBLAS's thread count
// is 1 for the whole process (OpenBLAS has one count, not one per thread). When the last scope
// ends, the count it found is put back, unless someone changed it meanwhile (the count is no
// longer 1): that change stands. Scopes may nest and overlap across threads. Nothing happens when
// the BLAS is not OpenBLAS, or is OpenBLAS's OpenMP build (whose count is per OpenMP thread);
// blas_threads_held() says whether scopes act.
#pragma once

namespace remora {

class BlasThreadsScope {
public:
  BlasThreadsScope();
  ~BlasThreadsScope();
  BlasThreadsScope(const BlasThreadsScope&) = delete;
  BlasThreadsScope& operator=(const BlasThreadsScope&) = delete;
};

/// Whether BlasThreadsScope acts in this process: the BLAS is OpenBLAS built with pthreads.
bool blas_threads_held();

} // namespace remora
