"""Meshes as numpy arrays: reading, writing, the repair of a soup, the quality figures against
`remora info`, and the vertex selections against their definitions."""

import json
import subprocess

import numpy as np
import pytest

import remora
from conftest import BUNNY, grid, octahedron


def test_read_mesh(bunny):
    V, F, report = bunny
    assert V.shape == (34834, 3) and V.dtype == np.float64 and V.flags.c_contiguous
    assert F.shape == (69451, 3) and F.dtype == np.int64 and F.flags.c_contiguous
    assert F.min() == 0 and F.max() == len(V) - 1
    assert report["format"] == "ply"
    assert report["repair"]["faces_loaded"] == len(F)


@pytest.mark.parametrize("suffix,binary", [(".ply", True), (".ply", False), (".obj", True), (".off", True)])
def test_write_and_read_round_trip_exactly(bunny, tmp_path, suffix, binary):
    path = tmp_path / f"bunny{suffix}"
    remora.write_mesh(path, bunny.V, bunny.F, binary=binary)
    back = remora.read_mesh(str(path))
    assert np.array_equal(back.V, bunny.V)
    # Writers start each triangle at its second corner (OpenMesh's face-vertex order): the same
    # triangles, each rotated once.
    assert np.array_equal(back.F, bunny.F[:, [1, 2, 0]])


def test_any_layout_and_array_like_is_accepted(bunny):
    # Fortran order, strided views, lists and tuples: converted once, same figures.
    V, F = bunny.V, bunny.F
    expected = remora.quality(V, F)
    wide = np.zeros((len(V), 6))
    wide[:, ::2] = V
    assert remora.quality(np.asfortranarray(V), np.asfortranarray(F)) == expected
    assert remora.quality(wide[:, ::2], F.astype(np.int32)) == expected
    small_V, small_F = octahedron()
    assert remora.quality(small_V.tolist(), tuple(map(tuple, small_F)))["faces"] == 8


def test_repair_leaves_a_clean_mesh_as_it_is(bunny):
    # arrays -> soup -> repaired mesh -> arrays keeps every vertex and corner in order.
    r = remora.remesh(bunny.V, bunny.F, cycles=1, max_cycles=1, equalize_iterations=0,
                      compute_report=False)
    again = remora.repair(r.V, r.F)
    assert np.array_equal(again.V, r.V) and np.array_equal(again.F, r.F)


def test_repair_welds_and_orients_a_soup():
    V, F = octahedron()
    # Every triangle with its own copies of its corners, and every other one flipped.
    soup_V = V[F].reshape(-1, 3)
    soup_F = np.arange(len(soup_V)).reshape(-1, 3)
    soup_F[::2] = soup_F[::2, ::-1]
    fixed = remora.repair(soup_V, soup_F)
    assert len(fixed.V) == 6 and len(fixed.F) == 8
    assert fixed.report["welded_vertices"] == len(soup_V) - 6
    assert fixed.report["flipped_faces"] == 4
    assert np.array_equal(fixed.V, soup_V[fixed.report["source_vertex"]])
    q = remora.quality(fixed.V, fixed.F)
    assert q["components"] == 1 and q["component_topology"][0]["closed"]


def test_quality_matches_remora_info(bunny, cli):
    out = subprocess.run([cli, "info", str(BUNNY), "--json"], check=True, capture_output=True,
                         text=True).stdout
    expected = json.loads(out)
    expected.pop("load")
    assert remora.quality(bunny.V, bunny.F) == expected


def test_selections(bunny):
    V = bunny.V
    centre, radius = np.array([-0.03, 0.15, 0.0]), 0.05
    ids = remora.select_sphere(V, centre, radius)
    d = np.linalg.norm(V - centre, axis=1)
    inside = np.flatnonzero(d <= radius)
    assert ids.dtype == np.int64 and np.all(np.diff(ids) > 0)
    # Equal but for vertices within round-off of the sphere.
    assert set(ids) ^ set(inside) <= set(np.flatnonzero(np.abs(d - radius) < 1e-12))
    lo, hi = np.array([-0.05, 0.1, -0.02]), np.array([0.0, 0.2, 0.03])
    box = remora.select_box(V, lo, hi)
    assert np.array_equal(box, np.flatnonzero(np.all((V >= lo) & (V <= hi), axis=1)))
    assert remora.nearest_vertex(V, centre) == np.argmin(d)


def test_geodesic_disc_on_a_plane_is_round():
    V, F = grid(40)
    seed = remora.nearest_vertex(V, (0.5, 0.5, 0))
    disc = remora.select_geodesic_disc(V, F, seed, 0.3)
    d = np.linalg.norm(V[:, :2] - 0.5, axis=1)
    assert set(np.flatnonzero(d < 0.28)) <= set(disc) <= set(np.flatnonzero(d <= 0.3 + 1e-9))
    with pytest.raises(ValueError, match="radius"):
        remora.select_geodesic_disc(V, F, seed, -1.0)


def test_refine_region_splits_long_edges_on_the_surface():
    # An octahedron's upper half refined to edges of at most 0.3: the old vertices stay, every
    # new one lies on the surface (|x| + |y| + |z| = 1), the lower half is untouched, and every
    # edge between two region vertices is at most 0.3 long; the lower apex stays out.
    V, F = octahedron()
    upper = [0, 1, 2, 3, 4]
    r = remora.refine_region(V, F, upper, max_length=0.3)
    assert r.added == len(r.V) - len(V) > 0
    assert np.array_equal(r.V[: len(V)], V)
    assert np.allclose(np.abs(r.V).sum(axis=1), 1.0)
    assert set(range(len(V), len(r.V))) <= set(r.region.tolist())
    assert 5 not in r.region
    inside = np.zeros(len(r.V), bool)
    inside[r.region] = True
    for a, b in [(0, 1), (1, 2), (2, 0)]:
        e = r.F[:, [a, b]]
        both = inside[e[:, 0]] & inside[e[:, 1]]
        lengths = np.linalg.norm(r.V[e[both, 0]] - r.V[e[both, 1]], axis=1)
        assert lengths.max() <= 0.3 + 1e-12
    with pytest.raises(ValueError, match="max_length"):
        remora.refine_region(V, F, upper, max_length=0.0)
    with pytest.raises(ValueError, match="would pass 10 vertices"):
        remora.refine_region(V, F, upper, max_length=0.3, max_vertices=10)
    with pytest.raises(ValueError, match="region"):
        remora.refine_region(V, F, [0, 99], max_length=0.3)
