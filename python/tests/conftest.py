"""Shared fixtures of the Python tests. ctest runs them with PYTHONPATH=build/python and sets
REMORA_CLI (the `remora` binary), REMORA_SOURCE_DIR and REMORA_BUILD_DIR
(python/CMakeLists.txt); run by hand:

    PYTHONPATH=build/python REMORA_CLI=build/bin/remora /usr/bin/python3 -m pytest python/tests
"""

import os
import pathlib

import numpy as np
import pytest

import remora

SOURCE_DIR = pathlib.Path(
    os.environ.get("REMORA_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2])
)
BUNNY = SOURCE_DIR / "data" / "bunny.ply"

# The demo's ear edit (Makefile, `make demo`): support and handle spheres on the left ear.
EAR_SUPPORT = ((-0.03, 0.15, 0.0), 0.05)
EAR_HANDLE = ((-0.03, 0.17, 0.0), 0.015)


@pytest.fixture(scope="session")
def bunny():
    """The bundled bunny as read by remora.read_mesh: MeshData(V, F, report)."""
    return remora.read_mesh(BUNNY)


@pytest.fixture(scope="session")
def cli():
    """The path of the `remora` command-line tool."""
    path = os.environ.get("REMORA_CLI")
    if not path or not os.path.exists(path):
        pytest.skip("REMORA_CLI is not set to the remora binary (ctest sets it)")
    return path


def grid(n: int = 12, size: float = 1.0):
    """A flat (n+1) x (n+1) grid in the z = 0 plane, each square split into two triangles."""
    xs = np.linspace(0.0, size, n + 1)
    X, Y = np.meshgrid(xs, xs, indexing="xy")
    V = np.column_stack([X.ravel(), Y.ravel(), np.zeros(X.size)])
    ids = np.arange((n + 1) * (n + 1)).reshape(n + 1, n + 1)
    a, b = ids[:-1, :-1].ravel(), ids[:-1, 1:].ravel()
    c, d = ids[1:, 1:].ravel(), ids[1:, :-1].ravel()
    F = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    return V, F


def octahedron():
    """A closed octahedron with outward-facing triangles."""
    V = np.array(
        [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=np.float64
    )
    F = np.array(
        [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]]
    )
    return V, F
