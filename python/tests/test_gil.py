"""Long calls release the GIL: another Python thread runs while the library works."""

import sys
import threading
import time

import remora


def test_remesh_releases_the_gil(bunny):
    # With a switch interval of 100 s the interpreter never takes the GIL from a thread that
    # holds it; the main thread can only run while the worker is inside the library if the
    # binding let the GIL go. It then sees the worker's progress between two phases.
    calls = []
    started = threading.Event()

    def progress(phase, step, steps):
        calls.append(phase)
        started.set()

    seen = []
    worker = threading.Thread(
        target=lambda: remora.remesh(bunny.V, bunny.F, compute_report=False, progress=progress)
    )
    previous = sys.getswitchinterval()
    sys.setswitchinterval(100.0)
    try:
        worker.start()
        started.wait()
        while worker.is_alive():
            seen.append(len(calls))
            time.sleep(0.001)
        worker.join()
    finally:
        sys.setswitchinterval(previous)
    assert len(calls) > 10
    assert any(0 < c < len(calls) for c in seen), "the main thread never ran during remesh()"
