"""`pip install . --no-build-isolation` from the repository root, offline, into a throwaway
virtual environment that sees Debian's numpy (--system-site-packages): the installed package
imports from outside the clone and works. It packages the module of the build tree ctest runs
in (REMORA_CMAKE_BUILD_DIR, setup.py), so nothing is compiled again."""

import os
import pathlib
import subprocess
import sys

import pytest

from conftest import SOURCE_DIR


def test_pip_install_into_a_virtual_environment(tmp_path):
    build_dir = os.environ.get("REMORA_BUILD_DIR")
    if not build_dir:
        pytest.skip("REMORA_BUILD_DIR is not set (ctest sets it)")
    venv = tmp_path / "venv"
    # pip itself comes from the system site-packages, so the environment needs none of its own.
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", "--without-pip",
                    str(venv)], check=True)
    python = venv / "bin" / "python"
    env = dict(os.environ, REMORA_CMAKE_BUILD_DIR=build_dir, PIP_NO_INDEX="1",
               PIP_DISABLE_PIP_VERSION_CHECK="1")
    env.pop("PYTHONPATH", None)
    subprocess.run([str(python), "-m", "pip", "install", "--no-build-isolation", "--no-deps",
                    "--quiet", str(SOURCE_DIR)], check=True, env=env, cwd=tmp_path)
    check = (
        "import numpy as np, remora\n"
        "V, F, _ = remora.read_mesh(%r)\n"
        "r = remora.remesh(V, F, cycles=1, max_cycles=1, equalize_iterations=0, compute_report=False)\n"
        "print(remora.__file__, remora.__version__, len(r.F) > 0)\n"
    ) % str(SOURCE_DIR / "data" / "bunny.ply")
    out = subprocess.run([str(python), "-c", check], check=True, env=env, cwd=tmp_path,
                         capture_output=True, text=True).stdout.split()
    assert pathlib.Path(out[0]).is_relative_to(venv), out
    assert out[2] == "True"
    # The source tree is left as it was: setuptools' scratch went into the build tree.
    assert not (SOURCE_DIR / "remora.egg-info").exists()
    assert not (SOURCE_DIR / "python" / "remora.egg-info").exists()
