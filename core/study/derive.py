"""Figures derived from one point's sweep: resonance, Q, −3 dB bandwidth, values at frequencies.

Each takes the sweep's frequencies (F,) Hz and a response (F,) (the extinction
cross-section in free space, |R| of the (0, 0) order for an infinite array) and
returns floats, NaN where the figure does not exist in the band (no peak, a peak
whose half-power points fall outside the sweep).

>>> f = np.linspace(5e9, 7e9, 201)
>>> y = 1 / ((f - 6.19e9) ** 2 + 0.1e9**2)
>>> round(resonance(f, y)[0] / 1e9, 9), round(resonance(f, y)[1], 6)
(6.19, 30.95)
>>> round(bandwidth_3db(f, y) / 1e9, 3)
0.2
"""

from __future__ import annotations

import numpy as np

from ..mom.solve import lorentzian_peaks
from .spec import Derive


def resonance(frequencies: np.ndarray, response: np.ndarray) -> tuple[float, float]:
    """The strongest peak's frequency (Hz) and its Q = f0 / (2γ), from the Lorentzian fit.

    The peaks are those of :func:`barymesh.mom.lorentzian_peaks` (the sweep's
    ``resonances`` and ``quality_factors``); the strongest is the one at the largest
    sample. (NaN, NaN) without a peak inside the sweep.
    """
    f = np.asarray(frequencies, dtype=float)
    y = np.asarray(response, dtype=float)
    centres, half_widths = lorentzian_peaks(f, y)
    if len(centres) == 0:
        return float("nan"), float("nan")
    samples = np.interp(centres, f, y)
    k = int(np.argmax(samples))
    return float(centres[k]), float(centres[k] / (2.0 * half_widths[k]))


def bandwidth_3db(frequencies: np.ndarray, response: np.ndarray) -> float:
    """Width (Hz) of the band around the largest sample where ``response`` ≥ half of it.

    The response is a power-like quantity (a cross-section), so −3 dB is one half; the
    two crossings are interpolated linearly between samples. NaN when the response does
    not fall to half on both sides inside the sweep.
    """
    f = np.asarray(frequencies, dtype=float)
    y = np.asarray(response, dtype=float)
    if len(f) < 3 or not np.all(np.isfinite(y)):
        return float("nan")
    top = int(np.argmax(y))
    half = 0.5 * y[top]
    below = y < half
    left = np.flatnonzero(below[:top])
    right = np.flatnonzero(below[top:])
    if len(left) == 0 or len(right) == 0:
        return float("nan")
    i, j = left[-1], top + right[0]  # the last sample below on the left, first on the right
    fl = f[i] + (half - y[i]) * (f[i + 1] - f[i]) / (y[i + 1] - y[i])
    fr = f[j - 1] + (half - y[j - 1]) * (f[j] - f[j - 1]) / (y[j] - y[j - 1])
    return float(fr - fl)


def derived_figures(
    derive: tuple[Derive, ...], table: dict[str, np.ndarray], response: np.ndarray
) -> dict[str, float]:
    """The derived table's columns of one point: ``{column: value}`` in ``derive``'s order.

    ``table`` holds the point's per-frequency columns; ``response`` (F,) is the power-like
    quantity whose peak is the resonance: σ_ext in free space, |R_co|² for an infinite
    array. ``extinction_cross_section_at`` and ``reflection_at`` interpolate
    ``extinction_cross_section_m2`` and ``reflection_co_abs`` linearly.
    """
    frequencies = table["frequency_hz"]
    out: dict[str, float] = {}
    peak: tuple[float, float] | None = None
    for d in derive:
        if d.name in ("resonance_frequency", "quality_factor"):
            peak = resonance(frequencies, response) if peak is None else peak
            value = peak[0] if d.name == "resonance_frequency" else peak[1]
            out[d.columns[0]] = value
        elif d.name == "bandwidth_3db":
            out[d.columns[0]] = bandwidth_3db(frequencies, response)
        else:  # a value at given frequencies, interpolated between samples
            name = "extinction_cross_section_m2"
            if d.name == "reflection_at":
                name = "reflection_co_abs"
            values = np.interp(np.asarray(d.at), frequencies, table[name])
            out.update({c: float(v) for c, v in zip(d.columns, values, strict=True)})
    return out
