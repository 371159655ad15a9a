"""Meshes in and out of files, the soup repair, the quality figures, vertex selections, refinement."""

import os
from typing import NamedTuple

import numpy as np

from . import _remora


class MeshData(NamedTuple):
    """A mesh as arrays with the account of how it was made.

    V: (n, 3) float64 vertex positions. F: (m, 3) int64 zero-based vertex ids per triangle.
    report: a dict; for :func:`read_mesh` the file's account and the repair counts (docs/io.md),
    for :func:`repair` the repair counts.
    """

    V: np.ndarray
    F: np.ndarray
    report: dict


def read_mesh(path) -> MeshData:
    """Reads an OBJ, OFF, PLY or STL file and repairs it into a manifold, oriented mesh.

    The repair welds coincident vertices, triangulates polygons, drops repeated and degenerate
    triangles, orients each component and splits non-manifold edges and vertices; every change is
    counted in ``report["repair"]`` (docs/io.md). Zero-area triangles are kept.

    Returns ``MeshData(V, F, report)``. Raises OSError naming the file and the line or byte for
    an unreadable or malformed file (NaN coordinates, out-of-range indices, truncated data, an
    unknown extension, nothing to load).
    """
    V, F, report = _remora.read_mesh(os.fspath(path))
    return MeshData(V, F, report)


def write_mesh(path, V, F, binary: bool = True) -> None:
    """Writes V (n, 3) and F (m, 3) in the format of ``path``'s extension (.obj .off .ply .stl).

    PLY and STL are binary unless ``binary=False``; PLY stores doubles, text formats 17
    significant digits, so coordinates round-trip exactly (STL holds 32-bit floats only). The
    file is written atomically: on an error no file is left. Raises ValueError for bad arrays and
    OSError for the file.
    """
    _remora.write_mesh(os.fspath(path), V, F, bool(binary))


def repair(V, F, **options) -> MeshData:
    """Repairs a triangle soup as :func:`read_mesh` repairs a file's (docs/io.md).

    V: (n, 3) floats; F: (m, 3) vertex ids, which may share edges with any number of
    triangles, repeat vertices or disagree in orientation. Options: ``weld`` (True: merge
    bit-identical vertices and those within ``weld_tolerance`` (1e-10) times the bounding-box
    diagonal), ``orient`` (True: consistent orientation per component), ``outward`` (True:
    closed components face outward).

    Returns ``MeshData(V, F, report)`` with ``report["source_vertex"]``, an (n_out,) int64
    array: the input vertex each output vertex came from.
    """
    V2, F2, report, source = _remora.repair(V, F, options)
    report["source_vertex"] = source
    return MeshData(V2, F2, report)


def quality(V, F) -> dict:
    """The quality figures of ``remora info`` as a dict (docs/quality.md defines each one).

    Counts (vertices, faces, edges, boundary loops, components, genus per component), inner
    angles in degrees, valence histograms, edge lengths and vertex areas (barycentric and mixed
    Voronoi) in the mesh's units, zero-area faces and the bounding box.
    """
    return _remora.quality(V, F)


def select_sphere(V, center, radius: float) -> np.ndarray:
    """The ids of the vertices within ``radius`` of ``center`` (inclusive), increasing (int64).

    What ``remora edit --support-sphere x,y,z,r`` selects. Raises ValueError for a non-finite
    center or a negative radius.
    """
    return _remora.select_sphere(V, center, radius)


def select_box(V, lower, upper) -> np.ndarray:
    """The ids of the vertices in the axis-aligned box [lower, upper] (inclusive), increasing."""
    return _remora.select_box(V, lower, upper)


def select_geodesic_disc(V, F, seed: int, radius: float) -> np.ndarray:
    """The ids of the vertices within geodesic distance ``radius`` of vertex ``seed``.

    Distances by fast marching through the triangles (Kimmel & Sethian 1998), so a disc on a
    regular grid is round; only the seed's connected component is reached. Increasing ids.
    """
    return _remora.select_geodesic_disc(V, F, seed, radius)


def nearest_vertex(V, point) -> int:
    """The id of the vertex nearest to ``point`` (the first of equals)."""
    return _remora.nearest_vertex(V, point)


class Refined(NamedTuple):
    """A mesh refined in a region: V, F as for :class:`MeshData`; ``region`` the region's vertex
    ids after the refinement (int64, increasing: the old ones and the new); ``added`` the number
    of new vertices, numbered after the old ones."""

    V: np.ndarray
    F: np.ndarray
    region: np.ndarray
    added: int


def refine_region(V, F, region, max_length: float, max_vertices=None) -> Refined:
    """Splits the region's edges longer than ``max_length`` at their midpoints, longest first.

    What ``remora edit --refine-support`` does to a support of long CAD triangles before the
    edit (docs/editing.md, "A support of long triangles"): only the input's vertices move, so a
    long triangle stays flat; split to about the base's edge length it bends with the base. The
    midpoints lie on their edges, so the surface, its creases and corners stay where they are;
    the old vertices keep their ids and positions, faces with no edge in the region are kept.
    A good ``max_length`` is the editor's base edge length L,
    ``Editor(V, F).report()["base"]["target_length"]``; the refined mesh's editor,
    ``Editor(r.V, r.F, remesh_options={"target_length": L})``, then has the same base.

    ``region``: vertex ids or a boolean mask. ``max_vertices``: None, or the most vertices the
    result may have. Raises ValueError for an id out of range, a ``max_length`` that is not > 0 or
    a result over ``max_vertices``.
    """
    V2, F2, ids, added = _remora.refine_region(V, F, region, max_length, max_vertices)
    return Refined(V2, F2, ids, int(added))
