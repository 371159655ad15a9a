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

/// Keys of a changed graph on the tree of an old order, for a mesh changed in places (a local
/// bake's patch): rows are coupled when `graph` (n × n, a symmetric pattern: a mesh's cotan
/// matrix) joins them in at most k steps, the pattern of ring_pattern(graph, k); `tree` is the old
/// coupling's elimination tree by position (elimination_tree() of separator.h, in the order of
/// nested_dissection_keys(), which is a postorder), and keys[v] the old position row v stands at,
/// several rows sharing one where rows were added. Where two coupled rows stand at positions
/// neither of which is an ancestor of the other (the change crossed a separator), the row at the
/// lower position is raised to their lowest common ancestor, in one pass over the rows, after
/// which every coupled pair within one tree of the old order lies on one root path: the old
/// tree's separators then separate the new coupling again, widened by the raised rows, and
/// tree_separator() cuts at them (pairs across two trees, which a change joining two components
/// of the old graph makes, are left). Returns how many raisings it made. Throws
/// InvalidArgument when the sizes disagree, k < 1, a key is not a position of the tree, or the
/// tree is not postordered.
int raise_to_common_ancestors(const Eigen::SparseMatrix<double>& graph, int k,
                              const std::vector<int>& tree, std::vector<int>& keys);

/// The k-ring graph of a mesh as a sparse pattern: the pattern of (−W)^k for the cotan matrix
/// `minus_w` (n × n), which is that of every k-harmonic system's rows (kharmonic.h). Values are
/// not meaningful.
Eigen::SparseMatrix<double> ring_pattern(const Eigen::SparseMatrix<double>& minus_w, int k);

} // namespace remora
