"""Invariants of pixel cells on random masks: mesh topology, outline and tiling agree."""

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from core.cell import Lattice, PixelGrid, UnitCell, build_cell, tile
from core.cell.outline import outline_polygons

SETTINGS = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])

masks = st.tuples(st.integers(1, 6), st.integers(1, 6)).flatmap(
    lambda shape: arrays(bool, shape).filter(lambda m: m.any())
)


def cell_of(mask, n=1, mode="paper"):
    r, c = mask.shape
    grid = PixelGrid(mask, pixel_size=0.5, origin=(-0.25 * c, -0.25 * r), subdivisions=n)
    return UnitCell(Lattice.rectangular(0.5 * c, 0.5 * r), pixels=grid, mode=mode)


@SETTINGS
@given(masks, st.sampled_from([1, 2]), st.sampled_from(["paper", "conforming"]))
def test_pixel_mesh_counts_and_euler_characteristic(mask, n, mode):
    cell = cell_of(mask, n, mode)
    cm = build_cell(cell)
    s = cm.mesh.stats()
    k = int(mask.sum())
    assert s["triangles"] == 2 * n * n * k
    assert s["junction_edges"] == 0
    assert np.isclose(s["area"], 0.25 * k)
    # every pixel side shared by two set pixels is glued: n interior edges each
    shared = int((mask[:, 1:] & mask[:, :-1]).sum() + (mask[1:] & mask[:-1]).sum())
    assert s["boundary_edges"] == n * (4 * k - 2 * shared)
    # V - E + F = pieces - holes, minus one for every corner-only contact (a pinch vertex)
    polys = outline_polygons(cell)
    holes = sum(len(p.holes) for p in polys)
    contacts = len(cell.pixels.corner_contacts())
    assert s["euler_characteristic"] == len(polys) - holes - contacts
    assert np.isclose(sum(p.area for p in polys), 0.25 * k)
    assert all(len(p.outer) >= 4 and len(p.outer) % 2 == 0 for p in polys)  # rectilinear


@SETTINGS
@given(masks, st.integers(1, 3), st.integers(1, 3))
def test_tiling_glues_exactly_the_periodic_edge_pairs(mask, n1, n2):
    cm = build_cell(cell_of(mask))
    arr = tile(cm, n1, n2)
    s, a = cm.mesh.stats(), arr.mesh.stats()
    pairs = cm.periodic_pairs
    rows_match = np.array_equal(mask[0], mask[-1])
    cols_match = np.array_equal(mask[:, 0], mask[:, -1])
    assert pairs.matched == (rows_match and cols_match)
    m1, m2 = np.bincount(pairs.edge_shift, minlength=2).tolist()
    assert m1 == int((mask[:, 0] & mask[:, -1]).sum()) and m2 == int((mask[0] & mask[-1]).sum())
    seams = (n1 - 1) * n2 * m1 + n1 * (n2 - 1) * m2
    assert a["triangles"] == n1 * n2 * s["triangles"]
    assert a["interior_edges"] == n1 * n2 * s["interior_edges"] + seams
    assert a["junction_edges"] == 0
