"""The editor from Python: the invariants of an edit (a zero edit, the far vertices, a
translation of everything constrained), the region and transform forms agreeing bit for bit,
and the numpy arrays' shapes, types and ownership."""

import threading

import numpy as np
import pytest

import remora
from conftest import EAR_HANDLE, EAR_SUPPORT


@pytest.fixture(scope="module")
def bunny_editor(bunny):
    """One editor on the bunny (its preprocessing is the costly part); tests set their region."""
    return remora.Editor(bunny.V, bunny.F)


@pytest.fixture
def ear(bunny, bunny_editor):
    """The bunny's editor with the ear region set (k = 2)."""
    support = remora.select_sphere(bunny.V, *EAR_SUPPORT)
    handle = remora.select_sphere(bunny.V, *EAR_HANDLE)
    bunny_editor.set_system(k=2)
    bunny_editor.set_region(support, [handle])
    return bunny_editor, support, handle


def test_arrays_out(ear, bunny):
    editor, support, _ = ear
    P = editor.positions()
    assert P.shape == bunny.V.shape and P.dtype == np.float64 and P.flags.c_contiguous
    assert P.flags.owndata or P.base is not None
    assert P.flags.writeable
    assert np.array_equal(editor.movable_vertices(), support)
    assert editor.handle_count == 1
    Vb, Fb = editor.base()
    assert Vb.shape[1] == 3 and Fb.dtype == np.int64 and Fb.max() < len(Vb)
    assert editor.base_positions().shape == Vb.shape
    assert editor.transform(0).shape == (3, 4)
    report = editor.report()
    assert report["region"]["support_vertices"] == len(support)
    assert report["base"]["vertices"] == len(Vb)


def test_a_zero_edit_reproduces_the_input(ear, bunny):
    editor, support, _ = ear
    editor.set_transform(0, np.eye(3, 4))
    P = editor.positions()
    scale = np.ptp(bunny.V, axis=0).max()
    assert np.abs(P - bunny.V).max() < 1e-9 * scale


def test_far_vertices_stay_and_the_handle_follows(ear, bunny):
    editor, support, handle = ear
    t = np.array([0.0, 0.01, 0.005])
    editor.set_transform(0, remora.transform(translate=t))
    P = editor.positions()
    outside = np.setdiff1d(np.arange(len(P)), support)
    assert np.array_equal(P[outside], bunny.V[outside])
    # The handle's base vertices move by t exactly; its input vertices ride on them with their
    # details, so they move by t up to the change of the base around them.
    move = P[handle] - bunny.V[handle]
    assert np.abs(move.mean(axis=0) - t).max() < 0.1 * np.linalg.norm(t)


def test_translating_everything_constrained_translates_the_result(bunny, bunny_editor):
    # The whole mesh is the support, and the handle is all of it except a free band: moving the
    # handle by t moves every vertex by t (the solution of Delta^k p = 0 with constant shifts).
    V = bunny.V
    editor = bunny_editor
    band = remora.select_sphere(V, *EAR_SUPPORT)
    handle = np.setdiff1d(np.arange(len(V)), band)
    editor.set_region(np.ones(len(V), bool), [handle])
    t = np.array([0.02, -0.01, 0.03])
    editor.set_transform(0, remora.transform(translate=t))
    P = editor.positions()
    assert np.abs(P - (V + t)).max() < 1e-9


def test_masks_ids_and_matrix_forms_agree_bit_for_bit(ear, bunny):
    editor, support, handle = ear
    T = remora.transform(editor.handle_center(0), rotate_axis=(1, 0, 0), rotate_degrees=-15,
                         translate=(0, 0.01, 0))
    editor.set_transform(0, T)
    first = editor.positions()
    # The same region as boolean masks, shuffled ids with repeats, and T as a 4 x 4 list.
    n = len(bunny.V)
    support_mask = np.zeros(n, bool)
    support_mask[support] = True
    shuffled = np.random.default_rng(7).permutation(np.concatenate([handle, handle[:3]]))
    editor.set_region(support_mask, [shuffled.astype(np.int32)])
    editor.set_transform(0, np.vstack([T, [0, 0, 0, 1]]).tolist())
    out = np.empty_like(first)
    assert editor.positions(out=out) is out
    assert np.array_equal(out, first)
    assert np.array_equal(editor.transform(0), T)
    with pytest.raises(ValueError, match=r"out: expected a writeable C-contiguous"):
        editor.positions(out=np.empty((n, 3)).T.copy().T)


def test_positions_are_a_fresh_array_each_time(ear):
    editor, _, _ = ear
    a = editor.positions()
    a[:] = 0.0
    b = editor.positions()
    assert not np.shares_memory(a, b) and np.abs(b).max() > 0


def test_two_threads_on_one_editor(ear):
    editor, _, _ = ear
    editor.set_transform(0, remora.transform(translate=(0, 0.01, 0)))
    expected = editor.positions()
    results, errors = [], []

    def drag():
        try:
            for _ in range(20):
                editor.set_transform(0, remora.transform(translate=(0, 0.01, 0)))
                results.append(editor.positions())
        except Exception as e:  # reported below
            errors.append(e)

    threads = [threading.Thread(target=drag) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    assert len(results) == 40 and all(np.array_equal(r, expected) for r in results)


def test_higher_k_bends_wider(bunny, bunny_editor):
    V = bunny.V
    support = remora.select_sphere(V, *EAR_SUPPORT)
    handle = remora.select_sphere(V, *EAR_HANDLE)
    T = remora.transform(translate=(0, 0.02, 0))
    moved = {}
    editor = bunny_editor
    for k in (1, 2, 3):
        editor.set_system(k=k)
        editor.set_region(support, [handle])
        editor.set_transform(0, T)
        moved[k] = editor.positions()
    # Higher k: a smoother, wider bend, so the support's mid-region moves more.
    mid = np.setdiff1d(remora.select_sphere(V, EAR_SUPPORT[0], 0.035), handle)
    lift = {k: (moved[k][mid, 1] - V[mid, 1]).mean() for k in moved}
    assert lift[1] < lift[2] < lift[3]


def test_a_prepared_editor_solves_as_an_unprepared_one(bunny):
    # A region large enough to be factored in two halves on two threads, which are cut at the
    # top of the base's order once it exists. The result is the same to round-off.
    support = np.flatnonzero(bunny.V[:, 1] > 0.075)
    handle = np.flatnonzero(bunny.V[:, 1] > 0.16)
    T = remora.transform(translate=(0.01, 0.02, 0))
    moved, separators = [], []
    for prepared in (False, True):
        editor = remora.Editor(bunny.V, bunny.F, threads=2)
        if prepared:
            editor.prepare_regions()
        editor.set_region(support, [handle])
        editor.set_transform(0, T)
        moved.append(editor.positions())
        solver = editor.report()["solver"]
        if solver["name"] == "cholmod":
            assert solver["keyed_order"] == prepared and solver["tree_cut"] == prepared
            assert solver["separator_rows"] > 0
            separators.append(solver["separator_rows"])
    assert np.abs(moved[0] - moved[1]).max() < 1e-9
    if separators:
        assert separators[1] < separators[0]  # the order's separator is the thinner cut
