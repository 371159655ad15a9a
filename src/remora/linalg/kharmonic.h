// The k-harmonic systems of Botsch & Kobbelt 2004, §3 (Eq. 1-3) and §5: Δ^k p = 0 at the free
// vertices of a region, with the handle and fixed vertices as boundary values.
//
// With W the cotan weights and A the mixed areas (geometry/laplacian.h), Δ = A⁻¹W. The system is
// the rows of the free vertices F of (−1)^k S Δ^k, split into the free columns (the matrix) and
// the constrained columns C (moved to the right-hand side):
//   matrix · x_F = −coupling · x_C.
// Three weightings S, Δ (AreaWeights):
//   Mixed          S = I, each vertex's own area: unsymmetric on an arbitrary mesh (paper §5, (a));
//   Mean           every area replaced by the mean Ā, S = Ā^k: the rows of (−W)^k, symmetric
//                  positive definite (the paper's choice after the area-equalizing remesh, (b));
//   MixedSymmetric S = A_F, the exact areas made symmetric by scaling each row by its own area:
//                  rows of −W (−A⁻¹W)^(k−1), i.e. −W, W A⁻¹ W, −W A⁻¹ W A⁻¹ W — symmetric and
//                  positive definite as well, with no area approximation (docs/solvers.md).
// Positive definiteness: (−W) is positive semi-definite with the constants of each connected
// component as its kernel, so every symmetric form above is positive definite on the free
// vertices exactly when every mesh component that has a free vertex also has a constrained one;
// assemble_kharmonic() checks that and throws otherwise.
//
// The mesh's own boundary: a free vertex on it keeps its row of W, which has no term across the
// boundary. For k = 1 that is the natural (zero normal derivative) boundary condition of the
// Dirichlet energy xᵀ(−W)x; for k = 2 the rows are those of the minimizer of the thin-plate
// energy xᵀ W A⁻¹ W x over the free vertices, again with natural conditions at the boundary.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include "remora/mesh/mesh.h"

namespace remora {

using SparseMatrix = Eigen::SparseMatrix<double>;

/// What each vertex of a mesh does in an edit: free (the support, solved for), fixed, or part
/// of handle j (j = 0, 1, ...). Constrained = fixed or handle.
struct Region {
  static constexpr int kFree = -1;
  static constexpr int kFixed = -2;
  std::vector<int> label; ///< one per vertex (by idx()): kFree, kFixed or a handle index >= 0

  /// All vertices fixed.
  static Region all_fixed(std::size_t n_vertices) { return {std::vector<int>(n_vertices, kFixed)}; }
  /// 1 + the largest handle index (0 without handles).
  int handle_count() const;
  std::size_t free_count() const;
};

enum class AreaWeights { Mixed, Mean, MixedSymmetric };

/// "mixed", "mean", "mixed-symmetric"; parse_area_weights() throws InvalidArgument otherwise.
std::string to_string(AreaWeights weights);
AreaWeights parse_area_weights(const std::string& name);

struct KHarmonicOptions {
  int k = 2; ///< 1 (membrane), 2 (thin plate), 3 (minimum variation of curvature)
  AreaWeights areas = AreaWeights::Mean;
};

struct KHarmonicSystem {
  SparseMatrix matrix;                   ///< free × free
  SparseMatrix coupling;                 ///< free × constrained
  std::vector<int> free_vertices;        ///< row r of the system is vertex free_vertices[r]
  std::vector<int> constrained_vertices; ///< column c of coupling is this vertex
  std::vector<int> row_of;               ///< vertex -> row, or -1 when not free
  bool symmetric = false;                ///< true for Mean and MixedSymmetric

  /// −coupling · values, for values (constrained_vertices.size() × columns) in that order.
  Eigen::MatrixXd rhs(const Eigen::MatrixXd& constrained_values) const;
  /// The constrained vertices' rows of `positions` (n_vertices × columns).
  Eigen::MatrixXd gather_constrained(const Eigen::MatrixXd& positions) const;
};

/// The parts of every region's system that depend on the mesh alone (−W, the mixed areas, the
/// vertex adjacency, the connected components), computed once: an editor keeps one for its base
/// and assembles each region's system from it (factor once, assemble many). assemble() builds
/// the free rows directly, in parallel, at a cost of the free rows' k-ring stencils plus linear
/// passes over the labels; the Mean and MixedSymmetric matrices come out symmetric bit for bit.
class KHarmonicAssembler {
public:
  /// Copies what it needs from `mesh` (which may change or go afterwards). `threads`: 0 = all.
  explicit KHarmonicAssembler(const Mesh& mesh, int threads = 0);
  /// The assembler of `mesh` from `previous`, the assembler of an earlier state of the same
  /// surface (the editor's local bake, multires/bake.h): `previous_of[v]` is the vertex of the
  /// earlier mesh that vertex v of `mesh` was (-1: a new vertex), and `changed[v]` is 1 where v is
  /// new, its point moved, or the faces around it are not the earlier ones (renumbering through
  /// previous_of aside). The columns of −W, the areas and the one-rings of the vertices with no
  /// changed vertex on their faces are copied, the others computed, each as the constructor above
  /// computes it. Equal to KHarmonicAssembler(mesh, threads) but for the order of the sums of a
  /// copied vertex's diagonal entry and area where the mesh renumbered its edges or faces (round-
  /// off). The work is the changed part plus linear passes (copies, the components). Throws
  /// InvalidArgument when the sizes disagree or an unchanged vertex has no earlier vertex; an
  /// unchanged vertex whose faces did change is not detected (the caller's contract).
  KHarmonicAssembler(const Mesh& mesh, const KHarmonicAssembler& previous,
                     const std::vector<int>& previous_of, const std::vector<char>& changed,
                     int threads = 0);

  /// The system of `region` (see the top of this file), its free vertices in vertex order.
  /// Throws InvalidArgument when the label vector does not have one entry per vertex, a label is
  /// below kFixed, k is not 1, 2 or 3, nothing is free, a handle index in [0, handle_count()) has
  /// no vertex or touches no free vertex, or a mesh component has free vertices but no
  /// constrained one (the system would be singular). The message names the offending vertex or
  /// handle.
  KHarmonicSystem assemble(const Region& region, const KHarmonicOptions& options = {}) const;

  /// Computes and keeps the rows of every vertex for `options`' k and area weighting (about 12
  /// bytes per entry: a 2-ring stencil per vertex for k = 2): later assemble() calls with the
  /// same k and weighting copy their free rows instead of multiplying them out, the same numbers
  /// bit for bit. Another k or weighting is multiplied out, and keep_rows() for it replaces the
  /// kept rows. For an editor that sets many regions on one base (Editor::prepare_regions).
  /// Throws InvalidArgument for a k other than 1, 2, 3.
  void keep_rows(const KHarmonicOptions& options);
  /// The memory of the kept rows (0 without).
  std::size_t kept_row_bytes() const;

  std::size_t vertex_count() const { return static_cast<std::size_t>(offsets_.size() - 1); }
  /// −W (column-major, symmetric).
  const SparseMatrix& minus_w() const { return minus_w_; }
  /// The mixed vertex areas (vertex_areas_mixed(), unfloored).
  const Eigen::VectorXd& areas() const { return area_; }

private:
  void areas_and_adjacency(const Mesh& mesh); // area_, inverse_area_, offsets_, adjacent_, ...
  void inverse_areas();                       // inverse_area_ from area_
  void find_components(const Mesh& mesh);     // component_, components_ from the adjacency
  void check_handles_and_components(const Region& region) const;

  SparseMatrix minus_w_;
  Eigen::VectorXd area_;                // the mixed vertex areas
  Eigen::VectorXd inverse_area_;        // 1 / mixed area, floored (see kharmonic.cpp)
  std::vector<int> offsets_, adjacent_; // the one-ring of every vertex (edges of the mesh)
  std::vector<int> component_;          // connected component of every vertex
  int components_ = 0;
  int threads_ = 0;
  struct KeptRows;                       // keep_rows() (kharmonic.cpp)
  std::shared_ptr<const KeptRows> kept_; // shared by copies: the rows depend on the mesh alone
};

/// KHarmonicAssembler(mesh).assemble(region, options): one region's system.
KHarmonicSystem assemble_kharmonic(const Mesh& mesh, const Region& region,
                                   const KHarmonicOptions& options = {});

/// The vertex positions as an n_vertices × 3 matrix (row = vertex idx), and back; set_positions
/// throws InvalidArgument unless `positions` is n_vertices × 3.
Eigen::MatrixXd positions_matrix(const Mesh& mesh);
void set_positions(Mesh& mesh, const Eigen::MatrixXd& positions);

} // namespace remora
