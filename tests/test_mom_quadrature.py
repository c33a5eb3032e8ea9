"""Quadrature rules and closed-form potential integrals of the MoM solver."""

from math import factorial

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from barymesh.mom.geometry import close_pairs
from barymesh.mom.quadrature import ORDERS, triangle_rule
from barymesh.mom.singular import potential_integrals


@pytest.mark.parametrize("order", ORDERS)
def test_rule_integrates_every_monomial_up_to_its_degree(order):
    # mean of λ1^i λ2^j over a triangle is 2 i! j! / (i + j + 2)!
    bary, w = triangle_rule(order)
    assert np.all(bary >= 0) and np.allclose(bary.sum(axis=1), 1.0)
    for i in range(order + 1):
        for j in range(order + 1 - i):
            exact = 2.0 * factorial(i) * factorial(j) / factorial(i + j + 2)
            assert np.sum(w * bary[:, 0] ** i * bary[:, 1] ** j) == pytest.approx(exact, abs=1e-14)
    # and not one degree more (each rule is the smallest of its degree here)
    i = order + 1
    worst = max(
        abs(
            np.sum(w * bary[:, 0] ** a * bary[:, 1] ** (i - a))
            - 2.0 * factorial(a) * factorial(i - a) / factorial(i + 2)
        )
        for a in range(i + 1)
    )
    assert worst > 1e-12


@pytest.mark.parametrize("order", ORDERS)
def test_rule_is_symmetric_under_vertex_permutation(order):
    bary, w = triangle_rule(order)
    key = {(tuple(np.round(b, 13)), round(x, 13)) for b, x in zip(bary, w, strict=True)}
    for perm in ([1, 2, 0], [0, 2, 1]):
        permuted = {
            (tuple(np.round(b, 13)), round(x, 13)) for b, x in zip(bary[:, perm], w, strict=True)
        }
        assert permuted == key


def test_rule_rejects_unknown_orders():
    with pytest.raises(ValueError, match="order=9"):
        triangle_rule(9)
    with pytest.raises(TypeError, match="order"):
        triangle_rule(2.5)


def _fine_sum(r, corners, n=100):
    """Brute-force ∫ 1/R, ∫ R, ∫ (r'−r)/R, ∫ (r'−r) R with a degree-8 rule on n² sub-triangles."""
    b, w = triangle_rule(8)
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    v0, v1, v2 = corners
    e1, e2 = (v1 - v0) / n, (v2 - v0) / n
    up = i + j < n
    a = v0 + i[up][:, None] * e1 + j[up][:, None] * e2
    down = i + j < n - 1
    c = v0 + (i[down][:, None] + 1) * e1 + (j[down][:, None] + 1) * e2
    tris = np.concatenate([np.stack([a, a + e1, a + e2], 1), np.stack([c, c - e1, c - e2], 1)])
    area = 0.5 * np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1)
    pts = np.einsum("qk,tkc->tqc", b, tris)
    weights = area[:, None] * w
    d = pts - r
    dist = np.linalg.norm(d, axis=-1)
    return (
        np.sum(weights / dist),
        np.sum(weights * dist),
        np.sum(d * (weights / dist)[..., None], axis=(0, 1)),
        np.sum(d * (weights * dist)[..., None], axis=(0, 1)),
    )


CORNERS = np.array([[0.1, 0.2, 0.0], [1.3, 0.1, 0.2], [0.4, 1.1, -0.1]])


@pytest.mark.parametrize(
    "point",
    [(0.5, 0.5, 0.3), (0.5, 0.4, 0.05), (2.0, 2.0, 0.5), (-0.5, 0.3, 0.0), (0.61, 0.47, 0.02)],
)
def test_closed_forms_match_brute_force_quadrature(point):
    r = np.asarray(point, dtype=float)
    got = potential_integrals(r[None], CORNERS[None])
    want = _fine_sum(r, CORNERS)
    for g, w in zip(got, want, strict=True):
        np.testing.assert_allclose(np.asarray(g)[0], w, rtol=1e-9, atol=1e-11)


def test_closed_form_of_1_over_r_at_the_centroid_of_an_equilateral_triangle():
    # ∫ 1/R over an equilateral triangle of side a, seen from its centre: a √3 ln(2 + √3)
    a = 0.7
    corners = np.array([[0, 0, 0], [a, 0, 0], [a / 2, a * np.sqrt(3) / 2, 0]])
    inv_r, r1, vec_inv, vec_r = potential_integrals(corners.mean(axis=0)[None], corners[None])
    assert inv_r[0] == pytest.approx(a * np.sqrt(3) * np.log(2 + np.sqrt(3)), rel=1e-13)
    np.testing.assert_allclose(vec_inv[0], 0.0, atol=1e-14)  # symmetry
    np.testing.assert_allclose(vec_r[0], 0.0, atol=1e-14)


def test_closed_forms_ignore_corner_order_and_orientation():
    r = np.array([[0.3, 0.35, 0.12], [0.9, -0.2, 0.0]])
    ref = potential_integrals(r, np.repeat(CORNERS[None], 2, axis=0))
    for perm in ([1, 2, 0], [2, 1, 0], [0, 2, 1]):
        got = potential_integrals(r, np.repeat(CORNERS[perm][None], 2, axis=0))
        for g, w in zip(got, ref, strict=True):
            np.testing.assert_allclose(g, w, rtol=1e-13, atol=1e-15)


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n_a=st.integers(0, 40),
    n_b=st.integers(0, 40),
    spread=st.floats(0.1, 10.0),
)
def test_close_pairs_finds_exactly_the_brute_force_pairs(seed, n_a, n_b, spread):
    # graded sizes (a 100x range) and two different point sets, as the periodic images are
    rng = np.random.default_rng(seed)
    a, b = rng.uniform(0, spread, (n_a, 2)), rng.uniform(0, spread, (n_b, 2))
    size_a, size_b = 10 ** rng.uniform(-2, 0, n_a), 10 ** rng.uniform(-2, 0, n_b)
    got = close_pairs(a, b, size_a, size_b, 1.5)
    d = np.linalg.norm(a[:, None] - b[None], axis=2) if n_a and n_b else np.zeros((n_a, n_b))
    want = np.argwhere(d < 1.5 * np.maximum(size_a[:, None], size_b[None]))
    assert got.shape == want.shape and np.array_equal(got, want)  # both sorted by (i, j)
