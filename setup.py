"""Builds the Python package `remora` with CMake: `pip install . --no-build-isolation`.

The compiled module remora._remora is the CMake target _remora (python/CMakeLists.txt), built
for the interpreter running pip. By default a Release build is configured in build-pip/ (only the
library and the module are compiled; ccache is used when CMAKE_CXX_COMPILER_LAUNCHER=ccache is in
the environment). REMORA_CMAKE_BUILD_DIR=DIR packages the module of an existing build tree
instead, which must have built the target _remora for the same Python (`make test` installs the
release build's module this way).
"""

import os
import pathlib
import re
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = pathlib.Path(__file__).resolve().parent


def project_version() -> str:
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(remora VERSION ([0-9.]+)", text).group(1)


def configure_and_build(build_dir: pathlib.Path) -> None:
    configure = [
        "cmake", "-S", str(ROOT), "-B", str(build_dir),
        "-DCMAKE_BUILD_TYPE=Release",
        f"-DPython3_EXECUTABLE={sys.executable}",
        "-DREMORA_BUILD_TESTS=OFF", "-DREMORA_BUILD_BENCH=OFF", "-DREMORA_BUILD_WEB=OFF",
    ]
    subprocess.run(configure, check=True)
    jobs = os.environ.get("REMORA_JOBS", str(os.cpu_count() or 1))
    subprocess.run(["cmake", "--build", str(build_dir), "--target", "_remora", "-j", jobs],
                   check=True)


GIVEN_BUILD_DIR = os.environ.get("REMORA_CMAKE_BUILD_DIR")
BUILD_DIR = pathlib.Path(GIVEN_BUILD_DIR).resolve() if GIVEN_BUILD_DIR else ROOT / "build-pip"
# setuptools' scratch (its build/ and the egg-info) goes into the CMake build tree, never into
# the source tree, whose build/ is CMake's.
SCRATCH = BUILD_DIR / "setuptools"
SCRATCH.mkdir(parents=True, exist_ok=True)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        target = pathlib.Path(self.get_ext_fullpath(ext.name)).resolve()
        build_dir = BUILD_DIR
        if not GIVEN_BUILD_DIR:
            configure_and_build(build_dir)
        built = build_dir / "python" / "remora" / ("_remora" + sysconfig.get_config_var("EXT_SUFFIX"))
        if not built.exists():
            sys.exit(f"setup.py: {built} does not exist: build the CMake target _remora in "
                     f"{build_dir} for this Python ({sys.executable}) first")
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built, target)


setup(
    version=project_version(),
    packages=["remora"],
    package_dir={"remora": "python/remora"},
    ext_modules=[Extension("remora._remora", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
    options={"build": {"build_base": str(SCRATCH)}, "egg_info": {"egg_base": str(SCRATCH)}},
)
