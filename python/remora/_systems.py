"""The Laplacian, the mass matrix and the k-harmonic system (paper Eq. 1-3, section 5) as
scipy.sparse matrices. scipy is imported by these functions only."""

from typing import NamedTuple

import numpy as np

from . import _remora


def _csc(arrays):
    import scipy.sparse

    data, indices, indptr, shape = arrays
    return scipy.sparse.csc_matrix((data, indices, indptr), shape=shape)


def cotan_laplacian(V, F):
    """The cotan weight matrix W of Eq. 1, (n, n) scipy.sparse.csc_matrix, symmetric.

    W_ij = (cot alpha_ij + cot beta_ij) / 2 for every edge ij, W_ii = -sum_j W_ij, so W 1 = 0
    and W is negative semi-definite where all weights are >= 0 (Delaunay meshes). The Laplace-
    Beltrami operator is Delta = M^-1 W with M = :func:`mass_matrix` (Meyer et al. 2003);
    Delta x = -2 H n on a surface. Degenerate faces contribute nothing; no entry is NaN.
    """
    return _csc(_remora.cotan_laplacian(V, F))


def mass_matrix(V, F):
    """The lumped mass matrix M = diag(A), (n, n) scipy.sparse, A the mixed Voronoi vertex areas
    (Meyer et al. 2003) in the mesh's units squared; they sum to the surface area."""
    import scipy.sparse

    return scipy.sparse.diags(_remora.mixed_areas(V, F), format="csc")


class KHarmonicSystem(NamedTuple):
    """The k-harmonic system of a region: ``matrix @ x_free = -coupling @ x_constrained``.

    matrix: (f, f) scipy.sparse.csc_matrix on the free vertices; coupling: (f, c) on the
    constrained ones that couple to a free one (within k rings of it). free_vertices: (f,)
    int64, row r of the system is vertex free_vertices[r]; constrained_vertices: (c,) int64,
    column c of coupling. symmetric: True
    for the "mean" and "mixed-symmetric" weights (then the matrix is positive definite).
    """

    matrix: object
    coupling: object
    free_vertices: np.ndarray
    constrained_vertices: np.ndarray
    symmetric: bool

    def solve(self, positions: np.ndarray) -> np.ndarray:
        """Positions (n, d) with the free rows replaced by the solution for the constrained
        rows' values (a scipy sparse LU solve)."""
        import scipy.sparse.linalg

        out = np.array(positions, dtype=np.float64, copy=True)
        rhs = -(self.coupling @ out[self.constrained_vertices])
        out[self.free_vertices] = scipy.sparse.linalg.splu(self.matrix).solve(rhs)
        return out


def kharmonic_system(V, F, support, handles, k: int = 2, areas: str = "mean") -> KHarmonicSystem:
    """The system Delta^k p = 0 of the paper's Eq. 3 on (V, F) for a region.

    The support's vertices (an index array or boolean mask) are free, except the handles' (a
    list of index arrays or masks, each inside the support), which are constrained with the
    rest of the mesh. Rows are those of (-1)^k S Delta^k at the free vertices (linalg/kharmonic.h):
    ``areas="mean"`` replaces every area by the mean, the paper's symmetric positive definite
    system after the area-equalizing remesh (section 5); "mixed" keeps each vertex's own area
    (unsymmetric); "mixed-symmetric" scales each row by its area (symmetric, exact). k is 1, 2
    or 3. Raises ValueError when a component with free vertices has no constrained one.
    """
    from ._editor import _handle_list

    matrix, coupling, free, constrained, symmetric = _remora.kharmonic_system(
        V, F, support, _handle_list(handles), k, areas
    )
    return KHarmonicSystem(_csc(matrix), _csc(coupling), free, constrained, symmetric)
