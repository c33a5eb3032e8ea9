"""Subdivision of primary triangles and the patch template."""

import numpy as np
import pytest

from barymesh.subdivision import barycentric_subdivision, patch_template, uniform_subdivision


@pytest.mark.parametrize("n", [1, 2, 3, 4, 7, 16, 64])
def test_uniform_subdivision_counts_and_rows(n):
    bary, tri = uniform_subdivision(n)
    assert len(bary) == (n + 1) * (n + 2) // 2
    assert len(tri) == n * n
    # row k from the apex (t = 1) holds 2k - 1 sub-triangles
    top = bary[tri][:, :, 1].max(axis=1)
    rows = np.round((1 - top) * n).astype(int) + 1
    assert np.bincount(rows)[1:].tolist() == [2 * k - 1 for k in range(1, n + 1)]
    # sub-triangles are equal, tile the reference triangle, and are counter-clockwise
    p = bary[tri]
    d1, d2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    signed = 0.5 * (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])
    assert np.allclose(signed, 0.5 / n**2)


def test_paper_sixteen_and_classic_nine():
    assert len(uniform_subdivision(4)[1]) == 16
    assert len(uniform_subdivision(3)[1]) == 9


@pytest.mark.parametrize("levels", [1, 2, 3])
def test_barycentric_levels(levels):
    bary, tri = barycentric_subdivision(levels)
    assert len(tri) == 6**levels
    p = bary[tri]
    d1, d2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    signed = 0.5 * (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])
    assert (signed > 0).all()
    assert np.isclose(signed.sum(), 0.5)
    # every edge of the primary ends up cut into 2**levels equal segments
    on_base = np.sort(bary[np.isclose(bary[:, 1], 0), 0])
    assert np.allclose(on_base, np.linspace(0, 1, 2**levels + 1))
    # level 1 is centroid + three midpoints + corners
    if levels == 1:
        assert len(bary) == 7
        assert any(np.allclose(b, [1 / 3, 1 / 3]) for b in bary)


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5, 8])
@pytest.mark.parametrize("diagonal", ["BC", "AD"])
def test_patch_template_counts(n, diagonal):
    t = patch_template("uniform", n, diagonal)
    assert len(t.triangles) == 2 * n * n
    assert len(t.uv) == (n + 1) ** 2
    assert int((t.valence == 2).sum()) == 3 * n * n - 2 * n
    assert int((t.valence == 1).sum()) == 4 * n
    # the grid is stored at index b (n + 1) + a
    a, b = np.meshgrid(np.arange(n + 1), np.arange(n + 1))
    assert np.allclose(t.uv, np.stack([a.ravel(), b.ravel()], 1) / n)
    assert t.sides.shape == (4, n + 1)


@pytest.mark.parametrize(("diagonal", "direction"), [("BC", (1, -1)), ("AD", (1, 1))])
def test_cells_are_cut_parallel_to_the_diagonal(diagonal, direction):
    t = patch_template("uniform", 4, diagonal)
    e = t.uv[t.edges[:, 1]] - t.uv[t.edges[:, 0]]
    slanted = e[np.abs(e).min(axis=1) > 1e-12]
    slanted = slanted / slanted[:, :1]
    assert np.allclose(slanted, direction)


def test_first_half_of_template_is_primary_abc():
    t = patch_template("uniform", 4, "BC")
    c = t.uv[t.triangles].mean(axis=1)
    assert (c[:16].sum(axis=1) < 1).all() and (c[16:].sum(axis=1) > 1).all()
