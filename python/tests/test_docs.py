"""The documentation's code runs: the Python tutorial of docs/python.md (with its picture),
and the consumer example of docs/cpp.md is the one Package.Consumer builds."""

import os
import re
import struct
import subprocess
import sys

from conftest import SOURCE_DIR


def png_size(path):
    data = path.read_bytes()[:24]
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is no PNG"
    return struct.unpack(">II", data[16:24])


def test_the_python_tutorial_runs_and_draws(tmp_path):
    out = tmp_path / "tutorial.png"
    subprocess.run([sys.executable, str(SOURCE_DIR / "scripts" / "python_tutorial.py"),
                    "--out", str(out)], check=True, env=dict(os.environ))
    assert png_size(out) == (1200, 440)
    doc = (SOURCE_DIR / "docs" / "python.md").read_text()
    assert "(images/python_tutorial.png)" in doc
    assert png_size(SOURCE_DIR / "docs" / "images" / "python_tutorial.png") == (1200, 440)


def test_the_cpp_page_shows_the_consumer_example():
    doc = (SOURCE_DIR / "docs" / "cpp.md").read_text()
    blocks = re.findall(r"^```(\w+)\n(.*?)^```", doc, flags=re.M | re.S)
    example = SOURCE_DIR / "examples" / "consumer"
    shown = {lang: code for lang, code in blocks if lang in ("cmake", "cpp")}
    assert shown["cmake"] == (example / "CMakeLists.txt").read_text()
    assert shown["cpp"] == (example / "main.cpp").read_text()
