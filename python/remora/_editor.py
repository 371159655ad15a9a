"""The multiresolution editor (paper sections 3 and 6, Fig. 3) and handle transforms."""

from typing import Optional

import numpy as np

from . import _remora


def _handle_list(handles) -> list:
    """``handles`` as a list with one index array or mask per handle."""
    if isinstance(handles, np.ndarray):
        if handles.ndim == 1:
            return [handles]
        if handles.ndim == 2 and handles.dtype == np.bool_:
            return list(handles)
        raise ValueError(
            f"handles: expected a list of index arrays or masks (one per handle), "
            f"a 1-D array (one handle) or an (h, n) boolean array; got shape {handles.shape}"
        )
    if isinstance(handles, (list, tuple)):
        if any(np.ndim(h) == 0 for h in handles):
            raise ValueError(
                "handles: expected a list of index arrays or masks, one per handle "
                "(for one handle of ids a, b, c: [[a, b, c]]); got a list with a single number"
            )
        return list(handles)
    raise ValueError(
        f"handles: expected a list of index arrays or masks, got {type(handles).__name__}"
    )


class Editor:
    """The multiresolution editor of Botsch & Kobbelt 2004 on the mesh (V, F).

    Construction runs the preprocessing of Fig. 3 (steps 1-3): the base surface S (a low-pass
    filter of the mesh, same connectivity), its area-equalizing remesh B (section 4) and the
    correspondence between them. Then, per region:

    - :meth:`set_region` (steps 4-5) maps the painted support and handles onto B, factors the
      k-harmonic system (Eq. 3) once, encodes every support vertex as a Phong detail on the
      rest base, and solves the 3 + 4h basis functions (section 6);
    - :meth:`set_transform` (step 6) stores an affine map per handle: no work;
    - :meth:`positions` (step 7) blends the basis functions and decodes the details: no solve.

    The mesh's connectivity never changes, and vertices outside the support keep their
    positions bit for bit. For the same mesh, region and transforms, :meth:`positions` is bit
    for bit what ``remora edit`` writes (``remora edit --method nonlinear`` for
    ``method="nonlinear"``).

    How the base B follows the handles is ``method``:

    - ``"linear"`` (the paper): the blend of the k-harmonic basis functions, exact for the
      affine maps of the handles and free of iterations. A rotated handle does not rotate the
      support: the support shears and shrinks, the known limit of linear variational
      deformation (Botsch & Sorkine, "On linear variational surface deformation methods",
      TVCG 2008, section 4).
    - ``"nonlinear"``: starting from the linear result, B's free vertices minimize an energy
      that is invariant under rotations of the rest shape's local pieces, by alternating a
      local step (one best-fitting 3x3 rotation per vertex) and a global step (one sparse solve
      with a matrix factored once per region), as in as-rigid-as-possible modelling (Sorkine &
      Alexa 2007), with Anderson acceleration (Peng et al. 2018). The default energy rotates
      B's Laplacian coordinates (a thin plate like k = 2) and adds the ARAP term that fixes the
      rotations; ``"arap"`` alone is a membrane. Identity transforms give the input exactly,
      and the details are decoded on the deformed B as for linear. src/remora/multires/nonlinear.h
      states the energy.

    Args:
        V: (n, 3) float vertex positions, finite.
        F: (m, 3) integer vertex ids of a manifold, consistently oriented triangle mesh
            (:func:`remora.read_mesh` and :func:`remora.repair` give one).
        k: 1 (membrane), 2 (thin plate, the default) or 3 (minimum variation of curvature).
        method: "linear" (the default, the paper) or "nonlinear" (large rotations, above);
            :meth:`set_method` switches later.
        nonlinear_options: a dict for method "nonlinear": ``energy`` ("rotated-laplacian", the
            default, "propagated": the handles' rotations blended by their weights, one solve,
            "blended-motions": the handles' rigid motions blended by their weights as screws,
            in closed form, or "arap"), ``rigidity`` (100: the weight of the ARAP term against the
            rotated Laplacian's, relative to the support's size), ``max_iterations`` (200, per
            change of the transforms), ``tolerance`` (1e-4: converged when no free vertex
            moves more than this times B's mean edge length in an iteration), and
            ``energy_tolerance`` (1e-4: or when the energy falls by less than this fraction per
            iteration over three), ``anderson`` (5: the acceleration's history; 0 = plain
            iterations), ``preview_vertices`` (4000: a support of more than twice this many free
            base vertices is iterated on a coarser remesh of B of about this many while
            :meth:`positions` has a ``budget_ms``; 0 = never), ``solver`` (the global step's
            factorization, a name of :func:`remora.solver_names`; default: the direct solver).
        **options: ``areas`` ("mean", the paper's symmetric system; "mixed"; "mixed-symmetric";
            docs/solvers.md), ``solver`` (a name of :func:`remora.solver_names` or "multigrid";
            default: the direct solver, "lu" for "mixed"), ``solver_options`` (a dict:
            ``tolerance`` (1e-10) and ``max_iterations`` (0 = 10 times the dimension) of the
            iterative solvers, ``ordering`` of cholmod ("amd" or "metis"), ``preconditioner``
            of cg ("jacobi" or "ichol")), ``details`` ("normal", the paper's
            Phong details; "displacement"; "none"), ``remesh`` (True; False solves on the
            mesh's own connectivity, the baseline the paper improves on), ``base_smoothing``
            (2: the low-pass length in mean edge lengths), ``base_feature_cap`` (1),
            ``remesh_options`` (a dict of :func:`remora.remesh` options for the base),
            ``threads`` (0 = all cores), ``progress`` (``f(phase, step, steps)``, called at the
            start of every phase of the preprocessing). docs/editing.md explains each.

    Raises ValueError for bad arrays or options (the message names the option: ``Editor:
    option method: unknown method ...``), RuntimeError when a solver fails.
    """

    def __init__(
        self,
        V,
        F,
        k: int = 2,
        method: str = "linear",
        nonlinear_options: Optional[dict] = None,
        **options,
    ):
        options["k"] = k
        options["method"] = method
        if nonlinear_options is not None:
            options["nonlinear_options"] = nonlinear_options
        self._editor = _remora.Editor(V, F, options)

    @property
    def n_vertices(self) -> int:
        """The number of vertices of the edited mesh (rows of :meth:`positions`)."""
        return self._editor.n_vertices

    @property
    def handle_count(self) -> int:
        """The number of handles of the current region (0 before :meth:`set_region`)."""
        return self._editor.handle_count()

    def set_region(self, support, handles) -> None:
        """Sets the support and the handles, and precomputes everything a drag needs.

        Args:
            support: the vertices that may move, handles included: an index array or a boolean
                mask of length n.
            handles: one index array or mask per handle (a list), each inside the support and
                disjoint from the others; a single 1-D array is one handle.

        Every transform goes back to the identity. Raises ValueError for an empty support or
        handle, an id out of range, a handle vertex outside the support or in two handles, or a
        support component without a handle or fixed vertex next to it; RuntimeError when the
        solver fails. On an error the previous region stays.
        """
        self._editor.set_region(support, _handle_list(handles))

    def set_transform(self, handle: int, T) -> None:
        """Handle ``handle``'s vertices go to T [x; 1] of their rest positions.

        T: a (3, 4) affine map [M | t] or a (4, 4) one with last row 0, 0, 0, 1, in the mesh's
        coordinates (:func:`remora.transform` builds one). Raises ValueError for a handle out of
        range, a non-finite T, or an M that mirrors (det M <= 0) or collapses the handle.
        """
        self._editor.set_transform(handle, T)

    def transform(self, handle: int) -> np.ndarray:
        """Handle ``handle``'s current transform, (3, 4)."""
        return self._editor.transform(handle)

    def handle_center(self, handle: int) -> np.ndarray:
        """The centroid (3,) of handle ``handle``'s vertices at rest: the default centre of
        rotations and scalings (what ``remora edit --rotate`` turns about)."""
        return self._editor.handle_center(handle)

    def positions(
        self, out: Optional[np.ndarray] = None, *, budget_ms: Optional[float] = None
    ) -> np.ndarray:
        """The mesh's vertex positions under the current transforms, (n, 3) float64.

        A new array, or ``out`` (a writeable C-contiguous (n, 3) float64 array) filled and
        returned, which saves the allocation in an interactive loop. Only the first call after a
        :meth:`set_transform` computes (blend and decode, no solve).

        Method "nonlinear": with ``budget_ms=None`` (the default) the iteration runs until it
        has converged (or reached ``max_iterations``), and the result is final. A number
        (milliseconds of wall time, >= 0) bounds the iterations of this call (at least one),
        for an interactive drag: each call goes on from the last one, and :attr:`converged`
        says when the result is final. Method "linear" ignores ``budget_ms``.

        Raises ValueError before :meth:`set_region` and for a negative or non-finite
        ``budget_ms``.
        """
        return self._editor.positions(out, budget_ms)

    @property
    def method(self) -> str:
        """How the base follows the handles: "linear" or "nonlinear"."""
        return self._editor.method()

    def set_method(self, method: str, energy: str | None = None) -> None:
        """Switches between "linear" and "nonlinear", for the current region and the next ones;
        ``energy`` (optional) also sets the nonlinear method's (``nonlinear_options``' names).

        Cheap: the next :meth:`positions` builds what "nonlinear" needs for the current region
        (one factorization, none for "blended-motions"). The transforms stay. Raises ValueError
        (naming ``method`` or ``energy``) for another name.
        """
        self._editor.set_method(method, energy)

    @property
    def converged(self) -> bool:
        """Whether the last :meth:`positions` is final under the current transforms.

        Always True for method "linear" and without a region. Method "nonlinear": True once the
        iteration has converged, reached ``max_iterations`` or fallen back to the linear result
        (``report()["nonlinear"]["fallback"]`` says why); False after a :meth:`set_transform`
        until a :meth:`positions` has finished, and while calls with ``budget_ms`` are still
        iterating.
        """
        return self._editor.converged()

    def movable_vertices(self) -> np.ndarray:
        """The vertices that move under the current region (the support), increasing ids."""
        return self._editor.movable_vertices()

    def base(self):
        """The base mesh B at rest: (V_base, F_base), the remesh of the smoothed surface."""
        return self._editor.base()

    def base_positions(self) -> np.ndarray:
        """B's vertex positions under the current transforms, (n_base, 3)."""
        return self._editor.base_positions()

    def low_pass(self, values) -> np.ndarray:
        """The editor's low-pass filter (the one that made S) applied to (n, 3) values."""
        return self._editor.low_pass(values)

    def set_system(self, k: int = 2, areas: str = "mean") -> None:
        """Changes k and the area weights for the next :meth:`set_region`."""
        self._editor.set_system(k, areas)

    def prepare_regions(self) -> None:
        """Precomputes, once, what the regions to come share: the rows of the base's operator
        for the current k (each :meth:`set_region` then copies its system out of them) and, with
        the "cholmod" solver, a nested dissection of the base (METIS), which each large region's
        factor follows instead of ordering its own rows (docs/solvers.md). Worth its cost (METIS on
        the whole base) before many regions; does nothing on a base of more than 200,000
        vertices. The results are those of an unprepared editor to round-off;
        ``report()["solver"]["keyed_order"]`` and ``["tree_cut"]`` say whether a region's factor
        followed the order and was cut at its top."""
        self._editor.prepare_regions()

    def report(self) -> dict:
        """Figures and timings (docs/editing.md, "The report"): sizes of the input and base,
        the low-pass filter's sigma, the base's quality, the region on both meshes, the solver's
        statistics, the Phong details, ``method`` ("linear" or "nonlinear") and for
        "nonlinear" a dict ``nonlinear`` (the last :meth:`positions`' ``iterations`` and those
        since the last transform, ``accelerated``, ``converged``, ``last_move`` in B's mean
        edge lengths, ``energy`` after each iterate, ``fallback``: why the linear result is
        shown, or empty), and wall times in milliseconds ("base", "remesh", "set_region" and
        its parts, "frame": the last :meth:`positions` that had work)."""
        return self._editor.report()


def transform(
    center=(0.0, 0.0, 0.0),
    *,
    scale=None,
    rotate_axis=None,
    rotate_degrees: float = 0.0,
    translate=None,
) -> np.ndarray:
    """An affine map as a (3, 4) array [M | t]: scale, then rotate, then translate.

    Scaling by the factors ``scale`` (sx, sy, sz) and rotation by ``rotate_degrees`` about
    ``rotate_axis`` (any non-zero length, right-handed) are about ``center``; ``translate`` is
    (dx, dy, dz). The same map as a handle's transform in EDIT.json and as ``remora edit
    --scale/--rotate/--translate`` with ``center=editor.handle_center(j)``.
    """
    return _remora.handle_transform(center, scale, rotate_axis, float(rotate_degrees), translate)
