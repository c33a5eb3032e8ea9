"""Union area of rectangles (paper mode's overlap ratio) against a brute-force raster."""

import numpy as np
import pytest

from core import MeshParams, build_mesh
from core.overlap import union_area


def raster_area(rects, cells=800):
    lo, hi = rects[:, :2].min(0), rects[:, 2:].max(0)
    xs = np.linspace(lo[0], hi[0], cells, endpoint=False) + (hi[0] - lo[0]) / cells / 2
    ys = np.linspace(lo[1], hi[1], cells, endpoint=False) + (hi[1] - lo[1]) / cells / 2
    gx, gy = np.meshgrid(xs, ys)
    inside = np.zeros(gx.shape, dtype=bool)
    for x0, y0, x1, y1 in rects:
        inside |= (gx >= x0) & (gx < x1) & (gy >= y0) & (gy < y1)
    return inside.mean() * (hi - lo).prod()


def test_union_by_hand():
    assert union_area(np.array([[0.0, 0, 2, 2], [1, 1, 3, 3]])) == 7.0
    assert union_area(np.array([[0.0, 0, 1, 1], [0, 0, 1, 1]])) == 1.0
    assert union_area(np.array([[0.0, 0, 1, 1], [2, 2, 3, 3]])) == 2.0
    assert union_area(np.array([[0.0, 0, 4, 4], [1, 1, 2, 2]])) == 16.0
    assert union_area(np.empty((0, 4))) == 0.0


@pytest.mark.parametrize("seed", range(4))
def test_union_matches_raster(seed):
    rng = np.random.default_rng(seed)
    lo = rng.uniform(0, 10, (30, 2))
    rects = np.concatenate([lo, lo + rng.uniform(0.5, 3, (30, 2))], axis=1)
    assert union_area(rects) == pytest.approx(raster_area(rects), rel=0.01)


def test_overlap_ratio_of_fig12a():
    mesh = build_mesh(MeshParams())
    rects = mesh.patch_rects
    expect = 1 - raster_area(rects, 1500) / 720.0
    assert mesh.stats()["overlap_ratio"] == pytest.approx(expect, abs=0.005)
    assert 0.8 < mesh.stats()["overlap_ratio"] < 0.9
