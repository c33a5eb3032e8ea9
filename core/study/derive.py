"""Figures derived from one point's sweep: resonance, Q, −3 dB bandwidth, values at frequencies,
and for an infinite array the reflection phase and the frequency where it is zero.

Each takes the sweep's frequencies (F,) Hz and a response (F,) (the extinction
cross-section in free space, |R| of the (0, 0) order for an infinite array) and
returns floats, NaN where the figure does not exist in the band (no peak, a peak
whose half-power points fall outside the sweep, a phase that does not pass through 0).

>>> f = np.linspace(5e9, 7e9, 201)
>>> y = 1 / ((f - 6.19e9) ** 2 + 0.1e9**2)
>>> round(resonance(f, y)[0] / 1e9, 9), round(resonance(f, y)[1], 6)
(6.19, 30.95)
>>> round(bandwidth_3db(f, y) / 1e9, 3)
0.2

A grounded slab's reflection phase falls through 0 at its quarter-wave frequency
(here 1.5 mm of vacuum: 50 GHz):

>>> f = np.linspace(40e9, 60e9, 21)
>>> g = (1j * np.tan(2 * np.pi * f * 1.5e-3 / 299792458.0) - 1) / (1j * np.tan(
...     2 * np.pi * f * 1.5e-3 / 299792458.0) + 1)
>>> round(zero_phase_frequency(f, np.degrees(np.angle(g)), np.abs(g))[0] / 1e9, 2)
49.97
"""

from __future__ import annotations

import math

import numpy as np

from ..mom.solve import lorentzian_peaks
from .spec import REFERENCE_PLANE_COLUMN, Derive

#: Largest step of the phase (degrees) between two samples that the zero-phase frequency
#: trusts to have gone the shorter way round (a NaN's note says so above it).
PHASE_STEP = 90.0
#: |R_co| under which its phase is not read (the interpolating sweep's default tolerance,
#: the absolute error of its coefficients): no zero of the phase is looked for there.
PHASE_FLOOR = 1e-3


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


def wrapped(degrees: np.ndarray) -> np.ndarray:
    """Angles (degrees) brought into (−180, 180]."""
    return 180.0 - np.mod(180.0 - np.asarray(degrees, dtype=float), 360.0)


def reflection_phase(
    frequencies: np.ndarray, phase: np.ndarray, at: np.ndarray | tuple[float, ...]
) -> np.ndarray:
    """∠R (degrees, in (−180, 180]) at the frequencies ``at`` (Hz).

    Between two samples the phase goes linearly the shorter way round (``numpy.unwrap``);
    at a sample it is that sample's value exactly.

    >>> reflection_phase(np.array([1.0, 2.0]), np.array([170.0, -170.0]), [1.0, 1.5, 1.75])
    array([ 170.,  180., -175.])
    """
    f = np.asarray(frequencies, dtype=float)
    p = np.asarray(phase, dtype=float)
    x = np.asarray(at, dtype=float)
    out = wrapped(np.interp(x, f, np.degrees(np.unwrap(np.radians(p)))))
    hit = np.searchsorted(f, x).clip(0, len(f) - 1)
    return np.where(f[hit] == x, p[hit], out)


def zero_phase_frequency(
    frequencies: np.ndarray, phase: np.ndarray, magnitude: np.ndarray
) -> tuple[float, tuple[str, ...]]:
    """The lowest frequency (Hz) in the band where ∠R passes through 0, and notes.

    Over a ground plane that is the resonance of a high-impedance surface (an artificial
    magnetic conductor): R = +1 there, where the ground alone gives −1. A passage is a
    change of sign between two samples where the phase goes the shorter way round (not
    the ±180° wrap) and |R| ≥ :data:`PHASE_FLOOR` on both; it is placed by linear
    interpolation of the phase between the two (as fine as the frequency grid).

    Returns
    -------
    frequency : float
        NaN when the phase does not pass through 0 inside the band.
    notes : tuple of str
        Why it is NaN, or the further passages when there are several (one sentence,
        "zero phase: …").
    """
    f = np.asarray(frequencies, dtype=float)
    p = np.asarray(phase, dtype=float)
    m = np.asarray(magnitude, dtype=float)
    band = f"{f[0] / 1e9:.6g}-{f[-1] / 1e9:.6g} GHz" if len(f) else "an empty band"
    usable = np.isfinite(p) & np.isfinite(m) & (m >= PHASE_FLOOR)
    if not usable.any():
        return math.nan, (
            f"zero phase: |R_co| is below {PHASE_FLOOR:g} (or undefined) over {band}, so it "
            "has no phase to pass through 0; zero_phase_frequency_hz is NaN",
        )
    found = list(f[usable & (p == 0.0)])
    step = wrapped(np.diff(p))  # the shorter way round from each sample to the next
    ends = p[:-1] + step
    cross = usable[:-1] & usable[1:] & (p[:-1] * ends < 0.0)
    for i in np.flatnonzero(cross):
        found.append(float(f[i] + (f[i + 1] - f[i]) * p[i] / (p[i] - ends[i])))
    if not found:
        low, high = float(p[usable].min()), float(p[usable].max())
        text = (
            f"zero phase: the phase of R_co does not pass through 0 over {band} (it stays "
            f"between {low:+.4g}° and {high:+.4g}°); zero_phase_frequency_hz is NaN"
        )
        jumps = np.abs(step[usable[:-1] & usable[1:]])
        if len(jumps) and jumps.max() > PHASE_STEP:
            text += (
                f", but it moves by up to {jumps.max():.3g}° from one sample to the next, "
                "too far to tell which way it went: sample more finely"
            )
        return math.nan, (text,)
    found.sort()
    if len(found) == 1:
        return found[0], ()
    others = ", ".join(f"{x / 1e9:.6g}" for x in found[1:])
    return found[0], (
        f"zero phase: the phase of R_co passes through 0 {len(found)} times over {band}, "
        f"at {found[0] / 1e9:.6g} GHz (zero_phase_frequency_hz, the lowest) and also at "
        f"{others} GHz",
    )


def derived_figures(
    derive: tuple[Derive, ...],
    table: dict[str, np.ndarray],
    response: np.ndarray,
    reference_plane: float = 0.0,
) -> tuple[dict[str, float], tuple[str, ...]]:
    """The derived table's columns of one point, and the notes of figures that are NaN.

    ``table`` holds the point's per-frequency columns; ``response`` (F,) is the power-like
    quantity whose peak is the resonance: σ_ext in free space, |R_co|² for an infinite
    array. ``extinction_cross_section_at`` and ``reflection_at`` interpolate
    ``extinction_cross_section_m2`` and ``reflection_co_abs`` linearly,
    ``reflection_phase_at`` ``reflection_co_phase_deg`` (:func:`reflection_phase`);
    ``zero_phase_frequency`` is :func:`zero_phase_frequency`. With a phase figure the
    columns end with ``reflection_reference_plane_mm``: ``reference_plane``, the height
    (mm) over the sheet of the plane R is referred to.

    Returns
    -------
    figures : dict of str to float
        ``{column: value}`` in ``derive``'s order.
    notes : tuple of str
        Sentences "kind: text" on figures that are NaN for a reason worth saying.
    """
    frequencies = table["frequency_hz"]
    out: dict[str, float] = {}
    notes: tuple[str, ...] = ()
    peak: tuple[float, float] | None = None
    phased = False
    for d in derive:
        if d.name in ("resonance_frequency", "quality_factor"):
            peak = resonance(frequencies, response) if peak is None else peak
            value = peak[0] if d.name == "resonance_frequency" else peak[1]
            out[d.columns[0]] = value
        elif d.name == "bandwidth_3db":
            out[d.columns[0]] = bandwidth_3db(frequencies, response)
        elif d.name == "zero_phase_frequency":
            value, why = zero_phase_frequency(
                frequencies, table["reflection_co_phase_deg"], table["reflection_co_abs"]
            )
            out[d.columns[0]] = value
            notes += why
            phased = True
        elif d.name == "reflection_phase_at":
            values = reflection_phase(frequencies, table["reflection_co_phase_deg"], d.at)
            out.update({c: float(v) for c, v in zip(d.columns, values, strict=True)})
            phased = True
        else:  # a value at given frequencies, interpolated between samples
            name = "extinction_cross_section_m2"
            if d.name == "reflection_at":
                name = "reflection_co_abs"
            values = np.interp(np.asarray(d.at), frequencies, table[name])
            out.update({c: float(v) for c, v in zip(d.columns, values, strict=True)})
    if phased:
        out[REFERENCE_PLANE_COLUMN] = float(reference_plane)
    return out, notes
