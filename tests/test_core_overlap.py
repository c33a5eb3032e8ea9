"""Union area of rectangles (paper mode's overlap ratio).

Checked against exact rational arithmetic, a brute-force raster, and the previous
implementation (the O(P²) slab sweep, copied below as it was) to 1e-12 relative.
"""

from fractions import Fraction

import numpy as np
import pytest

from barymesh import MeshParams, build_mesh
from barymesh.overlap import union_area, union_area_slabs
from barymesh.presets import load_preset, preset_names


def reference_union_area(rects: np.ndarray) -> float:
    """The slab sweep ``barymesh.overlap.union_area`` used before the quadrant sweep (verbatim)."""
    chunk = 4_000_000
    rects = np.asarray(rects, dtype=np.float64).reshape(-1, 4)
    if len(rects) == 0:
        return 0.0
    xs = np.unique(rects[:, [0, 2]])
    width = np.diff(xs)
    first = np.searchsorted(xs, rects[:, 0])
    stop = np.searchsorted(xs, rects[:, 2])
    y0 = rects[:, 1] - rects[:, 1].min()
    y1 = rects[:, 3] - rects[:, 1].min()
    span = float(y1.max()) * 2 + 1.0
    total = 0.0
    per_slab = max(1, int(chunk // max(1, len(rects))))
    for lo in range(0, len(width), per_slab):
        hi = min(lo + per_slab, len(width))
        a = np.maximum(first, lo)
        b = np.minimum(stop, hi)
        count = np.clip(b - a, 0, None)
        rect = np.repeat(np.arange(len(rects)), count)
        before_rect = np.repeat(np.cumsum(count) - count, count)
        slab = np.repeat(a, count) + (np.arange(len(rect)) - before_rect)
        order = np.lexsort((y0[rect], slab))
        rect, slab = rect[order], slab[order]
        offset = (slab - lo) * span
        bottom = y0[rect] + offset
        top = y1[rect] + offset
        reach = np.maximum.accumulate(top)
        before = np.concatenate([[-np.inf], reach[:-1]])
        covered = np.clip(top - np.maximum(bottom, before), 0.0, None)
        length = np.bincount(slab - lo, weights=covered, minlength=hi - lo)
        total += float(length @ width[lo:hi])
    return total


def exact_union_area(rects: np.ndarray) -> float:
    """Sum of the covered cells of the grid of all edges, in rational arithmetic."""
    xs = sorted(set(rects[:, 0]) | set(rects[:, 2]))
    ys = sorted(set(rects[:, 1]) | set(rects[:, 3]))
    total = Fraction(0)
    for a, b in zip(xs[:-1], xs[1:], strict=True):
        over = rects[(rects[:, 0] <= a) & (rects[:, 2] >= b)]
        for c, d in zip(ys[:-1], ys[1:], strict=True):
            if ((over[:, 1] <= c) & (over[:, 3] >= d)).any():
                total += (Fraction(b) - Fraction(a)) * (Fraction(d) - Fraction(c))
    return float(total)


def raster_area(rects, cells=800):
    lo, hi = rects[:, :2].min(0), rects[:, 2:].max(0)
    xs = np.linspace(lo[0], hi[0], cells, endpoint=False) + (hi[0] - lo[0]) / cells / 2
    ys = np.linspace(lo[1], hi[1], cells, endpoint=False) + (hi[1] - lo[1]) / cells / 2
    gx, gy = np.meshgrid(xs, ys)
    inside = np.zeros(gx.shape, dtype=bool)
    for x0, y0, x1, y1 in rects:
        inside |= (gx >= x0) & (gx < x1) & (gy >= y0) & (gy < y1)
    return inside.mean() * (hi - lo).prod()


def random_rects(rng, count, congruent=False, grid=None):
    """(count, 4) rectangles in [0, 13]²; optionally all one size, or on a coarse grid."""
    lo = rng.uniform(0, 10, (count, 2))
    size = rng.uniform(0.3, 3, 2) if congruent else rng.uniform(0.3, 3, (count, 2))
    size = np.broadcast_to(size, (count, 2))
    if grid:  # shared and touching edges, coincident rectangles
        lo, size = np.round(lo * grid) / grid, np.round(size * grid) / grid + 1 / grid
    return np.concatenate([lo, lo + size], axis=1)


def test_union_by_hand():
    assert union_area(np.array([[0.0, 0, 2, 2], [1, 1, 3, 3]])) == 7.0
    assert union_area(np.array([[0.0, 0, 1, 1], [0, 0, 1, 1]])) == 1.0
    assert union_area(np.array([[0.0, 0, 1, 1], [2, 2, 3, 3]])) == 2.0
    assert union_area(np.array([[0.0, 0, 4, 4], [1, 1, 2, 2]])) == 16.0
    assert union_area(np.array([[0.0, 0, 2, 1], [1, 0, 3, 1]])) == 3.0  # touching sides
    assert union_area(np.array([[0.0, 0, 3, 1], [1, -1, 2, 2]])) == 5.0  # a cross
    assert union_area(np.empty((0, 4))) == 0.0


@pytest.mark.parametrize("seed", range(4))
def test_union_matches_raster(seed):
    rng = np.random.default_rng(seed)
    rects = random_rects(rng, 30)
    assert union_area(rects) == pytest.approx(raster_area(rects), rel=0.01)


@pytest.mark.parametrize("kind", ["varied", "congruent", "grid", "congruent grid"])
def test_union_is_exact_on_random_sets(kind):
    rng = np.random.default_rng(sum(map(ord, kind)))
    for _ in range(40):
        rects = random_rects(
            rng, int(rng.integers(1, 40)), "congruent" in kind, 4 if "grid" in kind else None
        )
        exact = exact_union_area(rects)
        assert union_area(rects) == pytest.approx(exact, rel=1e-12, abs=0)
        assert reference_union_area(rects) == pytest.approx(exact, rel=1e-12, abs=0)


@pytest.mark.parametrize("seed", range(3))
def test_union_matches_the_previous_implementation_on_large_random_sets(seed):
    rng = np.random.default_rng(seed)
    for rects in (random_rects(rng, 3000), random_rects(rng, 3000, congruent=True)):
        assert union_area(rects) == pytest.approx(reference_union_area(rects), rel=1e-12, abs=0)


def test_rectangles_of_very_different_sizes_take_the_slab_sweep():
    # a thin sliver next to a wide plate would need ~10⁶ grid cells: the slab sweep answers
    rects = np.array([[0.0, 0, 1000, 1000], [10, 10, 10.001, 10.001], [999, 999, 1001, 1001]])
    exact = exact_union_area(rects)
    assert union_area(rects) == pytest.approx(exact, rel=1e-12, abs=0)
    assert union_area_slabs(rects) == pytest.approx(exact, rel=1e-12, abs=0)


def test_small_rectangles_far_apart():
    # cells of 1 µm over a kilometre: a sparse grid of 10¹⁸ cells, of which 9 are used
    rects = np.array(
        [[0.0, 0, 1e-3, 1e-3], [5e-4, 5e-4, 1.5e-3, 1.5e-3], [1e6, 1e6, 1e6 + 1e-3, 1e6 + 1e-3]]
    )
    assert union_area(rects) == pytest.approx(exact_union_area(rects), rel=1e-12, abs=0)


def test_overlap_ratio_of_fig12a():
    mesh = build_mesh(MeshParams())
    rects = mesh.patch_rects
    expect = 1 - raster_area(rects, 1500) / 720.0
    assert mesh.stats()["overlap_ratio"] == pytest.approx(expect, abs=0.005)
    assert 0.8 < mesh.stats()["overlap_ratio"] < 0.9


def assert_matches_reference(mesh):
    """Union area to 1e-12 relative, hence the ratio 1 − union / sum to 1e-12 absolute.

    (The reference's own rounding is up to ~1e-13 of the area: it shifts every slab
    by a multiple of the y-span so that one running maximum serves all slabs.)
    """
    r = mesh.patch_rects
    reference = reference_union_area(r)
    assert union_area(r) == pytest.approx(reference, rel=1e-12, abs=0)
    total = float(((r[:, 2] - r[:, 0]) * (r[:, 3] - r[:, 1])).sum())
    assert mesh.stats()["overlap_ratio"] == pytest.approx(1.0 - reference / total, abs=1e-12)


@pytest.mark.parametrize("name", [n for n in preset_names() if load_preset(n)[0].mode == "paper"])
def test_overlap_ratio_of_paper_presets_matches_the_previous_implementation(name):
    assert_matches_reference(build_mesh(load_preset(name)[0]))


@pytest.mark.parametrize(
    "params",
    [
        # heavily overlapping double rings: thousands of patches over each point
        {"structure": "double_ring", "mode": "paper", "angle_step": 0.1, "subdivisions": 1},
        {"structure": "split_double_ring", "mode": "paper", "angle_step": 0.2, "subdivisions": 1},
        {"structure": "square_split_double_ring", "mode": "paper", "patch_size": 0.3},
        {"structure": "square_split_double_ring", "mode": "paper", "patch_size": 0.25},
        {"structure": "double_ring", "mode": "paper", "patch_size": 0.5, "patch_width": 2.0},
    ],
)
def test_overlap_ratio_of_paper_structures_matches_the_previous_implementation(params):
    assert_matches_reference(build_mesh(MeshParams(**params)))


def test_issue_10_heavily_overlapping_double_ring():
    # issue 10, item 5: ~100k triangles built in milliseconds, then 10 s in stats()
    params = MeshParams(
        structure="double_ring",
        mode="paper",
        inner_radius=0.9159,
        patch_size=3.2376,
        outer_radius=5.6588,
        angle_step=0.0568,
        subdivisions=2,
    )
    mesh = build_mesh(params)
    assert mesh.n_patches == 2 * 6339  # ceil(360 / 0.0568) per ring
    assert_matches_reference(mesh)
    assert 0.99 < mesh.overlap_ratio < 1.0
