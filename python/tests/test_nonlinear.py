"""Method "nonlinear" from Python: the option and set_method() reach the library (a twisted
cylinder keeps its radius where the linear method shrinks it), the identity gives the input,
converged and budget_ms behave as documented, and bad names and values are refused by name."""

import numpy as np
import pytest

import remora
from conftest import EAR_HANDLE, EAR_SUPPORT, grid


def cylinder(rings: int = 24, segments: int = 32, height: float = 4.0):
    """An open cylinder of radius 1 about the z axis, faces outward: (V, F, ring ids), where
    ring k holds the vertices at z = height * k / rings."""
    k, s = np.meshgrid(np.arange(rings + 1), np.arange(segments), indexing="ij")
    phi = 2.0 * np.pi * s / segments
    V = np.column_stack([np.cos(phi).ravel(), np.sin(phi).ravel(), (height * k / rings).ravel()])
    ids = np.arange(V.shape[0]).reshape(rings + 1, segments)
    a, b = ids[:-1], np.roll(ids, -1, axis=1)[:-1]
    c, d = np.roll(ids, -1, axis=1)[1:], ids[1:]
    F = np.concatenate([np.column_stack([a.ravel(), b.ravel(), c.ravel()]),
                        np.column_stack([a.ravel(), c.ravel(), d.ravel()])])
    return V, F, ids


@pytest.fixture(scope="module")
def twisted():
    """The cylinder with its top ring as the handle and every ring but the bottom one as the
    support, one editor per method, and the top twisted by 90 degrees about the axis."""
    V, F, rings = cylinder()
    T = remora.transform((0.0, 0.0, 4.0), rotate_axis=(0, 0, 1), rotate_degrees=90)
    editors = {}
    for method in ("linear", "nonlinear"):
        editor = remora.Editor(V, F, method=method)
        editor.set_region(rings[1:].ravel(), [rings[-1]])
        editor.set_transform(0, T)
        editors[method] = editor
    return V, F, rings, T, editors


def middle_radius(P, rings):
    ring = P[rings[len(rings) // 2]]
    return np.linalg.norm(ring[:, :2] - ring[:, :2].mean(axis=0), axis=1).mean()


def test_a_twist_shrinks_the_linear_cylinder_and_not_the_nonlinear_one(twisted):
    # The linear method's known failure (Botsch & Sorkine 2008): halfway up, the blend of the
    # identity and a 90 degree rotation scales by cos(45 degrees); the nonlinear one rotates.
    _, _, rings, _, editors = twisted
    linear = middle_radius(editors["linear"].positions(), rings)
    nonlinear = middle_radius(editors["nonlinear"].positions(), rings)
    assert linear < 0.9
    assert abs(nonlinear - 1.0) < 0.05
    report = editors["nonlinear"].report()
    assert report["method"] == "nonlinear" and editors["linear"].report()["method"] == "linear"
    assert report["nonlinear"]["fallback"] == ""
    energy = report["nonlinear"]["energy"]
    assert len(energy) > 1 and all(b <= a for a, b in zip(energy, energy[1:]))


def test_set_method_switches_the_same_region(twisted):
    V, F, rings, T, editors = twisted
    editor = editors["linear"]
    linear = editor.positions()
    editor.set_method("nonlinear")
    assert editor.method == "nonlinear" and not editor.converged
    switched = editor.positions()
    # The same options and the same transform as the editor made with method="nonlinear".
    assert np.array_equal(switched, editors["nonlinear"].positions())
    editor.set_method("linear")
    assert editor.method == "linear" and editor.converged
    assert np.array_equal(editor.positions(), linear)


def test_converged_after_positions_and_not_before(twisted):
    _, _, _, T, editors = twisted
    editor = editors["nonlinear"]
    editor.set_transform(0, T)
    assert not editor.converged  # a transform was set: nothing iterated yet
    editor.positions()
    assert editor.converged
    assert editors["linear"].converged  # the linear method is always final


def test_a_budget_iterates_a_little_per_call_until_converged(twisted):
    _, _, _, T, editors = twisted
    editor = editors["nonlinear"]
    editor.set_transform(0, remora.transform((0.0, 0.0, 4.0), rotate_axis=(0, 0, 1),
                                             rotate_degrees=60))
    editor.positions()  # converged at 60 degrees; the drag goes on to 90
    editor.set_transform(0, T)
    totals = []
    for _ in range(250):  # max_iterations is 200
        editor.positions(budget_ms=0)  # one iteration per call
        stats = editor.report()["nonlinear"]
        assert stats["iterations"] == 1 or editor.converged
        totals.append(stats["total_iterations"])
        if editor.converged:
            break
    assert editor.converged and len(totals) > 1
    assert totals == sorted(totals)


def test_nonlinear_options_reach_the_deformer(twisted):
    V, F, rings, T, _ = twisted
    one = remora.Editor(V, F, method="nonlinear", nonlinear_options={"max_iterations": 1})
    one.set_region(rings[1:].ravel(), [rings[-1]])
    one.set_transform(0, T)
    P = one.positions()
    assert one.converged  # max_iterations reached: final
    assert one.report()["nonlinear"]["total_iterations"] == 1
    arap = remora.Editor(V, F, method="nonlinear", nonlinear_options={"energy": "arap"})
    arap.set_region(rings[1:].ravel(), [rings[-1]])
    arap.set_transform(0, T)
    assert not np.array_equal(arap.positions(), P)


def test_blended_motions_keep_every_ring_in_closed_form(twisted):
    # The handles' screws blended by their weights: each ring moves rigidly, no iteration.
    V, F, rings, T, _ = twisted
    editor = remora.Editor(V, F, method="nonlinear",
                           nonlinear_options={"energy": "blended-motions"})
    editor.set_region(rings[1:].ravel(), [rings[-1]])
    editor.set_transform(0, T)
    P = editor.positions()
    assert editor.converged
    report = editor.report()
    assert report["nonlinear"]["total_iterations"] == 0
    assert report["nonlinear"]["energy_name"] == "blended-motions"
    ring = P[rings]  # (rings, segments, 3)
    radii = np.linalg.norm(ring[:, :, :2] - ring[:, :, :2].mean(axis=1, keepdims=True), axis=2)
    assert np.abs(radii.mean(axis=1) - 1.0).max() < 0.02
    # set_method switches the energy too, with the same region and transforms.
    editor.set_method("nonlinear", energy="rotated-laplacian")
    assert not np.array_equal(editor.positions(), P)
    editor.set_method("nonlinear", energy="blended-motions")
    assert np.array_equal(editor.positions(), P)
    with pytest.raises(ValueError, match=r"energy: unknown nonlinear energy 'screw'"):
        editor.set_method("nonlinear", energy="screw")


def test_the_identity_gives_the_input(bunny):
    V = bunny.V
    support = remora.select_sphere(V, *EAR_SUPPORT)
    editor = remora.Editor(V, bunny.F, method="nonlinear")
    editor.set_region(support, [remora.select_sphere(V, *EAR_HANDLE)])
    P = editor.positions()
    assert editor.converged and editor.report()["nonlinear"]["total_iterations"] == 0
    outside = np.setdiff1d(np.arange(len(V)), support)
    assert np.array_equal(P[outside], V[outside])
    assert np.abs(P - V).max() < 1e-9 * np.ptp(V, axis=0).max()
    # Back at the identity after a large rotation: the rest shape again, bit for bit the linear
    # method's decode of it (no iteration).
    editor.set_transform(0, remora.transform(editor.handle_center(0), rotate_axis=(0, 0, 1),
                                             rotate_degrees=90))
    editor.positions()
    editor.set_transform(0, np.eye(4))
    assert np.array_equal(editor.positions(), P)
    editor.set_method("linear")
    assert np.array_equal(editor.positions(), P)


def test_bad_methods_and_options_name_themselves():
    V, F = grid(8)
    with pytest.raises(ValueError, match=r"Editor: option method: unknown method 'arap'"):
        remora.Editor(V, F, method="arap")
    with pytest.raises(ValueError, match=r"Editor: option method: expected a string"):
        remora.Editor(V, F, method=1)
    for options, message in [
        ({"rigidity": 0.0}, r"option rigidity: must be > 0, got 0"),
        ({"max_iterations": 0}, r"option max_iterations: must be >= 1"),
        ({"max_iterations": 2.5}, r"option max_iterations: expected an integer"),
        ({"tolerance": -1.0}, r"option tolerance: must be > 0"),
        ({"anderson": -1}, r"option anderson: must be >= 0"),
        ({"energy": "elastic"}, r"option energy: unknown nonlinear energy 'elastic'"),
        ({"solver": "magic"}, r"option solver: unknown solver 'magic'"),
        ({"iterations": 5}, r"unknown option 'iterations' \(options: anderson, energy"),
    ]:
        with pytest.raises(ValueError, match=r"Editor: option nonlinear_options: .*" + message):
            remora.Editor(V, F, method="nonlinear", nonlinear_options=options)
    with pytest.raises(ValueError, match=r"nonlinear_options: expected a dict"):
        remora.Editor(V, F, nonlinear_options=3)

    editor = remora.Editor(V, F)
    with pytest.raises(ValueError, match=r"^method: unknown method 'Nonlinear'"):
        editor.set_method("Nonlinear")
    assert editor.method == "linear"
    editor.set_region(np.arange(len(V)), [np.array([0])])
    editor.set_method("nonlinear")
    for budget, message in [(-1.0, r"must be >= 0, got -1"), (float("nan"), "nan is not finite"),
                            (True, "expected a number, got bool")]:
        with pytest.raises(ValueError, match=r"^budget_ms: " + message):
            editor.positions(budget_ms=budget)
