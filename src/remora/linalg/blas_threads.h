// The BLAS's own threads, held to one while a sparse factor or solve runs.
//
// CHOLMOD's supernodal factor calls the BLAS once per supernode; a mesh's supernodes are small,
// and OpenBLAS's pthreads then spend more time waking and spinning (sched_yield) than computing.
// Worse, an idle OpenBLAS thread spins for a while after each call and takes a core from the
// editor's own threads (assembly, Phong encoding) that run next. BlasThreadsScope sets OpenBLAS to
// one thread for its lifetime and restores the count after the last scope ends (scopes may nest
// and overlap across threads). With a BLAS that is not OpenBLAS it does nothing.
#pragma once

namespace remora {

class BlasThreadsScope {
public:
  BlasThreadsScope();
  ~BlasThreadsScope();
  BlasThreadsScope(const BlasThreadsScope&) = delete;
  BlasThreadsScope& operator=(const BlasThreadsScope&) = delete;
};

} // namespace remora
