"""The metric constraint: welding within ε, never beyond it."""

import numpy as np
import pytest

from barymesh import MeshParams, build_mesh
from barymesh.weld import merge_pairs, weld_lattice_patches, weld_points

EPS = 1e-6


@pytest.mark.parametrize("centre", [0.0, 0.5e-6, 1e-6, 1.5e-6, 2.5e-6, 1.0, 1000.0 + 0.5e-6])
def test_points_within_eps_merge_across_any_rounding_boundary(centre):
    # two points 0.9 ε apart, straddling multiples of ε (a snapping grid would split them)
    pts = np.array([[centre - 0.45 * EPS, 0.0], [centre + 0.45 * EPS, 0.0]])
    ids, rep = weld_points(pts, EPS)
    assert ids.tolist() == [0, 0] and rep.tolist() == [0]


@pytest.mark.parametrize("gap", [1.01, 1.5, 3.0])
def test_points_farther_than_eps_never_merge(gap):
    pts = np.array([[0.0, 0.0], [gap * EPS, 0.0], [0.0, -gap * EPS]])
    ids, _ = weld_points(pts, EPS)
    assert ids.tolist() == [0, 1, 2]


def test_chains_longer_than_eps_are_refused():
    pts = np.array([[0.0, 0.0], [0.8 * EPS, 0.0], [1.6 * EPS, 0.0]])
    with pytest.raises(
        ValueError,
        match=r"tolerance=1e-06 mm joins a chain of near points .* "
        r"use a smaller tolerance",
    ):
        weld_points(pts, EPS)


def test_tight_cluster_of_three_merges():
    pts = np.array([[0.0, 0.0], [0.5 * EPS, 0.0], [0.25 * EPS, 0.4 * EPS], [5.0, 5.0]])
    ids, rep = weld_points(pts, EPS)
    assert ids.tolist() == [0, 0, 0, 1] and rep.tolist() == [0, 3]


def test_merge_pairs_numbers_in_first_appearance_order():
    ids, rep = merge_pairs(6, np.array([[5, 2], [4, 0]]))
    assert ids.tolist() == [0, 1, 2, 3, 0, 2] and rep.tolist() == [0, 1, 2, 3]


def _lattice_vs_kdtree(origins, h, n, eps):
    ids_l, rep_l = weld_lattice_patches(origins, (h / n, h / n), n, eps)
    a, b = np.meshgrid(np.arange(n + 1), np.arange(n + 1))
    grid = np.stack([a.ravel(), b.ravel()], 1) * (h / n)
    pts = (origins[:, None, :] + grid[None]).reshape(-1, 2)
    ids_k, rep_k = weld_points(pts, eps)
    assert np.array_equal(ids_l, ids_k) and np.array_equal(rep_l, rep_k)
    return ids_l


@pytest.mark.parametrize("dx", [1.0, 1.0 + 0.6 * EPS, 1.0 - 0.6 * EPS, 0.5, 0.25 + 0.3 * EPS])
def test_lattice_weld_of_touching_and_overlapping_patches(dx):
    ids = _lattice_vs_kdtree(np.array([[0.0, 0.0], [dx, 0.0]]), 1.0, 4, EPS)
    shared = 25 + 25 - len(np.unique(ids))
    assert shared == 5 * (4 - round(dx * 4) + 1)


def test_lattice_weld_does_not_merge_beyond_eps():
    ids = _lattice_vs_kdtree(np.array([[0.0, 0.0], [1.0 + 1.5 * EPS, 0.0]]), 1.0, 4, EPS)
    assert len(np.unique(ids)) == 50


def test_lattice_weld_matches_kdtree_on_a_dense_paper_ring():
    mesh = build_mesh(MeshParams(structure="ring", angle_step=3, tolerance=1e-3))
    origins = mesh.patch_rects[:, :2]
    _lattice_vs_kdtree(origins, 1.0, 4, 1e-3)


def test_tiled_patches_weld_into_one_mesh():
    """A paper-mode square ring whose sides are whole multiples of h tiles exactly."""
    mesh = build_mesh(
        MeshParams(
            structure="square_split_double_ring",
            inner_radius=4,
            outer_radius=6,
            patch_size=1,
            gap_width=1,
        )
    )
    s = mesh.stats()
    assert s["overlap_ratio"] == pytest.approx(0.0)
    assert s["junction_edges"] == 0
    assert s["euler_characteristic"] == 4


def test_paper_patches_that_share_a_side_are_welded():
    p = MeshParams(structure="ring", angle_step=180, inner_radius=0.5, patch_size=1.0)
    mesh = build_mesh(p)
    # patches at (0.5, 0) and (-0.5, 0): offset 1.0 = one patch: they share a side
    assert mesh.n_vertices == 2 * 25 - 5
    assert mesh.stats()["interior_edges"] == 2 * 40 + 4
