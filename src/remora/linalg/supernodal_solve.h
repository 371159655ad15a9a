// Triangular solves with a CHOLMOD supernodal factor L (L Lᵀ = P A Pᵀ) for a few right-hand
// sides at once (split_cholesky.h's sweeps; paper §5: factor once, solve many). CHOLMOD's own
// solve calls BLAS per supernode, whose dtrsm and dgemm copy ("pack") the block before using it:
// with 3 to 7 columns that copy costs as much as the product. Here a supernode's rows of the
// right-hand sides are copied into one vector per column, and the block, read from memory once,
// is applied to them four of its columns at a time.
//
// On x86-64 the sweeps are also compiled for AVX2 with FMA and chosen at run time where the
// processor has them (SweepCode).
//
// Right-hand sides are row-interleaved: x[columns · r + c] is row r (in the factor's order) of
// column c, so that a supernode's rows gather and scatter as whole rows.
//
// Only in builds with the GPL solvers (CHOLMOD).
#pragma once

#ifdef REMORA_WITH_GPL_SOLVERS
#include <cholmod.h>

namespace remora {

/// The sweeps' machine code: the best this processor runs (on x86-64 with AVX2 and FMA, the sweeps
/// compiled for them), or the baseline instruction set's (the tests compare the two).
enum class SweepCode { Best, Baseline };

/// Whether SweepCode::Best is the AVX2 code on this processor.
bool sweeps_use_avx2();

/// L y = x in place (the forward sweep); `factor` supernodal (is_super), numerically factored.
/// Throws InvalidArgument for a factor that is not.
void supernodal_forward(const cholmod_factor& factor, double* x, int columns,
                        SweepCode code = SweepCode::Best);

/// Lᵀ y = x in place (the backward sweep); as supernodal_forward().
void supernodal_backward(const cholmod_factor& factor, double* x, int columns,
                         SweepCode code = SweepCode::Best);

} // namespace remora
#endif
