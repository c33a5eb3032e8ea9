"""The fast paths taken for speed give exactly what the general paths give."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from core import MeshParams, TriMesh, build_mesh
from core.quality import triangle_quality
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


def reference_quality(points, triangles):
    """Areas, smallest angles and aspect ratios as first written: (T, 3, 3) corner gathers."""
    p = np.asarray(points, dtype=np.float64)[np.asarray(triangles)]
    sides = [np.sqrt(sum(x * x for x in (p[:, (k + 1) % 3] - p[:, k]).T)) for k in range(3)]
    u, v = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    if p.shape[2] == 2:
        cross2 = (u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]) ** 2
    else:
        cross2 = (
            (u[:, 1] * v[:, 2] - u[:, 2] * v[:, 1]) ** 2
            + (u[:, 2] * v[:, 0] - u[:, 0] * v[:, 2]) ** 2
            + (u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]) ** 2
        )
    area = 0.5 * np.sqrt(cross2)
    l0, l1, l2 = sides
    longest = np.maximum(np.maximum(l0, l1), l2)
    shortest = np.minimum(np.minimum(l0, l1), l2)
    perimeter = l0 + l1 + l2
    middle = perimeter - longest - shortest
    with np.errstate(invalid="ignore", divide="ignore"):
        sine = np.clip(2.0 * area / (longest * middle), 0.0, 1.0)
        aspect = longest * perimeter / (4.0 * np.sqrt(3.0) * area)
    angle = np.degrees(np.arcsin(sine))
    angle[~np.isfinite(angle)] = 0.0
    return area, angle, aspect


def assert_same_bits(got, expect):
    for a, b in zip(got, expect, strict=True):
        assert np.array_equal(a, b, equal_nan=True)


@pytest.mark.parametrize("scale", [1.0, 1e-160])
@pytest.mark.parametrize("dims", [2, 3])
def test_quality_equals_the_reference_bit_for_bit(scale, dims):
    # random triangles, slivers and repeated corners, at scales where c² underflows
    rng = np.random.default_rng(dims)
    points = rng.normal(size=(300, dims)) * scale
    triangles = rng.integers(0, 300, (2000, 3))
    triangles[:50, 2] = triangles[:50, 1]  # degenerate: two corners the same
    expect = reference_quality(points, triangles)
    assert_same_bits(triangle_quality(points, triangles), expect)
    pts3 = np.column_stack([points, np.zeros(len(points))]) if dims == 2 else points
    mesh = TriMesh(pts3, triangles, np.zeros(len(triangles)), np.ones(len(triangles)), 1)
    mesh.stats()  # edge lengths first: the sides are then taken from them
    assert_same_bits(mesh.quality, expect)


def test_planar_areas_do_not_overflow_where_the_square_would():
    # |cross| up to 1e300: its square overflowed to an infinite area before
    rng = np.random.default_rng(7)
    points = rng.normal(size=(300, 2)) * 1e150
    triangles = rng.integers(0, 300, (2000, 3))
    with np.errstate(over="ignore"):
        expect = reference_quality(points, triangles)[0]
    got = triangle_quality(points, triangles).areas
    assert np.isfinite(got).all() and not np.isfinite(expect).all()
    finite = np.isfinite(expect)
    assert np.array_equal(got[finite], expect[finite])


@pytest.mark.parametrize(
    "params",
    [
        MeshParams(),
        MeshParams(structure="double_ring", mode="conforming", subdivisions=6),
        MeshParams(structure="split_ring", mode="conforming", scheme="barycentric"),
        MeshParams(structure="square_split_double_ring", mode="paper", patch_size=0.5),
    ],
)
def test_quality_of_structures_equals_the_reference_bit_for_bit(params):
    fresh, after_stats = build_mesh(params), build_mesh(params)
    after_stats.stats()
    expect = reference_quality(fresh.points, fresh.triangles)
    assert_same_bits(fresh.quality, expect)
    assert_same_bits(after_stats.quality, expect)
