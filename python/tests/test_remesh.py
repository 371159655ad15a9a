"""remesh() from Python: the paper's targets (edge band, area spread), the correspondence both
ways as arrays, determinism, and the report."""

import numpy as np

import remora


def edge_lengths(V, F):
    E = np.unique(np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1), axis=0)
    return np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1)


def test_remesh_of_the_bunny(bunny):
    r = remora.remesh(bunny.V, bunny.F)
    assert r.V.dtype == np.float64 and r.F.dtype == np.int64
    assert r.V.flags.c_contiguous and r.F.flags.c_contiguous
    l = r.report["target_length"]
    assert 0.85 * edge_lengths(bunny.V, bunny.F).mean() < l < 0.95 * edge_lengths(bunny.V, bunny.F).mean()
    lengths = edge_lengths(r.V, r.F)
    in_band = np.mean((lengths >= 0.8 * l) & (lengths <= 4 / 3 * l))
    assert in_band > 0.95
    assert abs(100 * in_band - r.report["edges_in_band_percent"]["output"]) < 0.01
    # The area spread shrinks: the paper's point (section 4).
    assert (r.report["after_equalization"]["vertex_area_mixed"]["rel_mad"]
            < 0.5 * r.report["input"]["vertex_area_mixed"]["rel_mad"])
    # Output on input: every new vertex is where its surface point on the input says (projected).
    on_input = r.output_on_input.evaluate(bunny.V, bunny.F)
    assert np.abs(on_input - r.V).max() < 1e-9
    assert np.all(r.output_on_input.face >= 0)
    assert np.allclose(r.output_on_input.bary.sum(axis=1), 1.0)
    # Input on output: each input vertex's closest point on the new mesh. No output vertex is
    # closer (checked by brute force on a sample), and most are within a small part of l.
    assert np.allclose(r.input_on_output.bary.sum(axis=1), 1.0)
    on_output = r.input_on_output.evaluate(r.V, r.F)
    distance = np.linalg.norm(on_output - bunny.V, axis=1)
    sample = np.random.default_rng(5).choice(len(bunny.V), 300, replace=False)
    nearest = np.array([np.linalg.norm(r.V - bunny.V[i], axis=1).min() for i in sample])
    assert np.all(distance[sample] <= nearest + 1e-12)
    assert np.median(distance) < 0.05 * l


def test_deterministic_whatever_the_threads(bunny):
    a = remora.remesh(bunny.V, bunny.F, threads=1, compute_report=False)
    b = remora.remesh(bunny.V, bunny.F, threads=2, compute_report=False)
    assert np.array_equal(a.V, b.V) and np.array_equal(a.F, b.F)
    assert np.array_equal(a.input_on_output.bary, b.input_on_output.bary)
    assert set(a.report["milliseconds"]) >= {"split", "collapse", "flip", "total"}
    assert "input" not in a.report or a.report["input"]["faces"] == 0


def test_the_input_is_not_changed(bunny):
    V, F = bunny.V.copy(), bunny.F.copy()
    remora.remesh(V, F, cycles=1, max_cycles=1, equalize_iterations=0, compute_report=False)
    assert np.array_equal(V, bunny.V) and np.array_equal(F, bunny.F)


def test_progress_is_reported(bunny):
    phases = []
    remora.remesh(bunny.V, bunny.F, cycles=2, max_cycles=2, equalize_iterations=2,
                  compute_report=False, progress=lambda *p: phases.append(p))
    assert ("remesh", 0, 2) in phases and ("equalize", 1, 2) in phases
    assert phases[-1][0] == "correspondence"


def test_low_pass_smooths_and_keeps_the_connectivity(bunny):
    S, stats = remora.low_pass(bunny.V, bunny.F, smoothing=2.0)
    assert S.shape == bunny.V.shape and stats["sigma"] > 0
    # Smoothing lowers the total squared edge length (the Dirichlet energy of the positions).
    assert (edge_lengths(S, bunny.F) ** 2).sum() < (edge_lengths(bunny.V, bunny.F) ** 2).sum()
    same, _ = remora.low_pass(bunny.V, bunny.F, smoothing=0.0)
    assert np.array_equal(same, bunny.V)
