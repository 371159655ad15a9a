"""The Laplacian, mass matrix and k-harmonic system as scipy.sparse matrices: the identities of
Eq. 1 (W 1 = 0, symmetry, linear precision, the areas' sum) and analytic solutions of Eq. 3."""

import numpy as np
import pytest

import remora
from conftest import grid

scipy_sparse = pytest.importorskip("scipy.sparse")


def surface_area(V, F):
    return 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1).sum()


def test_cotan_laplacian_identities(bunny):
    W = remora.cotan_laplacian(bunny.V, bunny.F)
    n = len(bunny.V)
    assert scipy_sparse.issparse(W) and W.shape == (n, n)
    assert abs(W - W.T).max() == 0.0
    assert np.abs(W @ np.ones(n)).max() < 1e-9 * abs(W).max()
    M = remora.mass_matrix(bunny.V, bunny.F)
    assert M.shape == (n, n) and M.diagonal().min() >= 0
    assert M.diagonal().sum() == pytest.approx(surface_area(bunny.V, bunny.F), rel=1e-12)


def test_linear_precision_on_a_flat_grid():
    V, F = grid(8)
    # Shake the interior a little in the plane: the cotan Laplacian of a linear function is still
    # zero at interior vertices.
    rng = np.random.default_rng(3)
    interior = (V[:, 0] > 0) & (V[:, 0] < 1) & (V[:, 1] > 0) & (V[:, 1] < 1)
    V = V.copy()
    V[interior, :2] += rng.uniform(-0.02, 0.02, (interior.sum(), 2))
    W = remora.cotan_laplacian(V, F)
    f = 2.0 * V[:, 0] - 3.0 * V[:, 1] + 0.5
    assert np.abs((W @ f)[interior]).max() < 1e-12


@pytest.mark.parametrize("k", [1, 2])
@pytest.mark.parametrize("areas", ["mean", "mixed", "mixed-symmetric"])
def test_kharmonic_reproduces_linear_functions(k, areas):
    # On a plane with a linear height on the constrained vertices, Delta^k z = 0 is solved by the
    # linear height itself, whatever k and the area weights.
    V, F = grid(12)
    centre = np.linalg.norm(V[:, :2] - 0.5, axis=1)
    support = np.flatnonzero(centre < 0.4)
    handle = np.flatnonzero(centre < 0.08)
    system = remora.kharmonic_system(V, F, support, [handle], k=k, areas=areas)
    assert system.symmetric == (areas != "mixed")
    free = np.setdiff1d(support, handle)
    assert np.array_equal(system.free_vertices, free)
    assert system.matrix.shape == (len(free), len(free))
    # The constrained vertices that couple to a free one (within k rings), handles among them.
    assert system.coupling.shape == (len(free), len(system.constrained_vertices))
    assert not set(system.constrained_vertices) & set(free)
    assert set(handle) <= set(system.constrained_vertices)
    if system.symmetric:
        A = system.matrix.toarray()
        assert np.abs(A - A.T).max() < 1e-12 * np.abs(A).max()
        assert np.linalg.eigvalsh(A).min() > 0
    height = V.copy()
    height[:, 2] = 0.3 * V[:, 0] + 0.1 * V[:, 1]
    start = height.copy()
    start[free, 2] = 0.0
    solved = system.solve(start)
    assert np.abs(solved[:, 2] - height[:, 2]).max() < 1e-10


def test_kharmonic_region_errors():
    V, F = grid(6)
    with pytest.raises(ValueError, match=r"handles\[0\]: vertex 48 is not in the support"):
        remora.kharmonic_system(V, F, [8, 9, 10], [[48]])
    with pytest.raises(ValueError, match=r"handles\[1\]: vertex 9 is also in handle 0"):
        remora.kharmonic_system(V, F, [8, 9, 10], [[9], [9]])
    # Everything free and nothing constrained: singular, refused.
    with pytest.raises(ValueError, match=r"no fixed or handle vertex"):
        remora.kharmonic_system(V, F, np.arange(len(V)), [], k=1)
