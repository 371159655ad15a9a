// What CHOLMOD's users (solver.cpp's one factor, split_cholesky.cpp's two halves,
// nested_dissection.cpp's order) set alike.
// Only in builds with the GPL solvers.
#pragma once

#include <cstddef>

#include <cholmod.h>

namespace remora {

/// Coarser supernodes than CHOLMOD's defaults (nrelax 4, 16, 48; zrelax 0.8, 0.1, 0.05) when
/// `coarse`: 16, 64, 256 and 0.9, 0.3, 0.1. A mesh's supernodes are small, and such a factor
/// spends its time between BLAS calls, not in them (docs/solvers.md, "The factor of a region").
inline void set_supernodes(cholmod_common& c, bool coarse) {
  const int nrelax[2][3] = {{4, 16, 48}, {16, 64, 256}};
  const double zrelax[2][3] = {{0.8, 0.1, 0.05}, {0.9, 0.3, 0.1}};
  for (int i = 0; i < 3; ++i) {
    c.nrelax[i] = static_cast<std::size_t>(nrelax[coarse][i]);
    c.zrelax[i] = zrelax[coarse][i];
  }
}

/// A column-major block of doubles (rows × cols, leading dimension rows) as CHOLMOD's dense
/// matrix, without a copy; CHOLMOD reads it as its right-hand side.
inline cholmod_dense dense_view(const double* data, std::size_t rows, std::size_t cols) {
  cholmod_dense d{};
  d.nrow = d.d = rows;
  d.ncol = cols;
  d.nzmax = rows * cols;
  d.x = const_cast<double*>(data);
  d.xtype = CHOLMOD_REAL;
  d.dtype = CHOLMOD_DOUBLE;
  return d;
}

/// A packed, sorted lower triangle in CSC (n × n, 32-bit indices) as CHOLMOD's symmetric sparse
/// matrix, without a copy; a pattern alone when `values` is null.
inline cholmod_sparse lower_view(std::size_t n, std::size_t nonzeros, int* colptr, int* rowind,
                                 double* values) {
  cholmod_sparse m{};
  m.nrow = m.ncol = n;
  m.nzmax = nonzeros;
  m.p = colptr;
  m.i = rowind;
  m.x = values;
  m.stype = -1;
  m.itype = CHOLMOD_INT;
  m.xtype = values ? CHOLMOD_REAL : CHOLMOD_PATTERN;
  m.dtype = CHOLMOD_DOUBLE;
  m.sorted = 1;
  m.packed = 1;
  return m;
}

} // namespace remora
