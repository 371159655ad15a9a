"""Remora: detail-preserving multiresolution editing of triangle meshes.

After Botsch & Kobbelt, "A Remeshing Approach to Multiresolution Modeling" (SGP 2004). The
package wraps Remora's C++ library (docs/python.md is the tutorial):

- meshes as numpy arrays: ``V`` is (n, 3) float64 (the vertex positions, in the mesh's units),
  ``F`` is (m, 3) int64 (zero-based vertex ids per triangle, counter-clockwise seen from
  outside); any array-like of those shapes is accepted on input;
- files: :func:`read_mesh` (with repair), :func:`write_mesh`, :func:`repair`, :func:`quality`;
- the area-equalizing remesh of the paper's section 4: :func:`remesh`, and the editor's low-pass
  filter :func:`low_pass`;
- the editor (sections 3 and 6, Fig. 3): :class:`Editor`, :func:`transform`, and the region
  helpers :func:`select_sphere`, :func:`select_box`, :func:`select_geodesic_disc`,
  :func:`nearest_vertex`, and :func:`refine_region` for a support of long triangles;
- the mathematics (Eq. 1-3, section 5) as scipy.sparse matrices: :func:`cotan_laplacian`,
  :func:`mass_matrix`, :func:`kharmonic_system`.

Errors: ``ValueError`` for a bad argument (its message names the argument), ``OSError`` for a
file that cannot be read or written, ``RuntimeError`` when a numerical method fails. Long calls
release the GIL, and Ctrl+C stops them at the next phase.
"""

from ._remora import __version__, WITH_GPL_SOLVERS, keep_freed_memory
from ._mesh import (
    MeshData,
    nearest_vertex,
    quality,
    read_mesh,
    refine_region,
    Refined,
    repair,
    select_box,
    select_geodesic_disc,
    select_sphere,
    write_mesh,
)
from ._remesh import Remeshed, SurfacePoints, low_pass, remesh
from ._editor import Editor, transform
from ._systems import KHarmonicSystem, cotan_laplacian, kharmonic_system, mass_matrix

__all__ = [
    "__version__",
    "WITH_GPL_SOLVERS",
    "Editor",
    "KHarmonicSystem",
    "MeshData",
    "Refined",
    "Remeshed",
    "SurfacePoints",
    "cotan_laplacian",
    "keep_freed_memory",
    "kharmonic_system",
    "low_pass",
    "mass_matrix",
    "nearest_vertex",
    "quality",
    "read_mesh",
    "refine_region",
    "remesh",
    "repair",
    "select_box",
    "select_geodesic_disc",
    "select_sphere",
    "solver_names",
    "transform",
    "write_mesh",
]


def solver_names() -> list:
    """The sparse solvers of this build, by the names ``Editor(solver=...)`` takes.

    ``cholmod`` (the default) and UMFPACK's ``lu`` exist only in a build with the GPL solvers
    (``WITH_GPL_SOLVERS``); docs/solvers.md compares them (the paper's section 5).
    """
    from ._remora import solver_names as names

    return list(names())
