"""The goals of the Python module: remesh() and Editor.positions() give bit for bit what
`remora remesh` and `remora edit` write for the same mesh, options, region and transform, with
either editing method."""

import subprocess

import numpy as np

import remora
from conftest import BUNNY, EAR_HANDLE, EAR_SUPPORT


def run(*args):
    subprocess.run([str(a) for a in args], check=True, capture_output=True)


def assert_same_file(a, b):
    assert a.read_bytes() == b.read_bytes(), f"{a} and {b} differ"


def test_remesh_matches_the_cli_bit_for_bit(bunny, cli, tmp_path):
    out_cli = tmp_path / "cli.ply"
    run(cli, "remesh", BUNNY, "-o", out_cli)
    r = remora.remesh(bunny.V, bunny.F)  # with the quality report, which the CLI skips
    out_py = tmp_path / "py.ply"
    remora.write_mesh(out_py, r.V, r.F)
    assert_same_file(out_cli, out_py)
    # The arrays themselves: the binary PLY holds doubles, and reading keeps their order.
    back = remora.read_mesh(out_cli)
    assert np.array_equal(back.V, r.V)
    assert back.V.shape == r.V.shape and back.F.shape == r.F.shape


def test_remesh_options_match_the_cli_flags(bunny, cli, tmp_path):
    out_cli = tmp_path / "cli.obj"
    run(cli, "remesh", BUNNY, "-o", out_cli, "--length-factor", "1.6", "--cycles", "3",
        "--equalize", "4", "--method", "gravity", "--lambda", "0.5", "--no-project")
    r = remora.remesh(bunny.V, bunny.F, length_factor=1.6, cycles=3, equalize_iterations=4,
                      equalization="gravity", lambda_=0.5, project=False, compute_report=False)
    out_py = tmp_path / "py.obj"
    remora.write_mesh(out_py, r.V, r.F)
    assert_same_file(out_cli, out_py)


def test_edit_matches_the_cli_bit_for_bit(bunny, cli, tmp_path):
    (sc, sr), (hc, hr) = EAR_SUPPORT, EAR_HANDLE
    out_cli = tmp_path / "cli.ply"
    run(cli, "edit", BUNNY, "-o", out_cli,
        "--support-sphere", ",".join(map(str, (*sc, sr))),
        "--handle-sphere", ",".join(map(str, (*hc, hr))),
        "--translate", "0,0.02,0", "--rotate", "0,1,0,20")
    support = remora.select_sphere(bunny.V, sc, sr)
    handle = remora.select_sphere(bunny.V, hc, hr)
    editor = remora.Editor(bunny.V, bunny.F)
    editor.set_region(support, [handle])
    T = remora.transform(editor.handle_center(0), rotate_axis=(0, 1, 0), rotate_degrees=20,
                         translate=(0, 0.02, 0))
    editor.set_transform(0, T)
    P = editor.positions()
    out_py = tmp_path / "py.ply"
    remora.write_mesh(out_py, P, bunny.F)
    assert_same_file(out_cli, out_py)
    assert np.array_equal(remora.read_mesh(out_cli).V, P)
    # The edit moved the ear and nothing outside the support.
    outside = np.ones(len(P), bool)
    outside[support] = False
    assert np.array_equal(P[outside], bunny.V[outside])
    assert np.abs(P[handle] - bunny.V[handle]).max() > 0.01


def test_edit_with_k3_and_a_scale_matches_the_cli(bunny, cli, tmp_path):
    (sc, sr), (hc, hr) = EAR_SUPPORT, EAR_HANDLE
    out_cli = tmp_path / "cli.ply"
    run(cli, "edit", BUNNY, "-o", out_cli, "--k", "3", "--details", "displacement",
        "--support-sphere", ",".join(map(str, (*sc, sr))),
        "--handle-sphere", ",".join(map(str, (*hc, hr))), "--scale", "1.5,1,1")
    mask = np.zeros(len(bunny.V), bool)
    mask[remora.select_sphere(bunny.V, sc, sr)] = True  # the support as a boolean mask
    editor = remora.Editor(bunny.V, bunny.F, k=3, details="displacement")
    editor.set_region(mask, remora.select_sphere(bunny.V, hc, hr))
    editor.set_transform(0, np.vstack([remora.transform(editor.handle_center(0),
                                                        scale=(1.5, 1, 1)), [0, 0, 0, 1]]))
    out_py = tmp_path / "py.ply"
    remora.write_mesh(out_py, editor.positions(), bunny.F)
    assert_same_file(out_cli, out_py)


def test_nonlinear_edit_matches_the_cli_bit_for_bit(bunny, cli, tmp_path):
    # A rotation large enough for the iteration to matter: the nonlinear result differs from
    # the linear one, and both sides iterate to the same converged positions.
    (sc, sr), (hc, hr) = EAR_SUPPORT, EAR_HANDLE
    out_cli = tmp_path / "cli.ply"
    run(cli, "edit", BUNNY, "-o", out_cli, "--method", "nonlinear",
        "--support-sphere", ",".join(map(str, (*sc, sr))),
        "--handle-sphere", ",".join(map(str, (*hc, hr))), "--rotate", "0,0,1,90")
    editor = remora.Editor(bunny.V, bunny.F, method="nonlinear")
    support, handle = remora.select_sphere(bunny.V, sc, sr), remora.select_sphere(bunny.V, hc, hr)
    editor.set_region(support, [handle])
    editor.set_transform(0, remora.transform(editor.handle_center(0), rotate_axis=(0, 0, 1),
                                             rotate_degrees=90))
    P = editor.positions()
    assert editor.converged and editor.report()["nonlinear"]["iterations"] > 1
    out_py = tmp_path / "py.ply"
    remora.write_mesh(out_py, P, bunny.F)
    assert_same_file(out_cli, out_py)
    editor.set_method("linear")
    assert np.abs(editor.positions() - P).max() > 1e-3
