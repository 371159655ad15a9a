// Separators that split a symmetric system into two halves that do not couple, for the factor in
// two halves on two threads (split_cholesky.h; paper §5: the editor's k-harmonic systems).
#pragma once

#include <vector>

#include <Eigen/SparseCore>

namespace remora {

/// The rows of a symmetric pattern split in two halves and a separator: part[i] is 0 or 1 for the
/// two halves, 2 for the separator. Rows of part 0 and part 1 are never coupled.
struct Separator {
  std::vector<unsigned char> part;
  std::vector<int> keys; ///< tree_separator: the postorder of its tree, a key per row
  int separator_rows = 0;
  int rows[2] = {0, 0};
};

/// The separator level whose halves are balanced within [0.4, 0.6] of the rest and which has the
/// fewest rows, read from the lower triangle of `a` (n × n). The largest connected component is
/// cut; the others join one half whole. Empty `part` when no level balances the halves.
Separator level_separator(const Eigen::SparseMatrix<double>& a);

/// The elimination tree of `a`'s pattern (n × n, lower triangle read) with row v at
/// `position[v]` (a permutation of 0 … n − 1; Liu's algorithm with path compression): the
/// parent of each position, −1 at a root. A parent's position is above its children's.
std::vector<int> elimination_tree(const Eigen::SparseMatrix<double>& a,
                                  const std::vector<int>& position);

/// The top of the elimination tree of `a` (lower triangle read) with its rows taken by
/// increasing `keys` (one per row; ties by row), as a separator: the path from the largest
/// tree's root down its largest children until no child holds more than 60 % of the rows left.
/// Every subtree hanging from the path couples only to the path, so the subtrees (and the other
/// trees) are shared between the halves, the largest first into the smaller one. With a nested-
/// dissection order this is its top separator within `a`. Empty `part` when the halves end
/// outside [0.4, 0.6] of the rest or the tree is one chain, and for fewer than 3 rows, a
/// non-square `a` or keys that are not one per row.
Separator tree_separator(const Eigen::SparseMatrix<double>& a, const std::vector<int>& keys);

} // namespace remora
