"""Solve the EFIE at one frequency or over a sweep (dense LU, refined in mixed precision)."""

from __future__ import annotations

import logging
import math
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import scipy.linalg as sla

from ..mesh import TriMesh
from . import geometry
from .caveats import check_electrical_size, solve_warnings
from .excitation import PlaneWave, VoltageSource, excitation_vector
from .geometry import FAR_ORDER, NEAR_FACTOR, NEAR_ORDER, MomGeometry, mom_geometry
from .operator import gram_matrix, impedance_matrix, wavenumber
from .quadrature import triangle_rule
from .solution import Solution

log = logging.getLogger(__name__)


class SolveCancelled(Exception):
    """Raised by :func:`sweep` when its ``cancel`` callable asked it to stop."""


class ProblemTooLarge(ValueError):
    """The dense matrix would not fit the memory allowed; raised before allocating it."""


def available_memory() -> int:
    """Bytes of memory available to a new allocation (MemAvailable on Linux)."""
    try:
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        return int(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return 1 << 62


#: Peak bytes per N² of a solve, measured (tracemalloc) at N = 3,145 and 4,754 (34.4 and
#: 33.9; the issue's runs 34.0–34.2 up to N = 22,533) plus a margin of about 5 %: Z
#: (16 N²), its complex64 copy and the Fortran-ordered copy LAPACK factorises (8 + 8),
#: or Z and a complex128 LU (16 + 16), and the geometry.
PEAK_BYTES_PER_N2 = 36.0
#: Bytes a solve needs beyond the N² term whatever its size (BLAS buffers, fill slabs).
FIXED_BYTES = 32 * 2**20


def memory_needed(n: int, far_points: int = 0) -> int:
    """Peak bytes of a solve with N unknowns (the measured model, with a margin).

    Parameters
    ----------
    n : int
        Number of unknowns.
    far_points : int
        Far-rule points of the mesh (triangles × points per triangle). When
        their distance table is cached (it fits
        :data:`~barymesh.mom.geometry.DISTANCE_CACHE_BYTES`), it counts twice:
        the table and the fill's kernel and moment blocks it feeds.

    Returns
    -------
    int
        ``PEAK_BYTES_PER_N2 * N² + FIXED_BYTES`` (+ 2 × the cached table).

    Examples
    --------
    >>> memory_needed(1000) == 36 * 1000**2 + 32 * 2**20
    True
    """
    table = 8 * int(far_points) ** 2
    cached = table if table <= geometry.DISTANCE_CACHE_BYTES else 0
    return int(PEAK_BYTES_PER_N2 * n * n) + FIXED_BYTES + 2 * cached


def check_memory(n: int, memory_limit: float | None = None, far_points: int = 0) -> int:
    """Refuse N unknowns whose solve would need more memory than allowed.

    Parameters
    ----------
    n : int
        Number of unknowns.
    memory_limit : float, optional
        A cap in bytes (in addition to the memory available now).
    far_points : int
        Far-rule points of the mesh (see :func:`memory_needed`).

    Returns
    -------
    int
        The bytes needed, :func:`memory_needed`.

    Raises
    ------
    ProblemTooLarge
        Naming N, the memory needed and the memory allowed.
    """
    need = memory_needed(n, far_points)
    allowed, source = memory_allowance(memory_limit)
    if need > allowed:
        raise ProblemTooLarge(
            f"N = {n:,} unknowns need {format_bytes(need)} at the peak of a solve (the dense "
            f"impedance matrix, its single-precision copies or LU factors: about "
            f"{PEAK_BYTES_PER_N2:g} N² bytes), more than {source}; use a coarser mesh"
        )
    return need


def memory_allowance(memory_limit: float | None = None) -> tuple[float, str]:
    """The bytes a solve may use now, and how to name that bound in an error.

    Parameters
    ----------
    memory_limit : float, optional
        A cap in bytes (in addition to the memory available now).

    Returns
    -------
    allowed : float
        The smaller of the memory available and ``memory_limit``.
    source : str
        "the memory_limit of 2.00 GiB" or "the 20.1 GiB of memory available".
    """
    avail = available_memory()
    if memory_limit is not None:
        limit = check_memory_limit(memory_limit)
        if limit < avail:
            return limit, f"the memory_limit of {format_bytes(limit)}"
    return float(avail), f"the {format_bytes(avail)} of memory available"


def check_memory_limit(memory_limit: object) -> float:
    """``memory_limit`` as bytes, or a ValueError naming it: a number > 0 (NaN was ignored,
    and -1 refused as "-0.0 MiB")."""
    try:
        limit = float(memory_limit)  # type: ignore[arg-type]  # any input: refused below
    except (TypeError, ValueError):
        limit = math.nan
    if isinstance(memory_limit, bool) or not (math.isfinite(limit) and limit > 0):
        raise ValueError(
            f"memory_limit={memory_limit!r:.40} is invalid; expected a positive number of "
            "bytes (e.g. 2e9), or None for the memory available"
        )
    return limit


def _far_points(mesh: TriMesh, far_order: int) -> int:
    """Far-rule points of ``mesh`` (0 for an order without a rule: mom_geometry says so)."""
    try:
        return mesh.n_triangles * len(triangle_rule(far_order)[1])
    except (TypeError, ValueError, KeyError):
        return 0


def format_bytes(b: float) -> str:
    """Bytes as GiB (from a quarter GiB) or MiB, for error messages: "9.47 GiB"."""
    return f"{b / 2**30:.2f} GiB" if b >= 2**28 else f"{b / 2**20:.1f} MiB"


def check_frequencies(frequencies: Any) -> np.ndarray:
    """``frequencies`` (Hz) as a read-only float array: numbers, at least one, each finite
    and positive, strictly increasing (the sweeps' common check; the message names the
    first bad one)."""
    try:
        freqs = np.asarray(frequencies, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ValueError(f"frequencies={frequencies!r} is not a list of numbers (Hz)") from None
    if len(freqs) == 0:
        raise ValueError("frequencies is empty; expected at least one frequency in Hz")
    bad = ~(np.isfinite(freqs) & (freqs > 0))
    if np.any(bad):
        raise ValueError(
            f"frequencies[{int(np.argmax(bad))}]={freqs[bad][0]!r} is invalid; "
            "expected positive frequencies in Hz"
        )
    if np.any(np.diff(freqs) <= 0):
        raise ValueError("frequencies must be strictly increasing")
    freqs = freqs.copy()
    freqs.flags.writeable = False
    return freqs


def _check_frequency(frequency: float, name: str = "frequency") -> float:
    try:
        f = float(frequency)
    except (TypeError, ValueError):
        raise ValueError(f"{name}={frequency!r} is not a number of Hz") from None
    if not np.isfinite(f) or f <= 0:
        raise ValueError(f"{name}={frequency!r} is invalid; expected a positive frequency in Hz")
    return f


def _default_excitation(excitation: PlaneWave | VoltageSource | None) -> PlaneWave | VoltageSource:
    if excitation is None:
        return PlaneWave()
    if not isinstance(excitation, (PlaneWave, VoltageSource)):
        raise TypeError(
            f"excitation must be a PlaneWave or a VoltageSource, got {type(excitation).__name__}"
        )
    return excitation


#: Most refinement steps of the single-precision LU before falling back to double precision.
REFINEMENT_STEPS = 10
#: A column stops refining once its residual is this fraction of zcgesv's acceptance bound.
ACCEPT_FRACTION = 0.1


def dense_solve(z: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, float, float | np.ndarray]:
    """Solve Z I = V: single-precision LU refined in double precision, else a double LU.

    The LU of Z rounded to complex64 costs half that of complex128; iterative
    refinement with residuals computed in double precision (as LAPACK's
    ``zcgesv``) then recovers the double-precision solution in a few O(N²)
    steps when cond(Z) is well under 1/ε₃₂ ≈ 1e7, which it is for conforming
    meshes. It refines until the residual is a tenth of ``zcgesv``'s bound
    ‖r‖∞ ≤ ‖I‖∞ ‖Z‖∞ ε₆₄ √N (:data:`ACCEPT_FRACTION`; ``zcgesv`` stops at the bound
    itself) or stops halving (the floor of double precision, that of a complex128
    LU), and accepts the result when it passes that bound. When that fails within
    :data:`REFINEMENT_STEPS` steps (an ill-conditioned matrix, e.g. overlapping
    paper-mode patches), Z is factorised in double precision.

    Several right-hand sides (the columns of a 2-D ``v``) share the one LU: each column
    is refined on its own (it stops when its own residual stops halving), and Z is
    factorised in double precision when any column fails the test.

    Parameters
    ----------
    z : (N, N) complex128
    v : (N,) or (N, K) complex128

    Returns
    -------
    current : (N,) or (N, K) complex128
        The shape of ``v``.
    condition_number : float
        LAPACK's estimate of the 1-norm condition number.
    residual : float or (K,) float
        ‖Z I − V‖ / ‖V‖ (per column for a 2-D ``v``).
    """
    v = np.asarray(v)
    if v.ndim not in (1, 2) or len(v) != len(z):
        raise ValueError(f"v has shape {v.shape}; expected ({len(z)},) or ({len(z)}, K)")
    single = v.ndim == 1
    rhs = v[:, None] if single else v
    n, kk = rhs.shape
    z32 = z.astype(np.complex64)
    magnitude = np.abs(z32)
    anorm = float(magnitude.sum(axis=0).max())
    inf_norm = float(magnitude.sum(axis=1).max())
    del magnitude
    lu32, piv32, info = sla.lapack.cgetrf(z32, overwrite_a=True)
    del z32
    current = None
    if info == 0:
        rcond, _ = sla.lapack.cgecon(lu32, anorm, norm="1")
        x = np.zeros((n, kk), dtype=np.complex128)
        r = rhs.astype(np.complex128)
        best = np.full(kk, np.inf)
        found_x = np.zeros((n, kk), dtype=np.complex128)
        found_r = r.copy()
        live = np.ones(kk, dtype=bool)  # columns still refining
        tol = np.finfo(np.float64).eps * np.sqrt(n) * inf_norm
        for _ in range(REFINEMENT_STEPS):
            cols = np.flatnonzero(live)
            if not len(cols):
                break
            dx, _ = sla.lapack.cgetrs(lu32, piv32, r[:, cols].astype(np.complex64))
            x[:, cols] += dx
            r[:, cols] = rhs[:, cols] - z @ x[:, cols]
            size = np.abs(r[:, cols]).max(axis=0)
            worse = size >= best[cols]  # stalled at the double-precision floor (or diverging)
            better = cols[~worse]
            improved = size[~worse] < 0.5 * best[better]
            best[better] = size[~worse]
            found_x[:, better] = x[:, better]
            found_r[:, better] = r[:, better]
            live[cols[worse]] = False
            live[better[~improved]] = False
            # done as soon as a step passes the test (zcgesv's stopping rule)
            passed = size[~worse] <= ACCEPT_FRACTION * tol * np.abs(x[:, better]).max(axis=0)
            live[better[passed]] = False
        if np.all(best <= tol * np.abs(found_x).max(axis=0)):
            current, r = found_x, found_r
    del lu32
    if current is None:
        lu, piv = sla.lu_factor(z, check_finite=False)
        current = sla.lu_solve((lu, piv), rhs, check_finite=False)
        rcond, _ = sla.lapack.zgecon(lu, anorm, norm="1")
        del lu
        r = rhs - z @ current
    residual = np.linalg.norm(r, axis=0) / np.linalg.norm(rhs, axis=0)
    cond = float(1.0 / rcond) if rcond > 0 else float("inf")
    if single:
        return current[:, 0], cond, float(residual[0])
    return current, cond, residual


def check_sheet_impedance(value: object) -> complex:
    """``value`` as a surface impedance Z_s (Ω per square); a ValueError naming it if invalid."""
    try:
        zs = complex(value)  # type: ignore[call-overload]  # any input: refused below
    except (TypeError, ValueError):
        raise ValueError(f"sheet_impedance={value!r} is not a number (ohms per square)") from None
    if isinstance(value, bool) or not np.isfinite(zs) or zs.real < 0:
        raise ValueError(
            f"sheet_impedance={value!r} is invalid; expected a finite complex number with a "
            "real part >= 0 (ohms per square; a negative one would be a gain)"
        )
    return zs


def _solve_at(
    mesh: TriMesh,
    geom: MomGeometry,
    frequency: float,
    excitation: PlaneWave | VoltageSource,
    sheet_impedance: complex = 0j,
) -> Solution:
    k = wavenumber(frequency)
    z = impedance_matrix(geom, k)
    if sheet_impedance != 0:
        z += sheet_impedance * gram_matrix(geom).toarray()
    v = excitation_vector(geom, k, excitation)
    i, cond, residual = dense_solve(z, v)
    del z
    if not np.all(np.isfinite(i)):  # a guard: check_electrical_size refuses the known cause
        raise FloatingPointError(
            f"the solve at {frequency:.6g} Hz gave non-finite currents: its matrix or "
            "right-hand side overflowed; no result"
        )
    warnings = solve_warnings(mesh, k, cond)
    return Solution(
        geom, frequency, excitation, i, v, cond, float(residual), warnings, complex(sheet_impedance)
    )


def solve(
    mesh: TriMesh,
    frequency: float,
    excitation: PlaneWave | VoltageSource | None = None,
    *,
    order: int = NEAR_ORDER,
    far_order: int = FAR_ORDER,
    near_factor: float = NEAR_FACTOR,
    memory_limit: float | None = None,
    sheet_impedance: complex = 0.0,
) -> Solution:
    """Currents on a perfectly conducting (or resistive) mesh in free space at one frequency.

    EFIE, RWG basis and Galerkin testing, time convention e^(jωt); the mesh's
    mm are converted to metres.

    Parameters
    ----------
    mesh : TriMesh
    frequency : float
        Hz.
    excitation : PlaneWave or VoltageSource, optional
        Default ``PlaneWave()``: 1 V/m along x travelling along −z.
    order, far_order : int
        Quadrature degrees of the near and far rules (see :func:`mom_geometry`).
    near_factor : float
        Near-pair distance in units of the larger triangle's longest edge.
    memory_limit : float, optional
        Refuse problems whose matrix and LU need more bytes than this.
    sheet_impedance : complex
        Surface impedance Z_s (Ω per square, Re Z_s >= 0) of the whole surface: the
        boundary condition E_tan = Z_s J adds Z_s times the Gram matrix to the EFIE, and
        :attr:`Solution.ohmic_power` is what the sheet dissipates. 0: a perfect conductor.

    Returns
    -------
    Solution

    Raises
    ------
    ProblemTooLarge
        Before allocating, when the solve's peak (:func:`memory_needed`) exceeds
        the memory allowed.

    Examples
    --------
    >>> from barymesh import MeshParams, build_mesh
    >>> mesh = build_mesh(MeshParams(structure="patch", patch_size=100.0, subdivisions=2))
    >>> s = solve(mesh, 1e9)
    >>> s.coefficients.shape, s.current_density.shape
    ((8,), (8, 3))
    """
    frequency = _check_frequency(frequency)
    excitation = _default_excitation(excitation)
    zs = check_sheet_impedance(sheet_impedance)
    if not isinstance(mesh, TriMesh):
        raise TypeError(f"mesh must be a TriMesh, got {type(mesh).__name__}")
    check_electrical_size(mesh, frequency)
    check_memory(len(mesh.rwg), memory_limit, _far_points(mesh, far_order))
    geom = mom_geometry(mesh, order, far_order, near_factor)
    solution = _solve_at(mesh, geom, frequency, excitation, zs)
    for text in solution.warnings:
        log.warning(text)
    return solution


@dataclass(frozen=True, eq=False)
class SweepResult:
    """Cross-sections (or input impedances) over a frequency sweep.

    Attributes
    ----------
    frequencies : (F,) float64
        Hz, as given.
    extinction_cross_section, scattering_cross_section : (F,) float64
        m² (NaN for a voltage source).
    input_impedance : (F,) complex128
        Ω for a voltage source, NaN for a plane wave.
    coefficients : (F, N) complex128
    condition_numbers, residuals : (F,) float64
    warnings : tuple of str
        Each kind of caveat once, as the first frequency that raised it said it
        (for the low-frequency breakdown: the lowest, worst frequency).
    """

    frequencies: np.ndarray
    extinction_cross_section: np.ndarray
    scattering_cross_section: np.ndarray
    input_impedance: np.ndarray
    coefficients: np.ndarray
    condition_numbers: np.ndarray
    residuals: np.ndarray
    warnings: tuple[str, ...] = field(default=())

    @property
    def resonances(self) -> np.ndarray:
        """(R,) float64 frequencies (Hz) of the extinction peaks, refined between samples.

        A sample larger than both neighbours (and above 5 % of the largest
        value) is a peak, refined as the peak of the Lorentzian through it
        and its two neighbours (see :func:`find_peaks`).
        """
        return find_peaks(self.frequencies, self.extinction_cross_section)

    @property
    def quality_factors(self) -> np.ndarray:
        """(R,) float64 Q = f0 / (2γ) of each resonance, from the same Lorentzian fit.

        γ is the half width at half maximum of the Lorentzian through the peak
        sample and its neighbours (one pole pair of a rational fit); sample the
        peak finely enough that three samples fall within its width.
        """
        centres, half_widths = lorentzian_peaks(self.frequencies, self.extinction_cross_section)
        return centres / (2.0 * half_widths)

    def to_csv(self, path: str | Path) -> None:
        """Write one row per frequency to ``path`` (CSV), the columns of ``barymesh solve -o
        sweep.csv``; see :func:`barymesh.io.cross_sections.write_sweep_csv`."""
        from ..io.cross_sections import write_sweep_csv

        write_sweep_csv(path, self)


def find_peaks(x: np.ndarray, y: np.ndarray, floor: float = 0.05) -> np.ndarray:
    """Abscissae of the interior local maxima of ``y(x)``, refined between samples.

    Near a resonance a cross-section is close to a Lorentzian
    A / ((x − x0)² + γ²), whose reciprocal is a parabola; so the peak is the
    vertex of the parabola through 1/y at the largest sample and its two
    neighbours (exact for a Lorentzian, any spacing).

    Parameters
    ----------
    x : (F,) float64
        Strictly increasing.
    y : (F,) float64
        Positive near the peaks.
    floor : float
        Peaks below ``floor * max(y)`` are ignored.

    Returns
    -------
    (R,) float64

    Examples
    --------
    >>> x = np.linspace(5.0, 7.0, 5)
    >>> round(float(find_peaks(x, 1 / ((x - 6.19) ** 2 + 0.04))[0]), 12)
    6.19
    """
    return lorentzian_peaks(x, y, floor)[0]


def lorentzian_peaks(
    x: np.ndarray, y: np.ndarray, floor: float = 0.05
) -> tuple[np.ndarray, np.ndarray]:
    """Centres x0 and half widths γ of the Lorentzians through each peak (see :func:`find_peaks`).

    Returns
    -------
    centres, half_widths : (R,) float64
        γ is NaN where the three samples do not fit a Lorentzian.

    Examples
    --------
    >>> x = np.linspace(5.0, 7.0, 5)
    >>> c, g = lorentzian_peaks(x, 1 / ((x - 6.19) ** 2 + 0.04))
    >>> round(float(g[0]), 12)
    0.2
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    if len(x) < 3 or not np.all(np.isfinite(y)):
        return np.zeros(0), np.zeros(0)
    mid = np.flatnonzero((y[1:-1] > y[:-2]) & (y[1:-1] >= y[2:]) & (y[1:-1] > floor * y.max()))
    i = mid + 1
    x0, x1, x2 = x[i - 1], x[i], x[i + 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        u0, u1, u2 = 1.0 / y[i - 1], 1.0 / y[i], 1.0 / y[i + 1]
        d01, d12 = (u1 - u0) / (x1 - x0), (u2 - u1) / (x2 - x1)
        curvature = (d12 - d01) / (x2 - x0)  # a in u = a (x − c)² + b
        vertex = 0.5 * (x0 + x1) - d01 / (2.0 * curvature)
        bottom = u1 - curvature * (x1 - vertex) ** 2
        half_width = np.sqrt(bottom / curvature)
    ok = np.isfinite(vertex) & (curvature > 0) & (y[i - 1] > 0) & (y[i + 1] > 0)
    centres = np.where(ok, np.clip(vertex, x0, x2), x1)
    return centres, np.where(ok & (bottom > 0), half_width, np.nan)


def sweep(
    mesh: TriMesh,
    frequencies: Sequence[float] | np.ndarray,
    excitation: PlaneWave | VoltageSource | None = None,
    *,
    progress: Callable[[int, int], None] | None = None,
    cancel: Callable[[], bool] | None = None,
    scattering: bool = True,
    order: int = NEAR_ORDER,
    far_order: int = FAR_ORDER,
    near_factor: float = NEAR_FACTOR,
    memory_limit: float | None = None,
    sheet_impedance: complex = 0.0,
) -> SweepResult:
    """Solve at each frequency, reusing the frequency-independent geometry.

    Parameters
    ----------
    mesh : TriMesh
    frequencies : (F,) float
        Hz, strictly increasing.
    excitation : PlaneWave or VoltageSource, optional
    progress : callable, optional
        ``progress(done, total)`` after each frequency.
    cancel : callable, optional
        Checked before each frequency; when it returns True the sweep stops
        with :class:`SolveCancelled`.
    scattering : bool
        Also integrate the far field for the scattering cross-section.
    order, far_order, near_factor, memory_limit, sheet_impedance
        As for :func:`solve`.

    Returns
    -------
    SweepResult
    """
    freqs = check_frequencies(frequencies)
    excitation = _default_excitation(excitation)
    zs = check_sheet_impedance(sheet_impedance)
    if not isinstance(mesh, TriMesh):
        raise TypeError(f"mesh must be a TriMesh, got {type(mesh).__name__}")
    check_electrical_size(mesh, float(freqs[0]), "frequencies")  # the lowest
    check_memory(len(mesh.rwg), memory_limit, _far_points(mesh, far_order))
    geom = mom_geometry(mesh, order, far_order, near_factor)
    plane = isinstance(excitation, PlaneWave)
    nf = len(freqs)
    ext = np.full(nf, np.nan)
    sca = np.full(nf, np.nan)
    zin = np.full(nf, complex(np.nan, np.nan))
    coefs = np.zeros((nf, geom.n_unknowns), dtype=complex)
    conds = np.zeros(nf)
    residuals = np.zeros(nf)
    warnings: tuple[str, ...] = ()
    for j, f in enumerate(freqs):
        if cancel is not None and cancel():
            raise SolveCancelled(f"the sweep was cancelled after {j} of {nf} frequencies")
        s = _solve_at(mesh, geom, float(f), excitation, zs)
        coefs[j] = s.coefficients
        conds[j] = s.condition_number
        residuals[j] = s.residual
        kinds = {w.split(":")[0] for w in warnings}
        new = tuple(w for w in s.warnings if w.split(":")[0] not in kinds)
        for text in new:  # logged once per kind, not once per frequency
            log.warning(text)
        warnings += new
        if plane:
            ext[j] = s.extinction_cross_section
            if scattering:
                sca[j] = s.scattering_cross_section
        else:
            zin[j] = s.input_impedance
        if progress is not None:
            progress(j + 1, nf)
    return SweepResult(freqs, ext, sca, zin, coefs, conds, residuals, warnings)
