"""The weld against brute force: all pairwise distances, groups joined by union-find.

``weld_lattice_patches`` finds candidate patch pairs on a periodic k-d tree and pairs their
grid points by lattice offsets; the reference looks at every pair of points. Both must give
the same vertex numbering (first appearance), or both refuse a chain whose ends are farther
apart than the tolerance.
"""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from barymesh.topology import INDEX
from barymesh.weld import merge_pairs, weld_lattice_patches, weld_points


def brute_force_weld(coords, tolerance):
    """(vertex_of_point, representative) by all pairs, or None when a group is too wide."""
    n = len(coords)
    dist = np.linalg.norm(coords[:, None] - coords[None], axis=-1)
    parent = list(range(n))

    def root(k):
        while parent[k] != k:
            k = parent[k]
        return k

    for a, b in zip(*np.nonzero(np.triu(dist <= tolerance, 1)), strict=True):
        ra, rb = root(int(a)), root(int(b))
        parent[max(ra, rb)] = min(ra, rb)
    label = [root(k) for k in range(n)]
    for g in set(label):
        members = [k for k in range(n) if label[k] == g]
        if dist[np.ix_(members, members)].max() > tolerance:
            return None
    representative = sorted(set(label))
    new_id = {r: i for i, r in enumerate(representative)}
    return np.array([new_id[r] for r in label]), np.array(representative)


def lattice_points(origins, step, n):
    a = np.tile(np.arange(n + 1), n + 1)
    b = np.repeat(np.arange(n + 1), n + 1)
    local = np.stack([a * step[0], b * step[1]], axis=1)
    return (origins[:, None, :] + local[None]).reshape(-1, 2)


@st.composite
def patch_arrays(draw):
    """Patches on one lattice, each moved by a few steps plus a small jitter.

    The jitter straddles zero, so the fractional lattice coordinates of the origins sit on
    both sides of the wrap from 1 to 0 (the periodic axes of the candidate search), and the
    lattice is anchored at a negative corner.
    """
    n = draw(st.integers(1, 3))
    step = (draw(st.sampled_from([0.5, 1.0, 1.5])), draw(st.sampled_from([0.5, 1.0, 2.0])))
    tolerance = draw(st.sampled_from([0.05, 0.1, 0.2]))
    count = draw(st.integers(1, 5))
    cells = draw(
        st.lists(st.tuples(st.integers(-3, 3), st.integers(-3, 3)), min_size=count, max_size=count)
    )
    jitter = draw(
        st.lists(
            st.tuples(
                st.sampled_from([-0.15, -0.04, 0.0, 0.03, 0.12]),
                st.sampled_from([-0.07, 0.0, 0.02, 0.15]),
            ),
            min_size=count,
            max_size=count,
        )
    )
    corner = np.array([-7.25, -3.5])
    origins = corner + np.array(cells) * step + np.array(jitter)
    return origins, step, n, tolerance


@given(patch_arrays())
def test_lattice_weld_equals_brute_force(case):
    origins, step, n, tolerance = case
    ref = brute_force_weld(lattice_points(origins, step, n), tolerance)
    if ref is None:
        with pytest.raises(ValueError, match="tolerance"):
            weld_lattice_patches(origins, step, n, tolerance)
        return
    ids, rep = weld_lattice_patches(origins, step, n, tolerance)
    assert ids.tolist() == ref[0].tolist()
    assert rep.tolist() == ref[1].tolist()
    assert ids.dtype == rep.dtype == INDEX


@given(patch_arrays())
def test_point_weld_equals_brute_force(case):
    origins, step, n, tolerance = case
    coords = lattice_points(origins, step, n)
    ref = brute_force_weld(coords, tolerance)
    if ref is None:
        with pytest.raises(ValueError, match="tolerance"):
            weld_points(coords, tolerance)
        return
    ids, rep = weld_points(coords, tolerance)
    assert ids.tolist() == ref[0].tolist() and rep.tolist() == ref[1].tolist()


def test_one_patch_and_far_patches_keep_every_point():
    for origins in ([[0.0, 0.0]], [[0.0, 0.0], [100.0, 0.0]], [[0.0, 0.0], [0.3, 0.3]]):
        ids, rep = weld_lattice_patches(np.array(origins), (1.0, 1.0), 2, 0.1)
        assert ids.tolist() == list(range(9 * len(origins)))
        assert rep.tolist() == list(range(9 * len(origins)))


def test_points_exactly_the_tolerance_apart_are_one_vertex():
    """'At most ε' welds: a group 1 wide is accepted with ε = 1 (binary-exact numbers)."""
    ids, rep = weld_points(np.array([[0.0, 0.0], [0.5, 0.0], [1.0, 0.0], [5.0, 5.0]]), 1.0)
    assert ids.tolist() == [0, 0, 0, 1] and rep.tolist() == [0, 3]


def test_a_chain_around_the_origin_is_refused_and_located():
    """Ends 2 apart with ε = 1.2; the group's bounding box is centred on (0, 0)."""
    coords = np.array([[10.0, 10.0], [10.5, 10.0], [-1.0, 0.0], [0.0, 0.0], [1.0, 0.0]])
    with pytest.raises(ValueError, match=r"tolerance=1\.2 .* near \(0, 0\) whose ends are 2 mm"):
        weld_points(coords, 1.2)
    shifted = coords + [3.0, -4.0]
    with pytest.raises(ValueError, match=r"near \(3, -4\) whose ends are 2 mm"):
        weld_points(shifted, 1.2)


def test_merge_pairs_numbers_vertices_by_first_appearance():
    ids, rep = merge_pairs(6, np.array([[5, 2], [4, 0], [2, 4]]))
    assert ids.tolist() == [0, 1, 0, 2, 0, 0] and rep.tolist() == [0, 1, 3]
    assert ids.dtype == rep.dtype == INDEX
    ids, rep = merge_pairs(3, np.empty((0, 2), dtype=np.int64))
    assert ids.tolist() == rep.tolist() == [0, 1, 2]


def test_a_group_exactly_the_tolerance_wide_inside_a_wider_box_is_accepted():
    """Bounding box 1 x 0.5 (diagonal above ε = 1), farthest pair exactly 1 apart."""
    ids, _ = weld_points(np.array([[0.0, 0.0], [1.0, 0.0], [0.5, 0.5]]), 1.0)
    assert ids.tolist() == [0, 0, 0]


def test_a_chain_of_lattice_patches_is_refused():
    """Patch origins 0, 0.15, 0.27 apart along x with ε = 0.2: neighbours weld, ends do not."""
    origins = np.array([[0.0, 0.0], [0.15, 0.0], [0.27, 0.0]])
    assert brute_force_weld(lattice_points(origins, (1.0, 1.0), 1), 0.2) is None
    with pytest.raises(ValueError, match="whose ends are 0.27 mm apart"):
        weld_lattice_patches(origins, (1.0, 1.0), 1, 0.2)


def test_an_origin_just_below_a_lattice_line_welds():
    """-1e-17 - floor(-1e-17) rounds to a fractional part of exactly 1.0, which is 0 here."""
    origins = np.array([[-1e-17, 0.0], [1.0, 0.0]])
    ids, rep = weld_lattice_patches(origins, (1.0, 1.0), 1, 0.1)
    ref = brute_force_weld(lattice_points(origins, (1.0, 1.0), 1), 0.1)
    assert ids.tolist() == ref[0].tolist() and rep.tolist() == ref[1].tolist()
    assert len(rep) == 6  # two 2 x 2 grids sharing one side
