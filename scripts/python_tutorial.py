#!/usr/bin/env python3
"""Runs the tutorial of docs/python.md: its ```python blocks in the section "Tutorial", in
order, as one script, in a scratch folder that holds the repository's data/; then copies the
picture the tutorial saves (python_tutorial.png) to --out.

    PYTHONPATH=build/python /usr/bin/python3 scripts/python_tutorial.py \\
        --out docs/images/python_tutorial.png

`make pictures` runs it; the test Python.test_docs runs it with --out in a temporary folder.
"""

import argparse
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
PICTURE = "python_tutorial.png"


def tutorial_code(markdown: str) -> str:
    """The ```python blocks of the section "## Tutorial", joined."""
    parts = re.split(r"^## ", markdown, flags=re.M)
    section = next((p for p in parts if p.startswith("Tutorial\n")), None)
    if section is None:
        raise SystemExit("python_tutorial: docs/python.md has no section '## Tutorial'")
    blocks = re.findall(r"^```python\n(.*?)^```", section, flags=re.M | re.S)
    if not blocks:
        raise SystemExit("python_tutorial: the tutorial has no ```python block")
    return "\n".join(blocks)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--doc", default=str(ROOT / "docs" / "python.md"))
    parser.add_argument("--out", help="where to copy the picture (PNG)")
    args = parser.parse_args()
    code = tutorial_code(pathlib.Path(args.doc).read_text())
    with tempfile.TemporaryDirectory(prefix="remora-tutorial-") as scratch:
        folder = pathlib.Path(scratch)
        (folder / "data").symlink_to(ROOT / "data")
        script = folder / "tutorial.py"
        script.write_text(code)
        env = dict(os.environ, MPLBACKEND="Agg")
        # The tutorial runs elsewhere: a relative PYTHONPATH (build/python) must still reach.
        paths = env.get("PYTHONPATH", "").split(os.pathsep)
        env["PYTHONPATH"] = os.pathsep.join(os.path.abspath(p) for p in paths if p)
        subprocess.run([sys.executable, str(script)], cwd=folder, env=env, check=True)
        picture = folder / PICTURE
        if not picture.exists():
            raise SystemExit(f"python_tutorial: the tutorial saved no {PICTURE}")
        if args.out:
            shutil.copyfile(picture, args.out)
            print(f"python_tutorial: wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
