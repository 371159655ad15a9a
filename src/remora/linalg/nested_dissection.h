// A nested-dissection order of a whole mesh's system, computed once and followed by the factor of
// every region on it (paper §5: one factorization per region; docs/solvers.md).
//
// METIS orders a mesh's graph with fewer flops than minimum degree, but takes too long to run per
// region. Restricted to a region's rows, the order of the whole base stays a good one: each
// recursive separator of the base that crosses the region still separates it.
// Solver::set_order_keys() passes it to the factor.
#pragma once

#include <vector>

#include <Eigen/SparseCore>

namespace remora {

/// The position of each row in a nested-dissection order of the symmetric pattern of `a`
/// (n × n; lower triangle read; CHOLMOD's METIS, then its elimination tree's postorder): rows
/// sorted by it eliminate the separators last. Empty without the GPL solvers, or with a CHOLMOD
/// built without METIS. Throws InvalidArgument for a non-square matrix, NumericalError when METIS
/// fails (out of memory).
std::vector<int> nested_dissection_keys(const Eigen::SparseMatrix<double>& a);

/// The k-ring graph of a mesh as a sparse pattern: the pattern of (−W)^k for the cotan matrix
/// `minus_w` (n × n), which is that of every k-harmonic system's rows (kharmonic.h). Values are
/// not meaningful.
Eigen::SparseMatrix<double> ring_pattern(const Eigen::SparseMatrix<double>& minus_w, int k);

} // namespace remora
