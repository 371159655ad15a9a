"""The area-equalizing isotropic remesh (paper section 4) and the editor's low-pass filter."""

from typing import NamedTuple

import numpy as np

from . import _remora


class SurfacePoints(NamedTuple):
    """Points on a triangle mesh: a face id and barycentric coordinates per point.

    face: (k,) int64, -1 where a point has no face (an isolated vertex). bary: (k, 3) float64,
    weights of the face's corners ``F[face, 0]``, ``F[face, 1]``, ``F[face, 2]``; they sum to 1.
    """

    face: np.ndarray
    bary: np.ndarray

    def evaluate(self, V: np.ndarray, F: np.ndarray) -> np.ndarray:
        """The (k, 3) positions of the points on the mesh (V, F): sum of bary times corners.

        Points without a face give NaN.
        """
        V = np.asarray(V, dtype=np.float64)
        corners = V[np.asarray(F)[np.maximum(self.face, 0)]]  # (k, 3 corners, 3)
        out = np.einsum("kc,kcd->kd", self.bary, corners)
        out[self.face < 0] = np.nan
        return out


class Remeshed(NamedTuple):
    """The result of :func:`remesh`.

    V, F: the new mesh. output_on_input: where each new vertex lies on the input
    (:class:`SurfacePoints` on the input's faces). input_on_output: where each input vertex
    lies on the new mesh (its closest point there). report: a dict (docs/remesh.md, "The
    report"): target length, cycles, operation counts, timings in milliseconds and, with
    ``compute_report`` (the default), the quality figures of the input, after the cycles and
    after the equalization, the Laplacian symmetry defects and the distances to the input.
    """

    V: np.ndarray
    F: np.ndarray
    output_on_input: SurfacePoints
    input_on_output: SurfacePoints
    report: dict


def remesh(V, F, **options) -> Remeshed:
    """Remeshes (V, F) isotropically with equalized vertex areas (Botsch & Kobbelt 2004, section 4).

    The result's edges are near a target length l, its valences near 6 and its mixed vertex
    areas nearly equal, so that the Laplacian of Eq. 1 becomes symmetric with the mean area
    (section 5). The input is not changed; boundaries stay on the input's boundary. The same
    input and options give the same output bit for bit, whatever the number of threads, and the
    same as ``remora remesh`` with the same options.

    Options (RemeshOptions in src/remora/remesh/remesh.h; docs/remesh.md explains each):
    ``target_length`` (absolute l; default 0: ``length_factor`` (0.9) times the mean edge
    length), ``cycles`` (7, at least), ``max_cycles`` (12), ``settle_fraction`` (0.03),
    ``equalize_iterations`` (9), ``equalization`` ("newton" or "gravity", the paper's update),
    ``lambda_`` (0.8, the damping), ``equalize_smoothing`` (2.5), ``smoothing_target`` ("odt"
    or "centroid"), ``equalize_momentum`` (0.5), ``equalize_flips`` (True),
    ``equalize_guard_deg`` (30), ``equalize_boundary`` (True), ``project`` (True),
    ``repair_angle_deg`` (25), ``corner_angle_deg`` (30), ``feature_angle_deg`` (0 = no feature
    lines), ``boundary_spacing`` (1.2), ``compute_report`` (True; False skips the quality
    figures, which take time), ``threads`` (0 = all cores), ``progress`` (a callable
    ``f(phase, step, steps)`` called at the start of every phase).

    Returns :class:`Remeshed`. Raises ValueError for bad arrays, an unknown option or a value
    out of range.
    """
    V2, F2, out_on_in, in_on_out, report = _remora.remesh(V, F, options)
    return Remeshed(V2, F2, SurfacePoints(*out_on_in), SurfacePoints(*in_on_out), report)


def low_pass(V, F, smoothing: float = 2.0, **options):
    """The editor's base surface S: a low-pass filtered copy of (V, F) (section 3, Fig. 3).

    One implicit fairing step (M - sigma^2 W) S = M V on the intrinsic Delaunay Laplacian, with
    sigma = ``smoothing`` times the mesh's length scale (its mean edge length unless needles
    inflate it); boundary loops are filtered as curves. Options: ``feature_cap`` (1: sigma at
    most that times the part's local half-width, so thin tubes and small holes are not pinched;
    0 = off), ``cap_slope`` (1), ``steps`` (1), ``tolerance`` (1e-10, of the CG solves),
    ``threads``. docs/editing.md explains each.

    Returns (S, stats): S (n, 3) float64, the same connectivity F; stats a dict with ``sigma``,
    ``sigma_min``, ``sigma_capped_vertices``, ``sigma_capped_loops`` and ``intrinsic_flips``.
    ``remora remesh --low-pass 2`` remeshes this S.
    """
    options["smoothing"] = smoothing
    return _remora.low_pass(V, F, options)
