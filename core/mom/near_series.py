"""The near pairs' smooth kernel as a power series in k: moment tables once, a sum per frequency.

On a near pair the free-space solver integrates 1/R and R in closed form
(:func:`barymesh.mom.geometry.static_moments`) and the smooth rest by the near rule
(:func:`barymesh.mom.operator.near_moments`)::

    S(R) = (e^(−jkR) − 1 + (kR)²/2) / R = Σ_{n ≥ 1, n ≠ 2} (−jk)ⁿ Rⁿ⁻¹ / n!

The rule's 4 × 4 moments of S are then Σ_n (−jk)ⁿ/n! Mₙ₋₁, with Mₘ the moments of Rᵐ
(frequency-independent, tabulated once per mesh, :func:`power_tables`): per frequency a
sum over tables instead of the kernel at every point pair. The series is cut where
its terms fall below :data:`SERIES_TOLERANCE` of the leading one, at x = k R_max over
the pairs' points; it is used while x ≤ :data:`SERIES_MAX_PHASE` (the terms then
stay under e^x, and their cancellation costs under two digits of double precision).
The result equals :func:`~barymesh.mom.operator.near_moments` to about 1e-12 of its
largest moment (tests/test_mom_near_series.py).
"""

from __future__ import annotations

import math

import numpy as np

from .geometry import MomGeometry
from .operator import near_moments_from_half

#: The series stops where (k R_max)ⁿ/n! falls below this.
SERIES_TOLERANCE = 1e-13
#: Largest k R_max (rad) over a mesh's near pairs for which the series is used.
SERIES_MAX_PHASE = 4.0
#: Most bytes the tables of one mesh may keep (beyond, the kernel is evaluated instead):
#: 128 bytes per pair and term, 29 MB for the 1,452-triangle slot's 14 terms at 28 GHz.
SERIES_MAX_BYTES = 48 * 2**20


def series_terms(phase: float) -> int | None:
    """Terms n = 1..N of the series at k R_max = ``phase``; None beyond :data:`SERIES_MAX_PHASE`.

    >>> series_terms(1.0)
    16
    """
    if not (0.0 <= phase <= SERIES_MAX_PHASE):
        return None
    n, term = 1, phase
    while term > SERIES_TOLERANCE * max(phase, 1e-300) or n < 3:
        n += 1
        term *= phase / n
    return n


def power_tables(geom: MomGeometry, count: int) -> np.ndarray:
    """(count, H, 4, 4) float64: the near rule's moments of Rᵐ, m = 0..count − 1.

    Over the pairs of ``geom.near_upper``, with the frame [w, w ρ] on each triangle as in
    :func:`~barymesh.mom.operator.near_moments`. Kept on the geometry and extended when
    more terms are asked for (read only).
    """
    kept: np.ndarray = geom.__dict__.get("_near_power_tables", np.zeros((0,)))
    have = len(kept)
    if have >= count:
        return kept[:count]
    upper = geom.near_upper
    obs, src = geom.near_pairs[upper, 0], geom.near_pairs[upper, 1]
    w = geom.near.weights[:, :, None]
    frame = np.concatenate([w, w * geom.near.rho], axis=2)  # (T, Qn, 4)
    left = frame[obs].transpose(0, 2, 1)  # (H, 4, Qn)
    right = frame[src]  # (H, Qn, 4)
    out = np.empty((count,) + (len(upper), 4, 4))
    if have:
        out[:have] = kept
    power = geom.near_distances**have  # R^m for the first table not kept
    for m in range(have, count):
        if m > have:
            power *= geom.near_distances
        np.matmul(left, power @ right, out=out[m])
    geom.__dict__["_near_power_tables"] = out  # a frozen dataclass: not setattr
    return out


def near_moments_series(geom: MomGeometry, k: complex) -> np.ndarray | None:
    """(K, 8) complex moments of G over the near pairs, as
    :func:`~barymesh.mom.operator.near_moments`; None when the series does not apply
    (k R_max > :data:`SERIES_MAX_PHASE`, or its tables would exceed
    :data:`SERIES_MAX_BYTES`)."""
    dist = geom.near_distances
    terms = series_terms(abs(k) * float(dist.max()) if dist.size else 0.0)
    if terms is None or terms * dist.shape[0] * 128 > SERIES_MAX_BYTES:
        return None
    tables = power_tables(geom, terms)  # M_m for m = n − 1
    n = np.arange(1, terms + 1)
    coefficients = (-1j * k) ** n / np.array([math.factorial(i) for i in n], dtype=np.float64)
    coefficients[1] = 0.0  # n = 2: cancelled by the (kR)²/2 taken out with R
    flat = tables.reshape(terms, -1)
    m4 = np.empty(flat.shape[1], dtype=np.complex128)
    m4.real = coefficients.real @ flat
    m4.imag = coefficients.imag @ flat
    return near_moments_from_half(geom, m4.reshape(-1, 4, 4), k)
