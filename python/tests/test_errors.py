"""Bad input from Python raises a clear exception naming the problem, never a crash:
ValueError for arguments, OSError for files, RuntimeError for numerical failures."""

import numpy as np
import pytest

import remora
from conftest import grid


@pytest.fixture(scope="module")
def flat():
    return grid(10)


@pytest.fixture(scope="module")
def editor(flat):
    V, F = flat
    return remora.Editor(V, F, base_smoothing=0.0)


def test_nan_coordinates(flat):
    V, F = flat
    bad = V.copy()
    bad[7, 1] = np.nan
    with pytest.raises(ValueError, match=r"V: row 7 has a non-finite coordinate"):
        remora.remesh(bad, F)
    bad[7, 1] = np.inf
    with pytest.raises(ValueError, match=r"V: row 7"):
        remora.Editor(bad, F)


def test_faces_out_of_range(flat):
    V, F = flat
    bad = F.copy()
    bad[3, 2] = len(V)
    with pytest.raises(ValueError, match=rf"F: row 3 has vertex id {len(V)}, outside \[0, {len(V)}\)"):
        remora.quality(V, bad)
    bad[3, 2] = -1
    with pytest.raises(ValueError, match=r"F: row 3 has vertex id -1"):
        remora.remesh(V, bad)


def test_wrong_shapes(flat):
    V, F = flat
    with pytest.raises(ValueError, match=r"V: expected an \(n, 3\) array of vertex positions, got shape \(\d+, 2\)"):
        remora.quality(V[:, :2], F)
    with pytest.raises(ValueError, match=r"F: expected an \(n, 3\) array of vertex ids"):
        remora.quality(V, F[:, :2])
    with pytest.raises(ValueError, match=r"V: expected an \(n, 3\) array.*shape \(\d+,\)"):
        remora.quality(V.ravel(), F)
    with pytest.raises(ValueError, match=r"V: expected an array, got None"):
        remora.quality(None, F)
    with pytest.raises(ValueError, match=r"V: expected an array of numbers"):
        remora.quality([[0, 0, 0], [1, 2]], F)


def test_wrong_dtypes(flat):
    V, F = flat
    with pytest.raises(ValueError, match=r"F: expected integer vertex ids, got dtype float64"):
        remora.remesh(V, F.astype(np.float64))
    with pytest.raises(ValueError, match=r"F: expected integer vertex ids, got dtype bool"):
        remora.quality(V, F.astype(bool))
    with pytest.raises(ValueError, match=r"V: expected floating-point coordinates .* got dtype int64"):
        remora.quality(V.astype(np.int64), F)
    # Other integer and float widths are converted.
    q = remora.quality(V.astype(np.float32), F.astype(np.uint32))
    assert q["faces"] == len(F)


def test_non_manifold_faces_point_to_repair(flat):
    V, F = flat
    bad = np.vstack([F, F[:1]])  # a triangle twice: an edge with too many triangles
    with pytest.raises(ValueError, match=r"F: .*remora.repair\(V, F\)"):
        remora.quality(V, bad)
    fixed = remora.repair(V, bad)
    assert len(fixed.F) == len(F) and fixed.report["dropped_duplicate"] == 1


def test_bad_regions(editor):
    n = editor.n_vertices
    with pytest.raises(ValueError, match=r"support: selects no vertex"):
        editor.set_region([], [[0]])
    with pytest.raises(ValueError, match=r"support: selects no vertex"):
        editor.set_region(np.zeros(n, bool), [[0]])
    with pytest.raises(ValueError, match=rf"support: vertex id {n} is out of range"):
        editor.set_region([0, n], [[0]])
    with pytest.raises(ValueError, match=r"support: vertex id -1 is negative"):
        editor.set_region([-1, 0], [[0]])
    with pytest.raises(ValueError, match=r"support: a boolean mask needs one entry per vertex"):
        editor.set_region(np.ones(n - 1, bool), [[0]])
    with pytest.raises(ValueError, match=r"support: expected vertex ids \(integers\) or a boolean mask, got dtype float64"):
        editor.set_region(np.array([0.0, 1.0]), [[0]])
    with pytest.raises(ValueError, match=r"handles\[1\]: selects no vertex"):
        editor.set_region(np.arange(n), [[0], []])
    with pytest.raises(ValueError, match=r"handles: expected a list of index arrays"):
        editor.set_region(np.arange(n), [0, 1])
    with pytest.raises(ValueError, match=r"handle"):
        editor.set_region(np.arange(20), [[60]])  # a handle outside the support


def test_no_region_yet(flat):
    V, F = flat
    fresh = remora.Editor(V, F, base_smoothing=0.0)
    assert fresh.handle_count == 0 and len(fresh.movable_vertices()) == 0
    with pytest.raises(ValueError, match=r"no region yet: call set_region\(\) first"):
        fresh.positions()
    with pytest.raises(ValueError, match=r"no region yet"):
        fresh.set_transform(0, np.eye(3, 4))


def test_bad_transforms(editor):
    V = np.asarray(editor.base()[0])
    editor.set_region(np.arange(editor.n_vertices), [[0]])
    with pytest.raises(ValueError, match=r"handle 1 does not exist: there are 1 handles"):
        editor.set_transform(1, np.eye(3, 4))
    with pytest.raises(ValueError, match=r"T: expected a \(3, 4\) or \(4, 4\) array"):
        editor.set_transform(0, np.eye(3))
    with pytest.raises(ValueError, match=r"T: the last row of a \(4, 4\) transform must be 0, 0, 0, 1"):
        editor.set_transform(0, 2 * np.eye(4))
    bad = np.eye(3, 4)
    bad[0, 3] = np.nan
    with pytest.raises(ValueError, match=r"NaN or infinite"):
        editor.set_transform(0, bad)
    mirror = np.eye(3, 4)
    mirror[0, 0] = -1
    with pytest.raises(ValueError, match=r"mirror"):
        editor.set_transform(0, mirror)
    assert len(V) > 0


def test_unknown_and_mistyped_options(flat):
    V, F = flat
    with pytest.raises(ValueError, match=r"remesh: unknown option 'cycels' \(options: .*cycles"):
        remora.remesh(V, F, cycels=3)
    with pytest.raises(ValueError, match=r"remesh: option cycles: expected an integer, got 2.5"):
        remora.remesh(V, F, cycles=2.5)
    with pytest.raises(ValueError, match=r"remesh: option project: expected True or False"):
        remora.remesh(V, F, project=1)
    with pytest.raises(ValueError, match=r"remesh: option equalization: 'magic' is not a method"):
        remora.remesh(V, F, equalization="magic")
    with pytest.raises(ValueError, match=r"lambda must be in \(0, 1\]"):
        remora.remesh(V, F, lambda_=2.0)
    with pytest.raises(ValueError, match=r"Editor: option areas: .*mixed"):
        remora.Editor(V, F, areas="exact")
    with pytest.raises(ValueError, match=r"k = 4 is not supported"):
        remora.Editor(V, F, k=4)
    with pytest.raises(ValueError, match=r"remesh_options: unknown option 'x'"):
        remora.Editor(V, F, remesh_options={"x": 1})
    with pytest.raises(ValueError, match=r"Editor: option progress: expected a callable"):
        remora.Editor(V, F, progress=3)


def test_files(tmp_path, flat):
    V, F = flat
    with pytest.raises(OSError, match=r"missing.ply: cannot open"):
        remora.read_mesh(tmp_path / "missing.ply")
    (tmp_path / "broken.off").write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n")
    with pytest.raises(OSError, match=r"broken.off"):
        remora.read_mesh(tmp_path / "broken.off")
    with pytest.raises(OSError, match=r"extension"):
        remora.write_mesh(tmp_path / "mesh.xyz", V, F)
    with pytest.raises(OSError):
        remora.write_mesh(tmp_path / "no" / "such" / "folder.ply", V, F)
    assert not (tmp_path / "mesh.xyz").exists()


def test_numerical_failure_is_a_runtime_error(flat):
    V, F = flat
    editor = remora.Editor(V, F, remesh=False, solver="cg", solver_options={"max_iterations": 1},
                           base_smoothing=0.0)
    centre = np.linalg.norm(V[:, :2] - 0.5, axis=1)
    with pytest.raises(RuntimeError, match=r"no convergence after 1 iterations"):
        editor.set_region(centre < 0.4, [centre < 0.1])


def test_an_exception_in_progress_stops_the_call(flat):
    V, F = flat

    def stop(phase, step, steps):
        raise KeyboardInterrupt(f"stopped at {phase}")

    with pytest.raises(KeyboardInterrupt, match=r"stopped at remesh"):
        remora.remesh(V, F, progress=stop)
    with pytest.raises(KeyboardInterrupt, match=r"stopped at base surface"):
        remora.Editor(V, F, progress=stop)
