"""A cell as a circuit: the sheet impedance of an infinite array and its Foster LC fit.

For the (0, 0) Floquet order alone, below the first grating lobe, an infinite array of
metal on a sheet is a shunt impedance Z_s across the transmission line that the stack
makes of a plane wave (:mod:`barymesh.mom.stack`)::

    η0 ──┬── layers above ──┬── layers below ── vacuum, or a short (ground plane)
       top face           sheet: Z_s

A free-standing sheet reflects R = −η0 / (η0 + 2 Z_s). A reflection that a solve or a
sweep found therefore gives Z_s back at every frequency (:func:`sheet_impedance`), and
near its first resonance Z_s is close to the simplest lossless circuit that can have one,
a Foster LC (Foster's reactance theorem: the reactance of a lossless one-port rises with
frequency):

- **series LC** (Z_s = R + jωL + 1/(jωC)): metal in islands, such as patches, rings and
  closed loops. At low frequency the islands are capacitively coupled (the sheet is
  nearly transparent); at ω0 = 1/√(LC) Z_s = 0 and a free-standing sheet reflects all.
- **parallel LC** (1/Z_s = 1/R + jωC + 1/(jωL)): connected metal, such as wire grids
  and apertures (slots) in a screen. At low frequency the sheet shorts the line
  (inductive, reflecting); at ω0 it is an open circuit and a free-standing screen
  passes all.

:func:`equivalent_circuit` fits one or the other to a sweep (which is chosen by the fit,
unless ``kind`` says) and says how far the circuit follows the cell. It stops doing so
above the next resonance of the cell (a second mode the one LC has not got), near a
grating lobe's onset (where the (0, 0) line picture breaks: the sheet's coupling to the
new order is not a lumped element) and where the cell's own current is not the one
mode (a cell strongly coupled to its neighbours).

:func:`luukkonen_patch_reflection` is the analytic model of patches over a grounded
slab of Luukkonen et al. (IEEE Trans. Antennas Propag. 56(6), 1624-1632, 2008): the
patch grid's capacitive impedance −jη_eff / (2α), α = (k_eff D / π) ln(1/sin(π w / 2D)),
with ε_eff = (ε_r + 1)/2, in parallel with the grounded slab's j (η0/√ε_r) tan(k0 √ε_r h),
at normal incidence: the reference the teaching view draws beside the solved curve.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..constants import ETA0, SPEED_OF_LIGHT
from .excitation import PlaneWave
from .stack import Stack, line_section, side, vacuum_admittance

__all__ = [
    "KINDS",
    "EquivalentCircuit",
    "equivalent_circuit",
    "luukkonen_patch_reflection",
    "reflection_from_sheet",
    "sheet_impedance",
]

#: The two Foster circuits of a sheet.
KINDS = ("series", "parallel")
#: |ΔR| between the circuit and the cell up to which the circuit "describes" the cell.
AGREEMENT = 0.05
#: A resistance (series) or conductance (parallel) under this fraction of the sheet's
#: typical |Z_s| (|Y_s|) is the solve's rounding: the circuit is fitted lossless.
LOSSLESS = 1e-4
#: Frequencies this close under an onset (relative) are left out of the fit.
ONSET_MARGIN = 0.02


def _line(
    frequency: float, stack: Stack | None, wave: PlaneWave, polarization: int
) -> tuple[complex, complex, list[tuple[complex, complex]]]:
    """(vacuum's y, far side's y at the sheet, [(y t, t/y) of each near layer, sheet
    outward]) over 1/η0 at ``frequency``, for TE (0) or TM (1)."""
    stack = Stack() if stack is None else stack
    k0 = 2.0 * math.pi * frequency / SPEED_OF_LIGHT
    d = np.asarray(wave.direction, dtype=np.float64)
    kappa2 = np.array([(k0 * math.hypot(d[0], d[1])) ** 2])
    near, far, grounded = stack.sides(from_above=bool(d[2] < 0))
    y0 = complex(vacuum_admittance(kappa2, k0)[0, polarization])
    y_far = complex(side(far, grounded, kappa2, k0).admittance[0, polarization])
    sections = []
    for layer in near:
        if layer.thickness == 0.0:
            continue
        yt, t_over_y, _ = line_section(layer, kappa2, k0)
        sections.append((complex(yt[0, polarization]), complex(t_over_y[0, polarization])))
    return y0, y_far, sections


def _polarization(wave: PlaneWave) -> int:
    """0 (TE) or 1 (TM): the incidence's, which must be one of the two (any at normal)."""
    from .floquet import te_tm_polarizations

    d = np.asarray(wave.direction, dtype=np.float64)
    if math.hypot(d[0], d[1]) < 1e-12:
        return 0  # at normal incidence TE and TM see the same line
    te, tm = te_tm_polarizations(d)
    e = np.asarray(wave.polarization, dtype=np.float64)
    parts = np.abs([np.dot(e, te), np.dot(e, tm)]) / np.linalg.norm(e)
    if parts.max() < 1.0 - 1e-6:
        raise ValueError(
            f"the incidence's polarisation is a mix of TE ({parts[0]:.3f}) and TM "
            f"({parts[1]:.3f}) at oblique incidence: a sheet impedance is per polarisation; "
            "sweep TE or TM alone"
        )
    return int(np.argmax(parts))


def sheet_impedance(
    frequencies: Sequence[float] | np.ndarray,
    reflection: Sequence[complex] | np.ndarray,
    stack: Stack | None = None,
    incidence: PlaneWave | None = None,
) -> np.ndarray:
    """(F,) complex Z_s (Ω) of the sheet that reflects ``reflection`` from the stack.

    ``reflection`` is the co-polar (0, 0) reflection referred to the face the wave falls
    on (as :class:`~barymesh.mom.PeriodicSweep` and the reflection library give it); the
    line through the layers on that side is walked back to the sheet, and the far side's
    admittance taken away. Valid below the first grating lobe (one propagating order).
    """
    f = np.asarray(frequencies, dtype=np.float64)
    r = np.asarray(reflection, dtype=np.complex128)
    if f.shape != r.shape or f.ndim != 1:
        raise ValueError(f"frequencies {f.shape} and reflection {r.shape}: expected two (F,)")
    wave = PlaneWave() if incidence is None else incidence
    p = _polarization(wave)
    out = np.empty(len(f), dtype=np.complex128)
    for i, (fi, ri) in enumerate(zip(f, r, strict=True)):
        y0, y_far, sections = _line(float(fi), stack, wave, p)
        with np.errstate(divide="ignore", invalid="ignore"):
            load = y0 * (1.0 - ri) / (1.0 + ri)  # at the face: R = (y0 − y)/(y0 + y)
            for yt, t_over_y in reversed(sections):  # from the face in to the sheet
                load = (load - yt) / (1.0 - load * t_over_y)
            out[i] = ETA0 / (load - y_far)
    return out


def reflection_from_sheet(
    frequencies: Sequence[float] | np.ndarray,
    impedance: Sequence[complex] | np.ndarray,
    stack: Stack | None = None,
    incidence: PlaneWave | None = None,
) -> np.ndarray:
    """(F,) complex co-polar reflection of a sheet of impedance Z_s (Ω) on ``stack``.

    The inverse of :func:`sheet_impedance`: referred to the face the wave falls on.
    """
    f = np.asarray(frequencies, dtype=np.float64)
    z = np.broadcast_to(np.asarray(impedance, dtype=np.complex128), f.shape)
    wave = PlaneWave() if incidence is None else incidence
    p = _polarization(wave)
    out = np.empty(len(f), dtype=np.complex128)
    for i, (fi, zi) in enumerate(zip(f, z, strict=True)):
        y0, y_far, sections = _line(float(fi), stack, wave, p)
        load = complex(math.inf) if zi == 0 else ETA0 / zi + y_far  # a short, or Y_s ∥ far
        for yt, t_over_y in sections:  # from the sheet out to the face
            load = (
                1.0 / t_over_y if math.isinf(abs(load)) else (load + yt) / (1.0 + load * t_over_y)
            )
        out[i] = -1.0 if math.isinf(abs(load)) else (y0 - load) / (y0 + load)
    return out


@dataclass(frozen=True)
class EquivalentCircuit:
    """A Foster LC fitted to a cell's sheet impedance (see the module's docstring).

    Attributes
    ----------
    kind : {"series", "parallel"}
    inductance : float
        L (H).
    capacitance : float
        C (F).
    resistance : float
        R (Ω): in series with L and C for "series", across them for "parallel" (inf
        for a lossless parallel circuit, 0 for a lossless series one).
    band : (float, float)
        The frequencies (Hz) fitted.
    error : float
        Largest |R_circuit − R_cell| over the fitted band.
    valid_below : float
        Up to this frequency (Hz), from the band's start, the circuit's reflection stays
        within :data:`AGREEMENT` of the cell's; NaN when it is not even at the start.
    stack : Stack or None
    incidence : PlaneWave
    """

    kind: str
    inductance: float
    capacitance: float
    resistance: float
    band: tuple[float, float]
    error: float
    valid_below: float
    stack: Stack | None = None
    incidence: PlaneWave = field(default_factory=PlaneWave)

    @property
    def resonance(self) -> float:
        """f0 = 1 / (2π √(LC)) (Hz): Z_s = R for "series", 1/Z_s = 1/R for "parallel"."""
        return 1.0 / (2.0 * math.pi * math.sqrt(self.inductance * self.capacitance))

    def impedance(self, frequencies: Any) -> np.ndarray:
        """Z_s (Ω) of the circuit at ``frequencies`` (Hz)."""
        w = 2.0 * math.pi * np.asarray(frequencies, dtype=np.float64)
        return _impedance(self.kind, w, self.inductance, self.capacitance, self.resistance)

    def reflection(self, frequencies: Any) -> np.ndarray:
        """The circuit's co-polar reflection on the stack, at the face the wave falls on."""
        f = np.atleast_1d(np.asarray(frequencies, dtype=np.float64))
        return reflection_from_sheet(f, self.impedance(f), self.stack, self.incidence)

    def describe(self) -> str:
        """One line: the circuit, its values and how far it follows the cell."""
        r = (
            f", R = {self.resistance:.3g} Ω"
            if (self.kind == "series" and self.resistance > 0)
            or (self.kind == "parallel" and math.isfinite(self.resistance))
            else ""
        )
        where = (
            f"follows the cell within |ΔR| ≤ {AGREEMENT} up to {self.valid_below / 1e9:.4g} GHz"
            if math.isfinite(self.valid_below)
            else f"does not follow the cell within |ΔR| ≤ {AGREEMENT}"
        )
        return (
            f"{self.kind} LC: L = {self.inductance * 1e9:.4g} nH, "
            f"C = {self.capacitance * 1e15:.4g} fF{r}; resonance {self.resonance / 1e9:.4g} GHz; "
            f"{where} (largest |ΔR| {self.error:.3f} over "
            f"{self.band[0] / 1e9:.4g}–{self.band[1] / 1e9:.4g} GHz)"
        )


def _impedance(kind: str, w: np.ndarray, inductance: float, capacitance: float, r: float):
    if kind == "series":
        return r + 1j * (w * inductance - 1.0 / (w * capacitance))
    g = 0.0 if not math.isfinite(r) else 1.0 / r
    y = g + 1j * (w * capacitance - 1.0 / (w * inductance))
    # at a lossless parallel resonance the sheet is open: an infinite impedance, not NaN
    z = np.full(np.shape(y), complex(math.inf))
    np.divide(1.0, y, out=z, where=y != 0)
    return z


def _linear_fit(kind: str, w: np.ndarray, z: np.ndarray) -> tuple[float, float, float] | None:
    """(L, C, R) by least squares on the reactance (series) or susceptance (parallel),
    each frequency weighted by how much it moves the reflection; None when L or C ≤ 0."""
    if kind == "series":
        value, scale = z, ETA0
    else:
        with np.errstate(divide="ignore", invalid="ignore"):
            value, scale = 1.0 / z, 1.0 / ETA0
    # a sample on a resonance of the other kind (a short sheet seen as an admittance, an
    # open one as an impedance) is infinite: no row of this fit (LAPACK refused the NaN)
    usable = np.isfinite(value)
    if usable.sum() < 2:
        return None
    w, value = w[usable], value[usable]
    weight = 1.0 / (np.abs(value) + scale)
    w_ref = float(np.sqrt(w[0] * w[-1]))  # columns of one size: ω/ω_ref and ω_ref/ω
    u = w / w_ref
    a = np.column_stack([u, -1.0 / u]) * weight[:, None]
    (y1, y2), *_ = np.linalg.lstsq(a, value.imag * weight, rcond=None)
    x1, x2 = y1 / w_ref, y2 * w_ref  # L and 1/C (series), C and 1/L (parallel)
    if not (x1 > 0 and x2 > 0):
        return None
    real = float(np.sum(value.real * weight) / np.sum(weight))
    if real < LOSSLESS * float(np.median(np.abs(value))):
        real = 0.0  # the solver's rounding, not a loss: a lossless circuit
    if kind == "series":
        return float(x1), float(1.0 / x2), max(real, 0.0)
    return float(1.0 / x2), float(x1), (1.0 / real if real > 0 else math.inf)


def equivalent_circuit(
    frequencies: Sequence[float] | np.ndarray,
    reflection: Sequence[complex] | np.ndarray,
    stack: Stack | None = None,
    incidence: PlaneWave | None = None,
    kind: str | None = None,
    band: tuple[float, float] | None = None,
    onsets: Sequence[float] = (),
) -> EquivalentCircuit:
    """The Foster LC whose sheet reflects most like ``reflection`` (see the module).

    Parameters
    ----------
    frequencies, reflection : (F,)
        Hz, and the co-polar (0, 0) reflection at the face the wave falls on.
    stack : Stack, optional
    incidence : PlaneWave, optional
        Default normal incidence from above.
    kind : {"series", "parallel"}, optional
        Default: both are fitted, the one closer to the cell kept.
    band : (float, float), optional
        Hz: fit only these frequencies (default all).
    onsets : sequence of float
        Hz: grating-lobe (and guided-order) onsets; the fit stops :data:`ONSET_MARGIN`
        under the first.

    Raises
    ------
    ValueError
        With fewer than 3 frequencies left to fit, or when no circuit of positive L and C
        fits (the cell is not one resonator there).
    """
    from scipy.optimize import least_squares

    if kind is not None and kind not in KINDS:
        raise ValueError(f"kind={kind!r}; expected one of {KINDS} or None (choose by the fit)")
    f = np.asarray(frequencies, dtype=np.float64)
    r = np.asarray(reflection, dtype=np.complex128)
    if f.shape != r.shape or f.ndim != 1:
        raise ValueError(f"frequencies {f.shape} and reflection {r.shape}: expected two (F,)")
    keep = np.isfinite(r) & (f > 0)
    if band is not None:
        lo, hi = (float(x) for x in band)
        if not lo < hi:
            raise ValueError(f"band={band!r}: expected (start, stop) with start < stop (Hz)")
        keep &= (f >= lo) & (f <= hi)
    first_onset = min((float(x) for x in onsets if x > 0), default=math.inf)
    keep &= f < first_onset * (1.0 - ONSET_MARGIN)
    if keep.sum() < 3:
        raise ValueError(
            f"{int(keep.sum())} frequencies to fit (below the first onset "
            f"{first_onset / 1e9:.4g} GHz and inside the band); the fit needs at least 3"
        )
    f, r = f[keep], r[keep]
    wave = PlaneWave() if incidence is None else incidence
    z = sheet_impedance(f, r, stack, wave)
    w = 2.0 * math.pi * f
    found = []
    for name in KINDS if kind is None else (kind,):
        start = _linear_fit(name, w, z)
        if start is None:
            continue
        inductance, capacitance, resistance = start
        lossy = 0.0 < resistance < math.inf

        def residual(x: np.ndarray, name: str = name, lossy: bool = lossy) -> np.ndarray:
            l_, c_ = math.exp(x[0]), math.exp(x[1])
            res = math.exp(x[2]) if lossy else (0.0 if name == "series" else math.inf)
            model = reflection_from_sheet(f, _impedance(name, w, l_, c_, res), stack, wave)
            d = model - r
            return np.concatenate([d.real, d.imag])

        x0 = [math.log(inductance), math.log(capacitance)]
        if lossy:
            x0.append(math.log(max(resistance, 1e-6)))
        fit = least_squares(residual, np.array(x0), x_scale=1.0)
        inductance, capacitance = math.exp(fit.x[0]), math.exp(fit.x[1])
        if lossy:
            resistance = math.exp(fit.x[2])
        else:
            resistance = 0.0 if name == "series" else math.inf
        model = reflection_from_sheet(
            f, _impedance(name, w, inductance, capacitance, resistance), stack, wave
        )
        gap = np.abs(model - r)
        found.append((float(gap.max()), name, inductance, capacitance, resistance, gap))
    if not found:
        raise ValueError(
            "no Foster LC of positive L and C fits this reflection: the cell is not one "
            "resonator in the band (narrow the band, or fit around one resonance)"
        )
    error, name, inductance, capacitance, resistance, gap = min(found, key=lambda t: t[0])
    bad = np.flatnonzero(gap > AGREEMENT)
    if not len(bad):
        valid = float(f[-1])
    elif bad[0] == 0:
        valid = math.nan
    else:
        valid = float(f[bad[0] - 1])
    return EquivalentCircuit(
        kind=name,
        inductance=inductance,
        capacitance=capacitance,
        resistance=resistance,
        band=(float(f[0]), float(f[-1])),
        error=error,
        valid_below=valid,
        stack=stack,
        incidence=wave,
    )


def luukkonen_patch_reflection(
    frequencies: Any, period: float, gap: float, thickness: float, eps_r: float
) -> np.ndarray:
    """Reflection of square patches over a grounded slab, Luukkonen et al.'s model (2008).

    Normal incidence, referred to the patches' plane (the slab's top face); lengths in
    mm, ``gap`` the width between neighbouring patches. The model's grid impedance is
    quasi-static: it holds while the period is well under a wavelength in the slab.
    """
    for name, value in (("period", period), ("gap", gap), ("thickness", thickness)):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name}={value!r} mm: expected a positive length")
    if not gap < period:
        raise ValueError(f"gap={gap!r} mm must be smaller than period={period!r} mm")
    if not (math.isfinite(eps_r) and eps_r >= 1):
        raise ValueError(f"eps_r={eps_r!r}: expected a relative permittivity ≥ 1")
    f = np.asarray(frequencies, dtype=np.float64)
    k0 = 2.0 * np.pi * f / SPEED_OF_LIGHT
    eps_eff = (eps_r + 1.0) / 2.0
    alpha = (k0 * math.sqrt(eps_eff) * period * 1e-3 / math.pi) * math.log(
        1.0 / math.sin(math.pi * gap / (2.0 * period))
    )
    grid = -1j * (ETA0 / math.sqrt(eps_eff)) / (2.0 * alpha)
    slab = 1j * (ETA0 / math.sqrt(eps_r)) * np.tan(k0 * math.sqrt(eps_r) * thickness * 1e-3)
    surface = grid * slab / (grid + slab)
    return (surface - ETA0) / (surface + ETA0)
