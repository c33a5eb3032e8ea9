"""A reflectarray laid out from a reflection-phase library: phases, parameters, pattern.

The feed at r_f lights element i, at r_i on the aperture (z = 0), over the path
d_i = |r_i − r_f|, which delays it by k d_i. The element re-radiates with the phase φ_i of
its cell's reflection; towards û its field is advanced by k r_i · û. The beam points at
û_b when the fields add in phase there::

    φ_i − k d_i + k r_i · û_b = const   ⇒   φ_i = k (d_i − r_i · û_b) + C

(time convention e^(jωt), the solver's and the library's: a longer path is a phase
*lag*, which the element makes up by a phase lead; with e^(−iωt) both signs flip). The
constant C is free: it is chosen so that the phases the cells must give fall where the
library's S-curve reaches them (:func:`design`).

Each element is then the library's cell with the parameter whose phase is closest to its
φ_i (modulo 360°), as if it sat in an infinite array of copies of itself: the
*local-periodicity approximation*, which ignores that its neighbours differ (mutual
coupling between unlike cells), the incidence angle of the feed's ray (the library's own
incidence is used for every cell) and the feed's blockage of the reflected beam.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from ..cell.model import Lattice, UnitCell
from ..constants import SPEED_OF_LIGHT_MM
from ..mom.reflection_library import ReflectionLibrary
from . import pattern as far

#: The feed's pattern is cos^q of the angle off its axis: q = 6.5 puts the edge of an
#: aperture seen at ±30° from the feed about 9 dB down (cos^6.5 30° = 0.39, −8.1 dB in
#: field, and the longer path adds −1.2 dB), near the usual −10 dB edge taper of a horn.
DEFAULT_FEED_Q = 6.5
#: The element's pattern is cos^qe θ, in reception (the angle of the feed's ray) and in
#: radiation: qe = 1, a patch over a ground plane.
DEFAULT_ELEMENT_Q = 1.0
#: The quantisations :func:`design` knows: None (continuous) or 1, 2, 3 bits.
BITS = (None, 1, 2, 3)
#: Largest number of elements of a design (memory of the pattern's grids).
MAX_ELEMENTS = 250_000
#: Steps (degrees) of the scan of the phase constant and of the table of phase errors.
_CONSTANT_STEP = 0.25
_TABLE_STEP = 0.05


def textbook_quantization_loss(bits: int) -> float:
    """The loss of directivity (dB, negative) of a ``bits``-bit phase quantisation.

    Quantising to 2^b levels leaves each element a phase error spread evenly over
    ±180°/2^b; the main beam's field falls to the mean of e^(jε), sinc(π/2^b), while the
    radiated power stays (the lost part goes into side lobes): 20 log10 sinc(π/2^b).

    >>> [round(textbook_quantization_loss(b), 2) for b in (1, 2, 3)]
    [-3.92, -0.91, -0.22]
    """
    if bits not in (1, 2, 3) or isinstance(bits, bool):
        raise ValueError(f"bits={bits!r} is invalid; expected 1, 2 or 3")
    return 20.0 * math.log10(float(np.sinc(1.0 / 2**bits)))


def wrapped(deg: np.ndarray) -> np.ndarray:
    """Degrees wrapped to (−180, 180].

    >>> wrapped(np.array([180.0, -180.0, 190.0, 360.0]))
    array([ 180.,  180., -170.,    0.])
    """
    return 180.0 - np.mod(180.0 - np.asarray(deg, dtype=float), 360.0)


@dataclass(frozen=True)
class CurvePoint:
    """Points of the library's S-curve: the parameter, its phase and |R| (each (N,))."""

    parameter: np.ndarray
    phase: np.ndarray
    magnitude: np.ndarray
    distance: np.ndarray  # degrees from the phase asked for, modulo 360


def closest_on_curve(
    wanted: np.ndarray, values: np.ndarray, phase: np.ndarray, magnitude: np.ndarray
) -> CurvePoint:
    """The point of the piecewise-linear S-curve whose phase is nearest ``wanted`` mod 360.

    The curve joins the samples (value, phase, |R|) in their order by straight segments,
    as :meth:`barymesh.mom.ReflectionLibrary.lookup` interpolates it. A phase the curve
    reaches gets the first segment (in the values' order) that reaches it, the value
    ``lookup`` gives; one it does not reach gets the nearer end of the closest segment,
    measured modulo 360° (the end of the covered range on the shorter way round).

    Parameters
    ----------
    wanted : (N,) float
        Degrees.
    values, phase, magnitude : (V,) float
        The curve's samples (phase unwrapped: no step over 180°).

    Returns
    -------
    CurvePoint
    """
    wanted = np.asarray(wanted, dtype=float)
    if len(values) == 1:
        n = len(wanted)
        d = np.abs(wrapped(phase[0] - wanted))
        return CurvePoint(np.full(n, values[0]), np.full(n, phase[0]), np.full(n, magnitude[0]), d)
    p0, p1 = phase[:-1], phase[1:]  # (K,) segments
    lo, hi = np.minimum(p0, p1), np.maximum(p0, p1)
    mid = 0.5 * (lo + hi)
    # wanted + 360 m nearest the segment's middle, then the nearest point of the segment:
    # a segment spans at most 180°, so no other turn is closer
    s = wanted[:, None] + 360.0 * np.round((mid - wanted[:, None]) / 360.0)
    c = np.clip(s, lo, hi)
    dist = np.abs(s - c)  # (N, K)
    dist[dist <= 1e-9 * np.maximum(1.0, np.abs(s))] = 0.0  # reached: the first segment wins
    seg = np.argmin(dist, axis=1)
    rows = np.arange(len(wanted))
    step = p1 - p0
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.where(step[seg] != 0, (c[rows, seg] - p0[seg]) / step[seg], 0.0)
    par = values[seg] + t * (values[seg + 1] - values[seg])
    ph = p0[seg] + t * step[seg]
    mag = magnitude[seg] + t * (magnitude[seg + 1] - magnitude[seg])
    return CurvePoint(par, ph, mag, dist[rows, seg])


def _level_offset(bits: int, curve: tuple[np.ndarray, np.ndarray, np.ndarray]) -> float:
    """ψ0 (degrees, in [0, 360/2^b)) of the levels ψ0 + m 360/2^b the library gives best.

    The levels keep their spacing; ψ0 slides them (0.25° steps) to where the curve's
    closest points miss them least (RMS over the levels): inside a curve that covers
    more than 360° − 360/2^b, every level is met exactly.
    """
    n = 2**bits
    offsets = np.arange(0.0, 360.0 / n, _CONSTANT_STEP)
    levels = (offsets[:, None] + np.arange(n) * 360.0 / n).ravel()
    miss = closest_on_curve(levels, *curve).distance.reshape(len(offsets), n)
    return float(offsets[np.argmin((miss**2).sum(axis=1))])


def _levels(
    bits: int, offset: float, curve: tuple[np.ndarray, np.ndarray, np.ndarray]
) -> tuple[np.ndarray, CurvePoint]:
    """The 2^b level phases (degrees) from ``offset`` and the curve's closest point to each."""
    n = 2**bits
    levels = offset + np.arange(n) * 360.0 / n
    return levels, closest_on_curve(levels, *curve)


def _level_index(phase: np.ndarray, bits: int, offset: float) -> np.ndarray:
    """(N,) int: the level nearest each phase (degrees), levels ``offset`` + m 360/2^b."""
    n = 2**bits
    return np.round(np.mod(phase - offset, 360.0) / (360.0 / n)).astype(int) % n


def _best_constant(
    phase0: np.ndarray,
    weights: np.ndarray,
    curve: tuple[np.ndarray, np.ndarray, np.ndarray],
    bits: int | None,
    offset: float,
) -> float:
    """The constant C (degrees) that minimises the weighted RMS phase error of the design.

    Every C of a 0.25° grid over [0, 360) is tried: the error of an element depends only
    on (φ_i + C) modulo 360, read from a table of the error against the phase (every
    0.05°). Continuous: the distance to the curve (0 where the curve reaches the phase).
    Quantised: the phase goes to the nearest level (``offset`` + m 360/2^b), whose closest
    point of the curve gives it, so the error is that point's phase minus the phase.
    """
    grid = np.arange(0.0, 360.0, _TABLE_STEP)
    if bits is None:
        table = closest_on_curve(grid, *curve).distance ** 2
    else:
        _, at = _levels(bits, offset, curve)
        table = wrapped(at.phase[_level_index(grid, bits, offset)] - grid) ** 2
    constants = np.arange(0.0, 360.0, _CONSTANT_STEP)
    w = weights / weights.sum()
    cost = np.empty(len(constants))
    for m, c in enumerate(constants):
        x = np.mod(phase0 + c, 360.0)
        cost[m] = w @ np.interp(x, grid, table, period=360.0)
    return float(constants[np.argmin(cost)])


def _lattice(lib: ReflectionLibrary, period: Any) -> Lattice:
    cell = lib.cell
    if period is None:
        if cell is None:
            raise ValueError(
                "the library has no cell (it was not made by reflection_library), so its "
                "lattice is unknown; give period= in mm (one period, or (px, py))"
            )
        return cell.lattice
    try:
        if isinstance(period, int | float | np.integer | np.floating) and not isinstance(
            period, bool
        ):
            lattice = Lattice.rectangular(float(period))
        else:
            px, py = period
            lattice = Lattice.rectangular(px, py)
    except (TypeError, ValueError):
        raise ValueError(
            f"period={period!r:.60} is invalid; expected a period in mm or (px, py)"
        ) from None
    if cell is not None and lattice != cell.lattice:
        raise ValueError(
            f"period={period!r} differs from the library's cell's lattice a1={cell.lattice.a1}, "
            f"a2={cell.lattice.a2}; leave period out to use the cell's"
        )
    return lattice


def _aperture(aperture: Any) -> tuple[int, int]:
    ok = (
        isinstance(aperture, tuple | list)
        and len(aperture) == 2
        and all(isinstance(n, int | np.integer) and not isinstance(n, bool) for n in aperture)
        and all(n > 0 for n in aperture)
    )
    if not ok:
        raise ValueError(
            f"aperture={aperture!r:.60} is invalid; expected two positive whole numbers "
            "(elements along the lattice's a1 and a2), e.g. (15, 15)"
        )
    n1, n2 = int(aperture[0]), int(aperture[1])
    if n1 * n2 > MAX_ELEMENTS:
        raise ValueError(
            f"aperture={aperture!r} has {n1 * n2:,} elements; expected at most {MAX_ELEMENTS:,}"
        )
    return n1, n2


def _numbers(name: str, value: Any, count: int, what: str) -> tuple[float, ...]:
    try:
        x = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        x = np.array([])
    if x.shape != (count,) or not np.all(np.isfinite(x)) or isinstance(value, str):
        raise ValueError(f"{name}={value!r:.60} is invalid; expected {what}")
    return tuple(float(a) for a in x)


def _exponent(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise ValueError(f"{name}={value!r:.40} is invalid; expected a number >= 0")
    if not (math.isfinite(value) and value >= 0):
        raise ValueError(f"{name}={value!r} is invalid; expected a finite number >= 0")
    return float(value)


def design(
    lib: ReflectionLibrary,
    aperture: tuple[int, int],
    feed: tuple[float, float, float],
    beam: tuple[float, float],
    frequency: float,
    bits: int | None = None,
    *,
    q: float = DEFAULT_FEED_Q,
    element_q: float = DEFAULT_ELEMENT_Q,
    period: float | tuple[float, float] | None = None,
) -> Reflectarray:
    """Lay out a reflectarray: the phase and the parameter of every element.

    Parameters
    ----------
    lib : ReflectionLibrary
        The cell's S-curve (:func:`barymesh.mom.reflection_library`), at ``frequency``.
    aperture : (N1, N2) int
        Elements along the lattice vectors a1 and a2 of the library's cell; element
        (i, j) sits at ``(i − (N1 − 1)/2) a1 + (j − (N2 − 1)/2) a2`` (mm, z = 0), the
        aperture centred on the origin.
    feed : (x, y, z)
        The feed's phase centre (mm), above the aperture (z > 0). Its pattern is
        cos^q of the angle off its axis, which points at the origin.
    beam : (theta, phi)
        The direction of the main beam (degrees, 0 ≤ theta < 90).
    frequency : float
        Hz, one of the library's frequencies.
    bits : None, 1, 2 or 3
        None: each element gets the phase it needs (continuous). 1, 2, 3: the phase is
        quantised to 2^bits levels, and each level is given by the library's parameter
        whose phase is closest to it (the same parameter for all the elements of a level).
    q : float
        The feed's exponent (default :data:`DEFAULT_FEED_Q`).
    element_q : float
        The element's exponent, in reception and radiation (default
        :data:`DEFAULT_ELEMENT_Q`, cos θ).
    period : float or (px, py), optional
        The lattice's periods (mm) of a library without a cell (made by hand or read from
        elsewhere); a library from :func:`barymesh.mom.reflection_library` keeps its cell,
        whose lattice is used.

    The phase each element needs is φ_i = k (d_i − r_i · û_b) + C (module docstring); C
    is scanned over 360° (0.25° steps) and the one with the smallest RMS phase error after
    the choice of parameters is kept, each element's error weighted by its illumination.
    A phase the curve does not reach (a curve covering 330° leaves a 30° gap) is given the
    curve's nearest end modulo 360° (:func:`closest_on_curve`).

    Returns
    -------
    Reflectarray

    Raises
    ------
    ValueError
        ``aperture`` not two positive whole numbers, a ``feed`` on or below the aperture's
        plane, ``beam`` theta not in [0, 90), ``bits`` not None, 1, 2 or 3, a
        ``frequency`` the library has not, or a library without a cell and no ``period``.

    Examples
    --------
    >>> from barymesh.mom import ReflectionLibrary
    >>> values = np.linspace(0.0, 1.0, 12)  # a made-up S-curve: 330° over the values
    >>> r = np.zeros((12, 1, 2, 2), complex)
    >>> r[:, 0, 1, 1] = np.exp(1j * np.radians(165.0 - 330.0 * values))
    >>> lib = ReflectionLibrary("x", values, np.array([10e9]), r, "TM",
    ...                         {"theta": 0.0, "phi": 0.0, "pol": "TM"}, 0.0)
    >>> ra = design(lib, (20, 20), (0.0, 0.0, 250.0), (20.0, 0.0), 10e9, period=15.0)
    >>> ra.positions.shape, ra.parameter.shape
    ((400, 3), (400,))
    >>> theta, phi = ra.beam_direction
    >>> bool(abs(theta - 20.0) < 0.5)
    True
    """
    if not isinstance(lib, ReflectionLibrary):
        raise ValueError(
            f"lib is a {type(lib).__name__}; expected a ReflectionLibrary "
            "(barymesh.mom.reflection_library)"
        )
    n1, n2 = _aperture(aperture)
    xf, yf, zf = _numbers("feed", feed, 3, "three numbers (x, y, z) in mm")
    if zf == 0.0:
        raise ValueError(
            f"feed={feed!r} lies in the aperture's plane (z = 0); expected the feed above it, "
            "z > 0 mm"
        )
    if zf < 0.0:
        raise ValueError(
            f"feed={feed!r} is below the aperture (z < 0); the cells reflect waves coming "
            "from above: expected z > 0 mm"
        )
    theta_b, phi_b = _numbers("beam", beam, 2, "two angles (theta, phi) in degrees")
    if not 0.0 <= theta_b < 90.0:
        raise ValueError(
            f"beam theta={theta_b:g} is invalid; expected 0 <= theta < 90 degrees (the beam "
            "leaves the aperture's front)"
        )
    if bits not in BITS or isinstance(bits, bool):
        raise ValueError(f"bits={bits!r} is invalid; expected None (continuous), 1, 2 or 3")
    bits = None if bits is None else int(bits)  # 2.0 or numpy's 2: the int
    j = lib.frequency_index(frequency)
    q = _exponent("q", q)
    element_q = _exponent("element_q", element_q)
    lattice = _lattice(lib, period)
    f = float(lib.frequencies[j])

    a1, a2 = np.asarray(lattice.a1), np.asarray(lattice.a2)
    ii, jj = np.meshgrid(np.arange(n1), np.arange(n2), indexing="ij")
    indices = np.stack([ii.ravel(), jj.ravel()], axis=1)
    xy = far.centred(n1)[ii.ravel(), None] * a1 + far.centred(n2)[jj.ravel(), None] * a2
    positions = np.column_stack([xy, np.zeros(len(xy))])
    r_f = np.array([xf, yf, zf])
    k = 2.0 * math.pi * f / SPEED_OF_LIGHT_MM
    t, p = math.radians(theta_b), math.radians(phi_b)
    u_b = np.array([math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)])
    ray = positions - r_f
    d = np.linalg.norm(ray, axis=1)
    phase0 = np.degrees(k * (d - positions @ u_b))
    weights = _illumination(positions, r_f, q, element_q)

    curve = (np.asarray(lib.values, float), lib.phase_deg[:, j], lib.magnitude[:, j])
    offset = 0.0 if bits is None else _level_offset(bits, curve)
    c = _best_constant(np.mod(phase0, 360.0), weights, curve, bits, offset)
    required = wrapped(phase0 + c)
    if bits is None:
        target = required
        point = closest_on_curve(required, *curve)
    else:
        level = _level_index(required, bits, offset)
        levels, at_levels = _levels(bits, offset, curve)
        target = wrapped(levels[level])
        point = CurvePoint(
            at_levels.parameter[level],
            at_levels.phase[level],
            at_levels.magnitude[level],
            at_levels.distance[level],
        )
    out = Reflectarray(
        library=lib,
        frequency=f,
        aperture=(n1, n2),
        lattice=lattice,
        feed=(xf, yf, zf),
        beam=(theta_b, phi_b),
        bits=bits,
        q=q,
        element_q=element_q,
        phase_constant=c,
        positions=positions,
        indices=indices,
        required_phase=required,
        target_phase=target,
        parameter=point.parameter,
        achieved_phase=point.phase,
        magnitude=point.magnitude,
    )
    for a in (positions, indices, required, target, point.parameter, point.phase):
        a.setflags(write=False)
    point.magnitude.setflags(write=False)
    return out


def _illumination(positions: np.ndarray, r_f: np.ndarray, q: float, element_q: float) -> np.ndarray:
    """(N,) float: the field amplitude each element receives and re-radiates, |R| aside.

    cos^q of the angle between the feed's axis (towards the origin) and its ray to the
    element, over the ray's length (a spherical wave), times cos^qe of the ray's angle of
    incidence on the aperture (the element's pattern in reception).
    """
    ray = positions - r_f
    d = np.linalg.norm(ray, axis=1)
    axis = -r_f / np.linalg.norm(r_f)
    off_axis = np.clip((ray @ axis) / d, 0.0, 1.0)
    incidence = np.clip(r_f[2] / d, 0.0, 1.0)
    return off_axis**q * incidence**element_q / d


@dataclass(frozen=True, eq=False)
class Reflectarray:
    """A reflectarray laid out by :func:`design`: one row per element.

    Elements are numbered n = i · N2 + j, (i, j) their place along a1 and a2. Phases are
    in degrees, time convention e^(jωt).

    Attributes
    ----------
    library : ReflectionLibrary
    frequency : float
        Hz.
    aperture : (N1, N2)
    lattice : Lattice
        The cells' lattice (mm).
    feed : (x, y, z)
        mm.
    beam : (theta, phi)
        The requested beam (degrees).
    bits : int or None
    q, element_q : float
        The feed's and the element's cos exponents.
    phase_constant : float
        C of the phase condition (degrees), as chosen.
    positions : (N, 3) float
        The elements' centres (mm), z = 0.
    indices : (N, 2) int
        (i, j) of each element.
    required_phase : (N,) float
        k (d_i − r_i · û_b) + C, wrapped to (−180, 180].
    target_phase : (N,) float
        The phase asked of the library: ``required_phase``, or its quantisation level.
    parameter : (N,) float
        The library's parameter chosen for each element.
    achieved_phase : (N,) float
        The library's phase at that parameter (on its unwrapped curve).
    magnitude : (N,) float
        |R| there.
    """

    library: ReflectionLibrary
    frequency: float
    aperture: tuple[int, int]
    lattice: Lattice
    feed: tuple[float, float, float]
    beam: tuple[float, float]
    bits: int | None
    q: float
    element_q: float
    phase_constant: float
    positions: np.ndarray
    indices: np.ndarray
    required_phase: np.ndarray
    target_phase: np.ndarray
    parameter: np.ndarray
    achieved_phase: np.ndarray
    magnitude: np.ndarray

    def __repr__(self) -> str:
        n1, n2 = self.aperture
        bits = "continuous" if self.bits is None else f"bits={self.bits}"
        return (
            f"Reflectarray({n1} x {n2}, {self.frequency / 1e9:g} GHz, feed={self.feed}, "
            f"beam={self.beam}, {bits}, {self.library.parameter!r})"
        )

    @property
    def phase_error(self) -> np.ndarray:
        """(N,) float: achieved − required phase, wrapped to (−180, 180]."""
        return wrapped(self.achieved_phase - self.required_phase)

    @property
    def wavenumber(self) -> float:
        """k = 2π f / c (rad/mm)."""
        return 2.0 * math.pi * self.frequency / SPEED_OF_LIGHT_MM

    @cached_property
    def excitation(self) -> np.ndarray:
        """(N,) complex: the field each element re-radiates, |R| e^(j(φ − k d)) × illumination.

        The illumination is cos^q of the feed's angle off its axis over the distance,
        times cos^qe of the ray's angle of incidence (the element in reception).
        """
        r_f = np.asarray(self.feed)
        d = np.linalg.norm(self.positions - r_f, axis=1)
        amp = _illumination(self.positions, r_f, self.q, self.element_q) * self.magnitude
        return amp * np.exp(1j * (np.radians(self.achieved_phase) - self.wavenumber * d))

    def _grid(self) -> np.ndarray:
        return self.excitation.reshape(self.aperture)

    def _vectors(self) -> tuple[np.ndarray, np.ndarray]:
        return np.asarray(self.lattice.a1), np.asarray(self.lattice.a2)

    @cached_property
    def radiated_power(self) -> float:
        """∫ |E|² dΩ of the model's pattern over the half space in front (pattern units).

        Exact for the model (:func:`barymesh.reflectarray.pattern.radiated_power`), so it
        counts only what the array factor sends into real directions: the part of a
        quantised aperture's spectrum beyond the visible disc, or near grazing where
        cos^qe θ is small, is missing from it, though a lossless surface would re-radiate
        it somewhere (the local-periodicity model does not say where).
        """
        return far.radiated_power(self._grid(), *self._vectors(), self.wavenumber, self.element_q)

    @cached_property
    def intercepted_power(self) -> float:
        """The power the aperture receives from the feed, in the pattern's units.

        An aperture whose cells re-radiate a_i each (|a_i| the illumination, cell area A)
        sends λ² Σ |a_i|² / A into the half space when its phase varies slowly (Parseval:
        a uniform aperture then has the gain 4π N A / λ²). With |R| = 1 that is what a
        lossless surface reflects, whatever the phases; |R| < 1 loses the rest. Spill-over
        (the feed's power that misses the aperture) is not in it.
        """
        wavelength = 2.0 * math.pi / self.wavenumber
        r_f = np.asarray(self.feed)
        amp = _illumination(self.positions, r_f, self.q, self.element_q)
        return float(wavelength**2 * np.sum(amp**2) / self.lattice.area)

    def _field_uv(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        e = far.array_field(self._grid(), *self._vectors(), self.wavenumber, u, v, self.element_q)
        return e * math.sqrt(4.0 * math.pi / self.intercepted_power)

    def pattern(self, theta: Any, phi: Any) -> np.ndarray:
        """The far field towards (theta, phi) (degrees), normalised so |E|² is the gain.

        Element pattern × array factor in the local-periodicity approximation:
        cos^qe θ Σ_i a_i e^(j k û · r_i), a_i :attr:`excitation`; 0 behind the aperture
        (θ ≥ 90°). |E|² is the gain over the power the aperture intercepts
        (:attr:`intercepted_power`: |R| < 1 is a loss, the spill-over is not counted).

        Parameters
        ----------
        theta, phi : float or array of float
            Degrees; broadcast together.

        Returns
        -------
        complex ndarray
            Shaped as the broadcast of ``theta`` and ``phi``.
        """
        t, p = np.broadcast_arrays(np.radians(theta), np.radians(phi))
        u = (np.sin(t) * np.cos(p)).ravel()
        v = (np.sin(t) * np.sin(p)).ravel()
        e = self._field_uv(u, v)
        e[(np.cos(t) <= 0).ravel()] = 0.0
        return e.reshape(t.shape)

    def pattern_db(self, theta: Any, phi: Any) -> np.ndarray:
        """The gain towards (theta, phi) (dBi; −inf behind the aperture): 20 log10 |pattern|."""
        with np.errstate(divide="ignore"):
            return 20.0 * np.log10(np.abs(self.pattern(theta, phi)))

    @cached_property
    def _beam(self) -> tuple[float, float, float]:
        """(u, v, |E|²) of the main beam: the pattern's peak nearest the requested beam."""
        from scipy.optimize import minimize

        t, p = np.radians(self.beam)
        start = np.array([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p)])
        size = np.array(self.aperture) * [self.lattice.size] * 1.0
        width = (2 * math.pi / self.wavenumber) / size.max()  # λ/D, a beamwidth in u

        def minus(uv: np.ndarray) -> float:
            return -float(np.abs(self._field_uv(uv[:1], uv[1:]))[0] ** 2)

        # the grid's peak nearest the start, then the simplex from there
        u, v, power = self._pattern_grid
        peaks = far.local_maxima(power)
        if len(peaks):
            du = u[peaks[:, 0], peaks[:, 1]] - start[0]
            dv = v[peaks[:, 0], peaks[:, 1]] - start[1]
            near = np.hypot(du, dv) < 1.5 * width
            if near.any():
                best = peaks[near][np.argmax(power[peaks[near][:, 0], peaks[near][:, 1]])]
                start = np.array([u[best[0], best[1]], v[best[0], best[1]]])
        simplex = [start, start + [0.1 * width, 0.0], start + [0.0, 0.1 * width]]
        res = minimize(
            minus,
            start,
            method="Nelder-Mead",
            options={"initial_simplex": simplex, "xatol": 1e-9, "fatol": 1e-12, "maxiter": 2000},
        )
        return float(res.x[0]), float(res.x[1]), -float(res.fun)

    @cached_property
    def _pattern_grid(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        u, v, power = far.pattern_grid(
            self._grid(), *self._vectors(), self.wavenumber, self.element_q
        )
        return u, v, power * (4.0 * math.pi / self.intercepted_power)

    @property
    def beam_direction(self) -> tuple[float, float]:
        """(theta, phi) of the main beam (degrees): the peak nearest the requested beam.

        Found on a grid of the pattern fine enough for every lobe, then refined by a
        simplex search. phi is in (−180, 180].
        """
        u, v, _ = self._beam
        s = min(1.0, math.hypot(u, v))
        return math.degrees(math.asin(s)), math.degrees(math.atan2(v, u))

    @property
    def gain(self) -> float:
        """Gain of the main beam (dBi) over the power the aperture intercepts.

        Spill-over aside, this is what a lossless reflectarray gives: all the power it
        receives is reflected, and the main beam gets the coherent part of it.
        """
        return 10.0 * math.log10(self._beam[2])

    @property
    def directivity(self) -> float:
        """Directivity of the main beam (dBi) over the model pattern's own radiated power.

        Equal to :attr:`gain` within a few tenths of a dB for a continuous design; a
        quantised one loses less directivity than gain, since :attr:`radiated_power` misses
        the part of its quantisation lobes that falls outside the visible directions.
        """
        return 10.0 * math.log10(self._beam[2] * self.intercepted_power / self.radiated_power)

    @cached_property
    def side_lobe_level(self) -> float:
        """The highest lobe other than the main beam, relative to it (dB, ≤ 0 in a good design).

        The lobes are the local maxima of the pattern's grid (six samples per beamwidth,
        so a lobe's top is caught within ~0.5 dB); the main beam's own maximum is the one
        within half a beamwidth of it. A 1-bit design lit on its axis has a mirror beam
        (its aperture phase is real), which counts here: about 0 dB.
        """
        u, v, power = self._pattern_grid
        peaks = far.local_maxima(power)
        bu, bv, top = self._beam
        lat = np.array([self.lattice.a1, self.lattice.a2], dtype=float)
        ab = np.stack([u[peaks[:, 0], peaks[:, 1]], v[peaks[:, 0], peaks[:, 1]]], axis=1) @ lat.T
        ab0 = lat @ np.array([bu, bv])
        half = (math.pi / self.wavenumber) / np.asarray(self.aperture)  # λ/(2N) in α and β
        main = np.all(np.abs(ab - ab0) < half, axis=1)
        others = power[peaks[~main, 0], peaks[~main, 1]]
        if len(others) == 0:
            return -math.inf
        return 10.0 * math.log10(float(others.max()) / top)

    def continuous(self) -> Reflectarray:
        """The same design with continuous phases (``bits=None``); itself when unquantised."""
        if self.bits is None:
            return self
        return design(
            self.library,
            self.aperture,
            self.feed,
            self.beam,
            self.frequency,
            None,
            q=self.q,
            element_q=self.element_q,
            period=None if self.library.cell is not None else _periods(self.lattice),
        )

    @cached_property
    def quantization_loss(self) -> float:
        """The main beam's gain over that of :meth:`continuous` (dB, ≤ 0; 0 unquantised).

        Both designs intercept the same power, so this is the loss of directivity of a
        surface that reflects all it receives: the main beam keeps |mean e^(jε)|² of
        it, ε the phase errors. Compare :func:`textbook_quantization_loss`: −3.9, −0.9
        and −0.2 dB for 1, 2 and 3 bits, the limit of a large aperture whose phase errors
        spread evenly. (:attr:`directivity`, over the model's visible power, loses less.)
        """
        if self.bits is None:
            return 0.0
        return self.gain - self.continuous().gain

    def summary(self) -> str:
        """A few lines: the beam, the directivity, the side lobes, the quantisation loss."""
        theta, phi = self.beam_direction
        err = self.phase_error
        lines = [
            f"{self.aperture[0]} x {self.aperture[1]} elements at {self.frequency / 1e9:g} GHz, "
            f"feed at {self.feed} mm, beam asked at theta={self.beam[0]:g}, "
            f"phi={self.beam[1]:g} deg",
            f"main beam: theta={theta:.2f}, phi={phi:.2f} deg; gain {self.gain:.2f} dBi "
            f"(directivity {self.directivity:.2f} dBi); side-lobe level "
            f"{self.side_lobe_level:.1f} dB",
            f"phase error: RMS {np.sqrt(np.mean(err**2)):.2f} deg, largest "
            f"{np.abs(err).max():.2f} deg",
        ]
        if self.bits is not None:
            lines.append(
                f"{self.bits}-bit quantisation loss {self.quantization_loss:.2f} dB "
                f"(textbook {textbook_quantization_loss(self.bits):.2f} dB)"
            )
        return "\n".join(lines)

    def to_cell(self, name: str | None = None) -> UnitCell:
        """The whole array as one unit cell: every element its cell's parts at its parameter.

        Each element is the library's cell with its parameter set to the chosen value
        (the path ``ReflectionLibrary.parameter`` of an element, e.g.
        ``elements[0].patch_size``), its parts moved to the element's position and named
        ``"<part> (i, j)"``; the lattice is the aperture's, N1 a1 by N2 a2. Save it with
        :func:`barymesh.cell.save_cell`, or write its outline as DXF or GDSII with
        :func:`barymesh.cell.export_outline`, as any cell.

        Raises
        ------
        ValueError
            The library keeps no cell, its parameter is not an element's (a layer of the
            stack, the incidence or the lattice does not change the metal), or the cell has
            a pixel grid (a cell holds one grid; it cannot be repeated per element).
        """
        from .layout import array_cell

        return array_cell(self, name)


def _periods(lattice: Lattice) -> tuple[float, float]:
    return (lattice.a1[0], lattice.a2[1])
