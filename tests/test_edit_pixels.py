"""The pixel painter's pure edits (barymesh.app.model.pixels): symmetry groups, paint/erase, flood
fill, invert, random fill and resize, with property tests over random masks."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from barymesh.app.model import pixels
from barymesh.cell import SYMMETRIES, symmetrized

GROUP_ORDER = {"none": 1, "mirror_x": 2, "mirror_y": 2, "4-fold": 4, "8-fold": 8}


@st.composite
def mask_and_mode(draw, square=None):
    """A mask, a symmetry mode it can take (4- and 8-fold on square masks) and a pixel."""
    mode = draw(st.sampled_from(SYMMETRIES))
    rows = draw(st.integers(1, 9))
    cols = rows if mode in ("4-fold", "8-fold") or square else draw(st.integers(1, 9))
    mask = draw(arrays(bool, (rows, cols)))
    pixel = (draw(st.integers(0, rows - 1)), draw(st.integers(0, cols - 1)))
    return mask, mode, pixel


def transforms(mode):
    """The group of ``mode`` as explicit maps (row, col) -> (row, col) on an R x C grid,
    written from the geometry (not from group_images): x = col - (C-1)/2, y = row - (R-1)/2."""

    def make(fx):
        def apply(r, c, rows, cols):
            x, y = c - (cols - 1) / 2, r - (rows - 1) / 2
            x2, y2 = fx(x, y)
            return int(round(y2 + (rows - 1) / 2)), int(round(x2 + (cols - 1) / 2))

        return apply

    ident = make(lambda x, y: (x, y))
    mx, my = make(lambda x, y: (-x, y)), make(lambda x, y: (x, -y))
    turns = [
        ident,
        make(lambda x, y: (-y, x)),
        make(lambda x, y: (-x, -y)),
        make(lambda x, y: (y, -x)),
    ]
    mirrors = [mx, my, make(lambda x, y: (y, x)), make(lambda x, y: (-y, -x))]
    return {
        "none": [ident],
        "mirror_x": [ident, mx],
        "mirror_y": [ident, my],
        "4-fold": turns,
        "8-fold": turns + mirrors,
    }[mode]


def invariant_by_definition(mask, mode):
    rows, cols = mask.shape
    for g in transforms(mode):
        for r, c in np.argwhere(mask):
            r2, c2 = g(r, c, rows, cols)
            if not mask[r2, c2]:
                return False
    return True


# -- the groups ------------------------------------------------------------------------


@pytest.mark.parametrize("mode", SYMMETRIES)
def test_orbit_of_a_generic_pixel_has_the_group_order(mode):
    ids = pixels.orbit_ids((9, 9), mode)  # (1, 2) is on no mirror line and not the centre
    assert (ids == ids[1, 2]).sum() == GROUP_ORDER[mode]
    assert (ids == ids[4, 4]).sum() == 1  # the centre is fixed by every element


@pytest.mark.parametrize("mode", SYMMETRIES)
def test_orbits_match_the_geometric_maps(mode):
    rows = cols = 6
    ids = pixels.orbit_ids((rows, cols), mode)
    for r in range(rows):
        for c in range(cols):
            orbit = {g(r, c, rows, cols) for g in transforms(mode)}
            assert {tuple(p) for p in np.argwhere(ids == ids[r, c])} == orbit


def test_4_fold_is_rotation_only_and_8_fold_adds_the_mirrors():
    m = pixels.paint(np.zeros((4, 4), bool), 0, 1, "4-fold")
    assert pixels.is_invariant(m, "4-fold")
    assert not pixels.is_invariant(m, "mirror_x")  # a pinwheel: C4, not mirror symmetric
    m8 = pixels.paint(np.zeros((4, 4), bool), 0, 1, "8-fold")
    assert m8.sum() == 8
    assert all(pixels.is_invariant(m8, s) for s in SYMMETRIES)


def test_the_shipped_coding_cell_is_4_fold():
    from barymesh.cell import load_cell_preset

    mask = load_cell_preset("coding-16x16").pixels.mask
    assert pixels.is_invariant(mask, "4-fold")
    assert not pixels.is_invariant(mask, "8-fold")


# -- properties ------------------------------------------------------------------------


@given(mask_and_mode(), st.booleans())
def test_every_edit_is_invariant_under_its_group(case, value):
    mask, mode, (r, c) = case
    results = [
        pixels.painted(mask, [(r, c)], mode, value),
        pixels.paint(mask, r, c, mode),
        pixels.erase(mask, r, c, mode),
        pixels.flood_filled(mask, r, c, mode, value),
        pixels.random_mask(mask.shape, r * 10 + c, mode),
        pixels.inverted(symmetrized(mask, mode)),
    ]
    for out in results:
        assert out.shape == mask.shape and out.dtype == bool
        assert invariant_by_definition(out, mode)
        assert pixels.is_invariant(out, mode)


@given(mask_and_mode())
def test_an_edit_keeps_the_metal_outside_the_orbit(case):
    mask, mode, (r, c) = case
    closed = symmetrized(mask, mode)
    orbit = pixels.orbit_ids(mask.shape, mode)
    outside = orbit != orbit[r, c]
    for value in (True, False):
        out = pixels.painted(mask, [(r, c)], mode, value)
        assert np.array_equal(out[outside], closed[outside])
        assert (out[~outside] == value).all()


@given(mask_and_mode())
def test_invert_twice_is_identity(case):
    mask, _, _ = case
    once = pixels.inverted(mask)
    assert (once != mask).all()
    assert np.array_equal(pixels.inverted(once), mask)


@given(mask_and_mode())
def test_paint_then_erase_restores_an_invariant_mask_empty_there(case):
    mask, mode, (r, c) = case
    mask = symmetrized(mask, mode)
    mask = pixels.erase(mask, r, c, mode)  # empty at the pixel (and its orbit)
    painted = pixels.paint(mask, r, c, mode)
    assert (
        painted[r, c]
        and painted.sum()
        == mask.sum()
        + (pixels.orbit_ids(mask.shape, mode) == pixels.orbit_ids(mask.shape, mode)[r, c]).sum()
    )
    assert np.array_equal(pixels.erase(painted, r, c, mode), mask)


@given(mask_and_mode(), st.booleans())
def test_flood_fill_sets_exactly_the_4_connected_region(case, value):
    mask, _, (r, c) = case
    out = pixels.flood_filled(mask, r, c, "none", value)
    # the region by breadth-first search over side neighbours
    region, todo = {(r, c)}, [(r, c)]
    while todo:
        i, j = todo.pop()
        for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1)):
            a, b = i + di, j + dj
            if (
                0 <= a < mask.shape[0]
                and 0 <= b < mask.shape[1]
                and (a, b) not in region
                and mask[a, b] == mask[r, c]
            ):
                region.add((a, b))
                todo.append((a, b))
    expected = mask.copy()
    for i, j in region:
        expected[i, j] = value
    assert np.array_equal(out, expected)


@given(st.sampled_from(SYMMETRIES), st.integers(1, 12), st.integers(0, 2**32), st.floats(0, 1))
def test_random_fill_is_reproducible_and_respects_density_ends(mode, n, seed, density):
    a = pixels.random_mask((n, n), seed, mode, density)
    assert np.array_equal(a, pixels.random_mask((n, n), seed, mode, density))
    assert pixels.is_invariant(a, mode)
    assert not pixels.random_mask((n, n), seed, mode, 0.0).any()
    assert pixels.random_mask((n, n), seed, mode, 1.0).all()


def test_random_fill_draws_about_the_density_and_depends_on_the_seed():
    a = pixels.random_mask((64, 64), 1, "none", 0.3)
    assert abs(a.mean() - 0.3) < 0.03  # 4096 draws: 3 % is over 4 standard deviations
    assert not np.array_equal(a, pixels.random_mask((64, 64), 2, "none", 0.3))
    eight = pixels.random_mask((64, 64), 1, "8-fold", 0.5)
    assert pixels.is_invariant(eight, "8-fold") and 0.4 < eight.mean() < 0.6


@given(
    arrays(bool, st.tuples(st.integers(1, 8), st.integers(1, 8))),
    st.integers(1, 12),
    st.integers(1, 12),
)
def test_resize_keeps_the_centre_and_back_again_restores(mask, rows, cols):
    out = pixels.resized(mask, rows, cols)
    assert out.shape == (rows, cols)
    if rows >= mask.shape[0] and cols >= mask.shape[1]:  # grown: nothing lost
        assert out.sum() == mask.sum()
        assert np.array_equal(pixels.resized(out, *mask.shape), mask)


@given(mask_and_mode(square=True), st.integers(0, 4))
def test_an_even_resize_keeps_the_symmetry(case, grow):
    mask, mode, _ = case
    mask = symmetrized(mask, mode)
    n = mask.shape[0] + 2 * grow
    assert pixels.is_invariant(pixels.resized(mask, n, n), mode)
    if mask.shape[0] > 2:
        m = mask.shape[0] - 2
        assert pixels.is_invariant(pixels.resized(mask, m, m), mode)


# -- bad input -------------------------------------------------------------------------


def test_bad_input_is_refused_with_the_parameter_named():
    m = np.zeros((3, 4), bool)
    with pytest.raises(ValueError, match="needs a square grid"):
        pixels.paint(m, 0, 0, "4-fold")
    with pytest.raises(ValueError, match="symmetry='c4' is unknown"):
        pixels.paint(m, 0, 0, "c4")
    with pytest.raises(ValueError, match="row=3 is outside the grid"):
        pixels.paint(m, 3, 0)
    with pytest.raises(ValueError, match="col=-1 is outside"):
        pixels.flood_filled(m, 0, -1)
    with pytest.raises(ValueError, match="expected booleans"):
        pixels.inverted(np.zeros((2, 2)))
    with pytest.raises(ValueError, match="seed=-1"):
        pixels.random_mask((2, 2), -1)
    with pytest.raises(ValueError, match="density=1.5"):
        pixels.random_mask((2, 2), 0, density=1.5)
    with pytest.raises(ValueError, match="rows=0"):
        pixels.resized(m, 0, 2)


def test_the_docstring_examples_hold():
    """app/ is not in the doctest paths: run this module's examples here."""
    import doctest

    result = doctest.testmod(pixels, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted >= 8 and result.failed == 0
