"""The fast paths taken for speed give exactly what the general paths give."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from core import MeshParams
from core.structures import _paper_origins
from core.weld import _lattice_candidates, _window_candidates, merge_pairs


def kd_tree_candidates(origins, frac, reach, radius):
    """The k-d tree search of ``_lattice_candidates`` alone (balanced tree)."""
    scaled = (origins - origins.min(axis=0)) / reach * radius
    span = float(scaled.max(initial=0.0))
    box = np.array([1.0, 1.0, 3 * span + 1.0, 3 * span + 1.0])
    tree = cKDTree(np.concatenate([frac, scaled], axis=1), boxsize=box)
    return tree.query_pairs(radius * 1.000001, p=np.inf, output_type="ndarray")


def lattice_inputs(origins, n, step, tolerance):
    steps = np.array([step, step])
    scaled = origins / steps
    frac = scaled - np.floor(scaled)
    frac[frac >= 1.0] = 0.0
    return origins, frac, n * steps + tolerance, tolerance / step * 1.000001


def pair_set(pairs):
    return set(map(tuple, np.sort(pairs, axis=1).tolist()))


@pytest.mark.parametrize("angle_step", [0.01, 0.5, 90.0])
def test_window_candidates_of_paper_rings_equal_the_kd_tree(angle_step):
    params = MeshParams(structure="double_ring", mode="paper", angle_step=angle_step)
    origins = _paper_origins(params)[0]
    args = lattice_inputs(origins, 4, 0.25, params.weld_tolerance)
    assert pair_set(_lattice_candidates(*args)) == pair_set(kd_tree_candidates(*args))


@pytest.mark.parametrize("seed", range(4))
def test_window_candidates_with_phases_across_the_period_equal_the_kd_tree(seed):
    # scattered origins, plus pairs whose lattice phases sit just above 0 and just below 1
    # three lattice steps apart: the sorted window must wrap around the period to pair them
    rng = np.random.default_rng(seed)
    scattered = rng.uniform(0, 100, (2000, 2))
    base = rng.integers(0, 100, (30, 2)).astype(float)
    low = base + [1e-12, 0.0]
    high = base + [3 - 1e-12, 1.0]
    origins = np.concatenate([scattered, low, high])
    args = lattice_inputs(origins, 4, 1.0, 1e-6)
    scaled = (origins - origins.min(axis=0)) / args[2] * args[3]
    assert _window_candidates(args[1], scaled, args[3] * 1.000001) is not None  # no fallback
    found = pair_set(_lattice_candidates(*args))
    assert found == pair_set(kd_tree_candidates(*args))
    assert {(2000 + k, 2030 + k) for k in range(30)} <= found


def test_merge_without_pairs_is_the_identity():
    ids, rep = merge_pairs(6, np.empty((0, 2), dtype=np.int64))
    assert ids.tolist() == rep.tolist() == list(range(6))
