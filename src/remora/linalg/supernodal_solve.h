// Triangular solves with a CHOLMOD supernodal factor L (L Lᵀ = P A Pᵀ) for a few right-hand
// sides at once (split_cholesky.h's sweeps; paper §5: factor once, solve many). CHOLMOD's own
// solve calls BLAS per supernode, whose dtrsm and dgemm copy ("pack") the block before using it:
// with 3 to 7 columns that copy costs as much as the product. Here a supernode's rows of the
// right-hand sides are copied into one vector per column, and the block, read from memory once,
// is applied to them four of its columns at a time.
//
// The sweeps are also compiled for AVX2 with FMA, chosen at run time (common/cpu.h).
//
// Right-hand sides are row-interleaved: x[columns · r + c] is row r (in the factor's order) of
// column c, so that a supernode's rows gather and scatter as whole rows.
//
// Only in builds with the GPL solvers (CHOLMOD).
#pragma once

#ifdef REMORA_WITH_GPL_SOLVERS
#include <cholmod.h>

namespace remora {

/// L y = x in place (the forward sweep); `factor` supernodal (is_super), numerically factored.
/// Throws InvalidArgument for a factor that is not.
void supernodal_forward(const cholmod_factor& factor, double* x, int columns);

/// Lᵀ y = x in place (the backward sweep); as supernodal_forward().
void supernodal_backward(const cholmod_factor& factor, double* x, int columns);

} // namespace remora
#endif
