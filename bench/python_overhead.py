#!/usr/bin/env python3
"""Python's overhead over the C++ library (docs/benchmarks.md, "Python"), measured in one process
against the library's own clock:

- remesh: the wall time of remora.remesh(V, F) against the C++ call inside it
  (report["milliseconds"]["library_call"]): the difference is the conversion of the arrays in and
  out. Goal: at most 5 % of the call on the bunny.
- a frame: the wall time of editor.set_transform(0, T) + editor.positions() against the
  editor's own frame (report["milliseconds"]["frame"]: blend, normals, decode), on a support of
  --support input vertices around the mesh's centre (the innermost 3 % the handle), moves
  alternating as in `remora bench edit`; into a preallocated array (out=) and a new one. And
  the Python layer alone: the same calls when the library has nothing to compute. Goal: at most
  0.2 ms per frame.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_overhead.py [MESH] [--runs 5] \\
        [--frames 200] [--support 31000]

Prints a table and, last, one JSON line. Not a test: timings are never asserted.
"""

import argparse
import json
import pathlib
import statistics
import subprocess
import time

import numpy as np

import remora

ROOT = pathlib.Path(__file__).resolve().parents[1]


def remesh_overhead(V, F, runs):
    remora.remesh(V, F, compute_report=False)  # warm-up: page faults, thread start
    walls, calls = [], []
    for _ in range(runs):
        t0 = time.perf_counter()
        r = remora.remesh(V, F, compute_report=False)
        walls.append(1e3 * (time.perf_counter() - t0))
        calls.append(r.report["milliseconds"]["library_call"])
    over = [w - c for w, c in zip(walls, calls)]
    return {
        "remesh_wall_ms": statistics.median(walls),
        "remesh_call_ms": statistics.median(calls),
        "remesh_overhead_ms": statistics.median(over),
        "remesh_overhead_percent": 100 * statistics.median(o / c for o, c in zip(over, calls)),
    }


def frame_overhead(V, F, support_size, frames):
    centre = V.mean(axis=0)
    order = np.argsort(np.linalg.norm(V - centre, axis=1), kind="stable")
    support = order[:support_size]
    handle = support[: max(1, support_size * 3 // 100)]
    editor = remora.Editor(V, F)
    editor.set_region(support, [handle])
    c = editor.handle_center(0)
    scale = np.ptp(V, axis=0).max()
    moves = [
        remora.transform(c, translate=(0, 0.01 * scale, 0)),
        remora.transform(c, rotate_axis=(0, 0, 1), rotate_degrees=10, translate=(0.005 * scale, 0, 0)),
    ]
    out = np.empty((len(V), 3))
    result = {"support_vertices": int(len(support)),
              "free_base_vertices": editor.report()["region"]["free_base_vertices"]}
    for label, target in (("out", out), ("new", None)):
        walls, cpp = [], []
        for i in range(frames + 5):
            t0 = time.perf_counter()
            editor.set_transform(0, moves[i % 2])
            editor.positions(out=target)
            wall = 1e3 * (time.perf_counter() - t0)
            if i >= 5:  # warm-up
                walls.append(wall)
                cpp.append(editor.report()["milliseconds"]["frame"])
        result[f"frame_{label}_wall_ms"] = statistics.median(walls)
        result[f"frame_{label}_cpp_ms"] = statistics.median(cpp)
        result[f"frame_{label}_overhead_ms"] = statistics.median(w - c for w, c in zip(walls, cpp))
    # The Python layer alone: set_transform (its C++ part checks the matrix and stores it), then
    # positions() on an editor with nothing to compute (update() returns at once and the stored
    # positions are handed back): argument checks, the GIL released and taken back, the lock,
    # the copy into numpy.
    walls = []
    for _ in range(frames):
        t0 = time.perf_counter()
        editor.set_transform(0, moves[0])
        walls.append(1e3 * (time.perf_counter() - t0))
    result["binding_set_transform_ms"] = statistics.median(walls)
    editor.positions()
    for label, target in (("out", out), ("new", None)):
        walls = []
        for _ in range(frames):
            t0 = time.perf_counter()
            editor.positions(out=target)
            walls.append(1e3 * (time.perf_counter() - t0))
        result[f"binding_positions_{label}_ms"] = statistics.median(walls)
    return result


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("mesh", nargs="?", default=str(ROOT / "data" / "bunny.ply"))
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--frames", type=int, default=200)
    parser.add_argument("--support", type=int, default=31000)
    args = parser.parse_args()
    V, F, _ = remora.read_mesh(args.mesh)
    figures = {"mesh": pathlib.Path(args.mesh).name, "vertices": len(V), "faces": len(F)}
    figures.update(remesh_overhead(V, F, args.runs))
    figures.update(frame_overhead(V, F, min(args.support, len(V)), args.frames))
    try:
        figures["commit"] = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                                           capture_output=True, text=True).stdout.strip()
    except OSError:
        pass
    for key, value in figures.items():
        print(f"{key:28} {value:.4g}" if isinstance(value, float) else f"{key:28} {value}")
    print(json.dumps(figures))


if __name__ == "__main__":
    main()
