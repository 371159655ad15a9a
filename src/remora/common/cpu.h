// Code compiled twice, for the baseline instruction set and for AVX2 with FMA, the processor
// choosing at run time. The library is built for plain x86-64 so that it runs on any such
// processor; a hot loop that gains from AVX2 (the supernodal sweeps, linalg/supernodal_solve.h)
// also has a copy for it:
//
//   [[gnu::always_inline]] inline double kernel(...) { ... }   // the loop's body, once
//   REMORA_AVX2 double kernel_avx2(...) { return kernel(...); } // inlined, compiled for AVX2
//   double kernel_baseline(...) { return kernel(...); }
//   ... use_avx2() ? kernel_avx2(...) : kernel_baseline(...)
//
// Only the entry points carry the attribute, so no inline function of a header is compiled for
// AVX2 where the baseline one is meant, and Eigen's types keep one layout (its packets follow
// the compiler's flags, not the attribute). Elsewhere than x86-64 with GCC or clang,
// REMORA_AVX2 is empty and use_avx2() false. The two copies agree to round-off (FMA rounds
// once where the baseline rounds twice).
#pragma once

namespace remora {

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define REMORA_AVX2 [[gnu::target("avx2,fma")]]
#else
#define REMORA_AVX2
#endif

/// Whether the AVX2 copies run: the processor has AVX2 and FMA, and the baseline code was not
/// asked for (set_baseline_code(true), or REMORA_BASELINE_CODE=1 in the environment).
bool use_avx2();

/// Runs only the baseline copies from now on (true), or the best this processor runs again
/// (false): the tests compare the two.
void set_baseline_code(bool baseline);

} // namespace remora
