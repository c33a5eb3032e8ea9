"""Symmetric Gaussian rules on triangles (Dunavant 1985), as data.

A rule is a pair ``(barycentric (Q, 3) float64, weights (Q,) float64)``;
the weights sum to 1, so ``area * weights`` integrates over a triangle.
Every rule here is invariant under any permutation of the triangle's
vertices (its points come in symmetric orbits), which is what makes the
solver's currents independent of how each triangle lists its vertices.

Reference: D. A. Dunavant, "High degree efficient symmetrical Gaussian
quadrature rules for the triangle", Int. J. Numer. Meth. Eng. 21 (1985)
1129–1148. The tables below are his, checked against exact monomial
integrals in ``tests/test_mom_quadrature.py``.

>>> bary, w = triangle_rule(2)
>>> bary.shape, float(w.sum())
((3, 3), 1.0)
"""

from __future__ import annotations

from functools import cache

import numpy as np

# degree -> list of orbits (kind, weight, coordinates):
#   "c": the centroid; "a": (a, b, b) and its 3 permutations, b = 1 - 2a;
#   "abc": (a, b, c) and its 6 permutations, c = 1 - a - b.
_ORBITS: dict[int, list[tuple[str, float, tuple[float, ...]]]] = {
    1: [("c", 1.0, ())],
    2: [("a", 1.0 / 3.0, (2.0 / 3.0,))],
    3: [("c", -27.0 / 48.0, ()), ("a", 25.0 / 48.0, (0.6,))],
    4: [
        ("a", 0.223381589678011, (0.108103018168070,)),
        ("a", 0.109951743655322, (0.816847572980459,)),
    ],
    5: [
        ("c", 0.225, ()),
        ("a", 0.132394152788506, (0.059715871789770,)),
        ("a", 0.125939180544827, (0.797426985353087,)),
    ],
    6: [
        ("a", 0.116786275726379, (0.501426509658179,)),
        ("a", 0.050844906370207, (0.873821971016996,)),
        ("abc", 0.082851075618374, (0.053145049844817, 0.310352451033784)),
    ],
    7: [
        ("c", -0.149570044467682, ()),
        ("a", 0.175615257433208, (0.479308067841920,)),
        ("a", 0.053347235608838, (0.869739794195568,)),
        ("abc", 0.077113760890257, (0.048690315425316, 0.312865496004874)),
    ],
    8: [
        ("c", 0.144315607677787, ()),
        ("a", 0.095091634267285, (0.081414823414554,)),
        ("a", 0.103217370534718, (0.658861384496480,)),
        ("a", 0.032458497623198, (0.898905543365938,)),
        ("abc", 0.027230314174435, (0.008394777409958, 0.263112829634638)),
    ],
}

#: The polynomial degrees for which a rule exists.
ORDERS = tuple(sorted(_ORBITS))


@cache
def _rule(order: int) -> tuple[np.ndarray, np.ndarray]:
    points: list[tuple[float, float, float]] = []
    weights: list[float] = []
    for kind, weight, coords in _ORBITS[order]:
        if kind == "c":
            orbit = [(1 / 3, 1 / 3, 1 / 3)]
        elif kind == "a":
            a = coords[0]
            b = (1.0 - a) / 2.0
            orbit = [(a, b, b), (b, a, b), (b, b, a)]
        else:
            a, b = coords
            c = 1.0 - a - b
            orbit = [(a, b, c), (a, c, b), (b, a, c), (b, c, a), (c, a, b), (c, b, a)]
        points.extend(orbit)
        weights.extend([weight] * len(orbit))
    bary = np.array(points)
    w = np.array(weights)
    w /= w.sum()  # the printed tables carry 15 digits; make the sum exact
    bary.flags.writeable = False
    w.flags.writeable = False
    return bary, w


def triangle_rule(order: int) -> tuple[np.ndarray, np.ndarray]:
    """Dunavant's rule exact for polynomials of degree ``order``.

    Parameters
    ----------
    order : int
        Polynomial degree, one of :data:`ORDERS` (1 to 8); the rules have
        1, 3, 4, 6, 7, 12, 13 and 16 points.

    Returns
    -------
    barycentric : (Q, 3) float64
        Barycentric coordinates of the points (rows sum to 1).
    weights : (Q,) float64
        Weights summing to 1 (multiply by the triangle's area).
    """
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)):
        raise TypeError(f"order must be an integer, got {order!r}")
    if int(order) not in _ORBITS:
        raise ValueError(f"order={order} has no rule; expected one of {ORDERS}")
    return _rule(int(order))
