"""The reflection-phase library of a unit cell: R of the infinite array over one parameter.

A reflectarray or a metasurface lens is laid out from one curve per frequency: the phase
of the co-polar reflection of the infinite array of a cell (the "S-curve") against the
parameter that tunes it, a patch's size or a ring's radius. :func:`reflection_library`
solves that curve, one infinite-array solve per value (:func:`barymesh.mom.periodic_sweep`
over the frequencies, interpolating between them where that saves solves), and returns a
:class:`ReflectionLibrary`: the full 2 × 2 TE/TM reflection of the (0, 0) Floquet order
at every point, the co-polar phase unwrapped along the parameter, its inverse
(:meth:`ReflectionLibrary.lookup`: the parameter that gives a wanted phase), and a CSV
file or an xarray Dataset.

Where the phase is referred matters as much as the phase itself: a plane 1 mm higher
moves it by 2 k · 1 mm (24° at 10 GHz). R is referred to the stack's top face, the plane
the incident wave meets first, :attr:`ReflectionLibrary.reference_plane` mm over the
sheet (0 for a cell without layers above it).

The points are those of a design study (:mod:`barymesh.study`): the parameter is a path
as a study's axis names it (``elements[0].patch_size``, ``stack.below[0].thickness``,
``incidence.theta``), set in the cell by the study's own code. In this process each
value's TE and TM incidence are solved from one fill of its matrix
(:func:`barymesh.study.point.solve_both_polarizations`); given a Dask ``client``, each
(value, polarisation) is a point of :func:`barymesh.study.run` on its cluster. The numbers
agree to rounding (one LU with two right-hand sides against two).
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .excitation import PlaneWave
from .floquet import te_tm_polarizations
from .stack import Stack

if TYPE_CHECKING:
    from ..cell import UnitCell

#: The two incident polarisations solved at every point, in the order of the 2 × 2's
#: columns (and rows): TE, then TM.
POLARIZATIONS = ("TE", "TM")
#: The incidence when none is given: normal, from above, E along the cell's x (which the
#: solver's TE/TM convention calls TM at normal incidence).
DEFAULT_INCIDENCE = {"theta": 0.0, "phi": 0.0, "pol": "TM"}
#: Keys of an ``incidence`` mapping.
INCIDENCE_KEYS = ("theta", "phi", "pol")
#: Columns of :meth:`ReflectionLibrary.to_csv`, after the parameter's.
CSV_COLUMNS = (
    "frequency_hz",
    "phase_deg",
    "magnitude",
    "r_te_te_re",
    "r_te_te_im",
    "r_te_tm_re",
    "r_te_tm_im",
    "r_tm_te_re",
    "r_tm_te_im",
    "r_tm_tm_re",
    "r_tm_tm_im",
    "reference_plane_mm",
)


@dataclass(frozen=True)
class ReflectionLibrary:
    """The reflection of a cell's infinite array over one parameter and the frequencies.

    Attributes
    ----------
    parameter : str
        The path that was varied, as a study's axis names it.
    values : (V,) float
        Its values, in the order given.
    frequencies : (F,) float
        Hz, increasing.
    reflection : (V, F, 2, 2) complex
        R of the (0, 0) Floquet order, ``reflection[v, f, out, in]``, TE = 0 and TM = 1
        in both indices (the fields of :func:`barymesh.mom.te_tm_polarizations`: at
        normal incidence TE is along y and TM along −x for the incident wave), incident
        amplitude 1, referred to :attr:`reference_plane`.
    polarization : str
        "TE" or "TM": the incident polarisation, whose diagonal entry is the co-polar R
        of :attr:`phase_deg` and :attr:`magnitude`.
    incidence : dict
        ``theta``, ``phi`` (degrees) and ``pol`` of the incident wave, from above.
    reference_plane : float
        Height (mm) over the sheet of the plane R is referred to: the stack's top face
        (the sum of the thicknesses of the layers above the sheet; 0 without any).
    stack : Stack or None
        The layers around the sheet (None: the sheet in vacuum).
    warnings : tuple of str
        The solves' warnings ("kind: text"), each once.
    cell : UnitCell or None
        The cell the library was solved from, as given (:func:`reflection_library` sets
        it; None for a library made otherwise). The reflectarray designer builds its
        elements from it (:meth:`barymesh.reflectarray.Reflectarray.to_cell`).
    """

    parameter: str
    values: np.ndarray
    frequencies: np.ndarray
    reflection: np.ndarray
    polarization: str
    incidence: dict[str, Any]
    reference_plane: float
    stack: Stack | None = None
    warnings: tuple[str, ...] = field(default=())
    cell: UnitCell | None = None

    @property
    def co_polar(self) -> np.ndarray:
        """(V, F) complex: the incident polarisation's diagonal entry of :attr:`reflection`."""
        k = POLARIZATIONS.index(self.polarization)
        return self.reflection[:, :, k, k]

    @property
    def phase_deg(self) -> np.ndarray:
        """(V, F) float: ∠ of :attr:`co_polar` in degrees, unwrapped along the values
        (``numpy.unwrap`` in radians: no step of more than 180° from one value to the
        next), starting in (−180, 180] at the first value."""
        return np.degrees(np.unwrap(np.angle(self.co_polar), axis=0))

    @property
    def magnitude(self) -> np.ndarray:
        """(V, F) float: |:attr:`co_polar`|."""
        return np.abs(self.co_polar)

    def frequency_index(self, frequency: float) -> int:
        """The index of ``frequency`` (Hz) in :attr:`frequencies` (equal to 1e-9 relative).

        Raises
        ------
        ValueError
            ``frequency`` is not one of the library's.
        """
        f = _finite_number("frequency", frequency)
        hit = np.flatnonzero(np.isclose(self.frequencies, f, rtol=1e-9, atol=0.0))
        if len(hit) == 0:
            known = ", ".join(f"{x / 1e9:.6g}" for x in self.frequencies[:10])
            more = ", …" if len(self.frequencies) > 10 else ""
            raise ValueError(
                f"frequency={f / 1e9:.9g} GHz is not one of the library's ({known}{more} GHz); "
                "make the library at that frequency"
            )
        return int(hit[0])

    def lookup(self, phase_deg: float | np.ndarray, frequency: float) -> float | np.ndarray:
        """The parameter value that gives the co-polar phase ``phase_deg`` at ``frequency``.

        The inverse of the curve :attr:`phase_deg` at that frequency. The curve is cut into
        its monotone pieces (between the values where it turns); on each the parameter is
        interpolated linearly in the phase, so a phase that was sampled gives its value
        exactly. A phase is taken modulo 360°: the first piece (in the order of
        :attr:`values`) that covers ``phase_deg + k · 360`` for some whole k answers.

        Parameters
        ----------
        phase_deg : float or array of float
            Degrees.
        frequency : float
            Hz, one of :attr:`frequencies`.

        Returns
        -------
        float or ndarray
            Shaped as ``phase_deg``; NaN where no piece of the curve reaches the phase
            (the cell cannot give it over the values solved).

        Raises
        ------
        ValueError
            ``frequency`` is not one of the library's, or a phase is not finite.
        """
        j = self.frequency_index(frequency)
        wanted = np.asarray(phase_deg, dtype=float)
        if not np.all(np.isfinite(wanted)):
            raise ValueError(f"phase_deg={phase_deg!r} is invalid; expected finite degrees")
        curve = self.phase_deg[:, j]
        out = np.full(wanted.shape, np.nan)
        for a, b in _monotone_pieces(curve):
            p, v = curve[a : b + 1], self.values[a : b + 1]
            if p[-1] < p[0]:
                p, v = p[::-1], v[::-1]
            low, high = p[0], p[-1]
            tol = 1e-9 * max(1.0, abs(low), abs(high))  # a sampled phase ± 360 k is its own
            # the largest phase + 360 k at or below the high end; inside if not below the low
            shifted = wanted + 360.0 * np.floor((high + tol - wanted) / 360.0)
            inside = np.isnan(out) & (shifted >= low - tol)
            shifted = np.clip(shifted, low, high)
            out[inside] = np.interp(shifted[inside], p, v)
        return float(out) if out.ndim == 0 else out

    def rows(self) -> list[list[float]]:
        """The rows of :meth:`to_csv`: one per (value, frequency), values slowest."""
        r = self.reflection
        phase, mag = self.phase_deg, self.magnitude
        out = []
        for i, value in enumerate(self.values):
            for j, f in enumerate(self.frequencies):
                m = r[i, j]
                entries = (m[0, 0], m[0, 1], m[1, 0], m[1, 1])
                row = [float(value), float(f), float(phase[i, j]), float(mag[i, j])]
                row += [float(x) for z in entries for x in (z.real, z.imag)]
                row.append(float(self.reference_plane))
                out.append(row)
        return out

    def to_csv(self, path: str | Path) -> Path:
        """Write the library as CSV, atomically; returns the path.

        One row per (value, frequency), the values slowest. Columns: the parameter's path
        (its value), then :data:`CSV_COLUMNS`: ``frequency_hz``, ``phase_deg`` and
        ``magnitude`` of the co-polar R, then the four entries of :attr:`reflection` as
        real and imaginary parts, ``r_OUT_IN_re`` / ``r_OUT_IN_im`` (``r_te_tm`` is the
        TE reflected by a TM incidence), and ``reference_plane_mm``, where they are
        referred (:attr:`reference_plane`, the same on every row). Numbers are written
        with 17 significant digits: read back, they are the same floats.
        """
        from ..io.atomic import atomic_write_text

        text = io.StringIO()
        writer = csv.writer(text, lineterminator="\n")
        writer.writerow([self.parameter, *CSV_COLUMNS])
        for row in self.rows():
            writer.writerow([repr(x) for x in row])
        target = Path(path)
        atomic_write_text(target, text.getvalue())
        return target

    def to_xarray(self) -> Any:
        """The library as an ``xarray.Dataset`` (needs the ``study`` extra).

        Variables ``reflection`` (value, frequency, out, in) complex, ``phase_deg`` and
        ``magnitude`` (value, frequency); coordinates ``value`` (named by the parameter in
        the attributes), ``frequency`` (Hz), ``out`` and ``in`` ("TE", "TM"); attributes
        ``parameter``, ``polarization``, ``reference_plane_mm`` and ``stack``.
        """
        try:
            from ..study.results import library_dataset
        except ImportError as exc:  # pandas or pyarrow missing: the study extra
            raise ImportError(
                "ReflectionLibrary.to_xarray needs xarray: pip install 'barymesh[study]' "
                f"(missing {exc.name})"
            ) from None
        return library_dataset(self)


def _monotone_pieces(curve: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) indices of the pieces of ``curve`` (V,) where it does not turn.

    >>> _monotone_pieces(np.array([0.0, 1.0, 2.0, 1.0, 0.0, 3.0]))
    [(0, 2), (2, 4), (4, 5)]
    >>> _monotone_pieces(np.array([0.0, 1.0, 1.0, 0.0]))  # a flat top is a turn too
    [(0, 2), (2, 3)]
    """
    if len(curve) < 2:
        return [(0, 0)] if len(curve) else []
    sign = np.sign(np.diff(curve))
    for i in range(1, len(sign)):  # a flat step goes on the way the curve went
        if sign[i] == 0:
            sign[i] = sign[i - 1]
    turns = [i for i in range(1, len(sign)) if sign[i] * sign[i - 1] < 0]  # sample i turns
    ends = [0, *turns, len(curve) - 1]
    return list(zip(ends[:-1], ends[1:], strict=True))


def _finite_number(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise ValueError(f"{name}={value!r:.40} is invalid; expected a number")
    if not math.isfinite(value):
        raise ValueError(f"{name}={value!r} is invalid; expected a finite number")
    return float(value)


def _checked_values(values: Any) -> np.ndarray:
    try:
        v = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"values={values!r:.60} is invalid; expected a list of numbers") from None
    if v.ndim != 1:
        raise ValueError(f"values has shape {v.shape}; expected a 1-D list of numbers")
    if len(v) == 0:
        raise ValueError("values is empty; expected at least one value of the parameter")
    bad = np.flatnonzero(~np.isfinite(v))
    if len(bad):
        raise ValueError(f"values[{bad[0]}]={float(v[bad[0]])!r} is not finite; expected numbers")
    if len(np.unique(v)) != len(v):
        raise ValueError("values lists a value twice; expected distinct values")
    return v


def _checked_frequencies(frequencies: Any) -> np.ndarray:
    try:
        f = np.atleast_1d(np.asarray(frequencies, dtype=float))
    except (TypeError, ValueError):
        raise ValueError(f"frequencies={frequencies!r:.60} is invalid; expected Hz") from None
    if f.ndim != 1 or len(f) == 0:
        raise ValueError(f"frequencies has shape {f.shape}; expected one frequency or a list")
    bad = np.flatnonzero(~(np.isfinite(f) & (f > 0)))
    if len(bad):
        raise ValueError(f"frequencies[{bad[0]}]={float(f[bad[0]])!r} is invalid; expected Hz > 0")
    if np.any(np.diff(f) <= 0):
        raise ValueError("frequencies must be increasing, each once")
    return f


def _checked_incidence(incidence: Mapping[str, Any] | None) -> dict[str, Any]:
    if incidence is None:
        return dict(DEFAULT_INCIDENCE)
    if not isinstance(incidence, Mapping):
        raise ValueError(
            f"incidence={incidence!r:.60} is invalid; expected None or a mapping of "
            "theta, phi (degrees) and pol ('TE' or 'TM')"
        )
    extra = sorted(set(incidence) - set(INCIDENCE_KEYS))
    if extra:
        raise ValueError(f"incidence has an unknown key {extra[0]!r}; expected theta, phi, pol")
    out = {**DEFAULT_INCIDENCE, **incidence}
    pol = out["pol"]
    if not isinstance(pol, str) or pol.upper() not in POLARIZATIONS:
        raise ValueError(
            f"incidence pol={pol!r} is invalid; expected 'TE' or 'TM' (the co-polar R is a "
            "diagonal entry of the TE/TM reflection)"
        )
    out["pol"] = pol.upper()
    out["theta"] = _finite_number("incidence theta", out["theta"])
    out["phi"] = _finite_number("incidence phi", out["phi"])
    if not 0.0 <= out["theta"] < 90.0:
        raise ValueError(f"incidence theta={out['theta']:g} is invalid; expected 0 <= theta < 90")
    return out


def _parameter_error(parameter: str, exc: Exception) -> ValueError:
    """A spec's error about an axis, said of the library's parameter."""
    text = str(exc)
    for prefix in ("study spec: ", f"axes.{parameter}: ", f"axes.{parameter} "):
        text = text.removeprefix(prefix)
    return ValueError(f"parameter {parameter!r}: {text}")


def _check_parameter(
    parameter: Any, values: np.ndarray, base: Any, stack: Stack | None
) -> tuple[str | int, ...]:
    """Refuse a path the study cannot vary, or a value the cell or the stack rejects."""
    from ..study.layers import is_stack_path, layer_field
    from ..study.spec import parse_path

    if not isinstance(parameter, str):
        raise ValueError(
            f"parameter={parameter!r:.40} is invalid; expected a path such as "
            "'elements[0].patch_size'"
        )
    try:
        tokens = parse_path(parameter)
    except ValueError as exc:
        raise _parameter_error(parameter, exc) from None
    if tokens[0] == "incidence":
        if len(tokens) != 2 or tokens[1] not in ("theta", "phi"):
            raise ValueError(
                f"parameter {parameter!r}: expected incidence.theta or incidence.phi (the "
                "polarisation is the incidence's pol: both are solved at every point)"
            )
        for v in values:
            if not 0.0 <= v < 90.0 and tokens[1] == "theta":
                raise ValueError(f"{parameter}={v:g} is invalid; expected 0 <= theta < 90")
        return tokens
    if is_stack_path(parameter):
        try:
            side, index, name = layer_field(tokens, stack)
        except ValueError as exc:
            raise ValueError(f"parameter {parameter!r}: {exc}") from None
        assert stack is not None  # layer_field refuses a path into no stack
        if side == "above" and name == "thickness":
            raise ValueError(
                f"parameter {parameter!r}: a layer above the sheet moves the reference plane "
                "with its thickness, so the phases of the library would be referred to "
                "different planes; vary a layer below the sheet, or its eps_r"
            )
        for v in values:
            try:
                stack.replaced(f"{side}[{index}].{name}", float(v))
            except (TypeError, ValueError) as exc:
                raise ValueError(f"{parameter}={v:g} makes the stack invalid: {exc}") from None
        return tokens
    for v in values:
        try:
            data = base.design({parameter: float(v)})
        except ValueError as exc:
            raise _parameter_error(parameter, exc) from None
        try:
            base.build(data)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"{parameter}={v:g}: the cell refuses it: {exc}") from None
    return tokens


def reflection_library(
    cell: Any,
    parameter: str,
    values: Sequence[float] | np.ndarray,
    frequencies: float | Sequence[float] | np.ndarray,
    incidence: Mapping[str, Any] | None = None,
    stack: Stack | None = None,
    client: Any = None,
) -> ReflectionLibrary:
    """Solve the reflection of the infinite array of ``cell`` for each value of a parameter.

    Parameters
    ----------
    cell : UnitCell
        As :func:`barymesh.cell.load_cell` returns it. It is meshed as it is (not made
        solver-grade): give it the subdivisions the frequencies need.
    parameter : str
        The path of the value to vary, as a study's axis names it: a cell path
        (``elements[0].patch_size``, ``lattice.rectangular[0]``), a layer of ``stack``
        (``stack.below[0].thickness``, ``stack.below[0].eps_r``; not the thickness of a
        layer above the sheet, which would move the reference plane), or
        ``incidence.theta`` / ``incidence.phi``.
    values : (V,) float
        The parameter's values, distinct and finite; the curve follows their order.
    frequencies : float or (F,) float
        Hz, > 0, increasing. Several give a family of curves; between them the
        interpolating sweep fits what it need not solve (:func:`barymesh.mom.periodic_sweep`,
        to 1e-3 in R).
    incidence : dict, optional
        ``theta``, ``phi`` (degrees, from above) and ``pol`` ("TE" or "TM": which
        diagonal entry is the co-polar R). Default: normal incidence with E along the
        cell's x, which the solver's TE/TM convention calls TM.
    stack : Stack, optional
        Dielectric layers and a ground plane around the sheet; R is referred to its top
        face (:attr:`ReflectionLibrary.reference_plane`).
    client : distributed.Client, optional
        Solve the points on this Dask cluster through the study engine
        (:func:`barymesh.study.run`; needs the ``study`` extra). Without it they are
        solved here, one after the other.

    Both incident polarisations are solved at every point, so that
    :attr:`ReflectionLibrary.reflection` is the whole 2 × 2: here from one fill and one
    LU per value and frequency (two right-hand sides), on a cluster as two points.

    Returns
    -------
    ReflectionLibrary

    Raises
    ------
    ValueError
        An unknown parameter path, empty or non-finite values, a value the cell or the
        stack rejects (named), frequencies that are not > 0 and increasing, a bad
        incidence, or a point whose solve failed (its value and the solver's message).

    Examples
    --------
    >>> from barymesh.cell import cell_from_dict
    >>> from barymesh.mom import parse_stack
    >>> cell = cell_from_dict({"format": "barymesh-cell", "version": 1,
    ...     "lattice": {"rectangular": [10.0, 10.0]},
    ...     "elements": [{"structure": "patch", "patch_size": 6.0, "subdivisions": 6,
    ...                   "position": [-4.0, -4.0]}]})
    >>> lib = reflection_library(cell, "elements[0].patch_size", [6.0, 7.0], 8e9,
    ...                          stack=parse_stack("1.575mm eps=2.2; ground"))
    >>> lib.reflection.shape, lib.reference_plane
    ((2, 1, 2, 2), 0.0)
    >>> power = (abs(lib.reflection) ** 2).sum(axis=2)  # (V, F, in): all is reflected
    >>> bool(np.allclose(power, 1.0, atol=1e-4))  # (lossless, over a ground plane)
    True
    """
    from ..cell import UnitCell, cell_to_dict
    from ..study.point import StudyContext, solve_both_polarizations
    from ..study.spec import Base, Solve

    if not isinstance(cell, UnitCell):
        raise ValueError(
            f"cell is a {type(cell).__name__}; expected a UnitCell (barymesh.cell.load_cell)"
        )
    v = _checked_values(values)
    f = _checked_frequencies(frequencies)
    inc = _checked_incidence(incidence)
    if stack is not None and not isinstance(stack, Stack):
        raise ValueError(f"stack is a {type(stack).__name__}; expected a barymesh.mom.Stack")
    base = Base("cell", cell_to_dict(cell))
    _check_parameter(parameter, v, base, stack)
    solve = Solve(
        "infinite_array",
        tuple(float(x) for x in f),
        incidence={"theta": inc["theta"], "phi": inc["phi"], "pol": inc["pol"]},
        interpolate=True,
    )
    context = StudyContext(base, solve, (), stack)
    reflection = np.empty((len(v), len(f), 2, 2), dtype=complex)
    warnings: dict[str, None] = {}
    if client is None:
        # TE and TM of a value from one fill (the same matrix): half the work of two points
        for i, x in enumerate(v):
            point = {parameter: float(x), "incidence.pol": inc["pol"]}
            status, r_both, notes = solve_both_polarizations(context, point)
            if r_both is None:
                raise ValueError(f"{parameter}={float(x):g}: the solve failed: {status}")
            reflection[i] = r_both
            warnings.update(dict.fromkeys(notes))
        return _library(parameter, v, f, reflection, inc, stack, tuple(warnings), cell)
    points = [{parameter: float(x), "incidence.pol": pol} for x in v for pol in POLARIZATIONS]
    outcomes = _solve_on(client, context, points)
    for n, (point, (status, table, notes)) in enumerate(zip(points, outcomes, strict=True)):
        if status != "ok":
            raise ValueError(f"{parameter}={point[parameter]:g}: the solve failed: {status}")
        i, k = divmod(n, 2)
        wave = _wave(inc, point, parameter, POLARIZATIONS[k])
        # the table holds R = M c for the incident TE/TM components c (one of them zero)
        c = te_tm_polarizations(wave.direction) @ np.asarray(wave.polarization)
        r = np.stack(
            [
                table["reflection_te_real"] + 1j * table["reflection_te_imag"],
                table["reflection_tm_real"] + 1j * table["reflection_tm_imag"],
            ],
            axis=-1,
        )
        reflection[i, :, :, k] = r / c[k]
        warnings.update(dict.fromkeys(notes))
    return _library(parameter, v, f, reflection, inc, stack, tuple(warnings), cell)


def _library(
    parameter: str,
    v: np.ndarray,
    f: np.ndarray,
    reflection: np.ndarray,
    inc: dict[str, Any],
    stack: Stack | None,
    warnings: tuple[str, ...],
    cell: UnitCell,
) -> ReflectionLibrary:
    """The library of the solved points, its arrays read-only."""
    top = 0.0 if stack is None else stack.reference_planes[0]
    for a in (v, f, reflection):
        a.setflags(write=False)
    return ReflectionLibrary(
        parameter, v, f, reflection, inc["pol"], inc, top, stack, warnings, cell
    )


def _wave(inc: dict[str, Any], point: dict[str, Any], parameter: str, pol: str) -> PlaneWave:
    """The incident wave of a point (the parameter may be one of its angles)."""
    theta, phi = inc["theta"], inc["phi"]
    if parameter == "incidence.theta":
        theta = point[parameter]
    elif parameter == "incidence.phi":
        phi = point[parameter]
    return PlaneWave.from_angles(theta, phi, 90.0 if pol == "TE" else 0.0)


Outcome = tuple[str, dict[str, np.ndarray], tuple[str, ...]]


def _solve_on(client: Any, context: Any, points: list[dict[str, Any]]) -> list[Outcome]:
    """Each point on the Dask ``client``'s cluster, by :func:`barymesh.study.run`."""
    import json

    from ..study.point import solve_columns
    from ..study.run import run
    from ..study.spec import Axis, StudySpec

    parameter = next(iter(points[0]))
    axes = (
        Axis(parameter, tuple(dict.fromkeys(p[parameter] for p in points))),
        Axis("incidence.pol", POLARIZATIONS),
    )
    document = {
        "base": {"cell": context.base.data},
        "axes": {a.path: list(a.values) for a in axes},
        "solve": {"frequencies": list(context.solve.frequencies), **context.solve.incidence},
        "stack": context.stack.to_dict() if context.stack is not None else None,
    }
    document = json.loads(json.dumps(document))
    spec = StudySpec(
        context.base, axes, "product", context.solve, (), None, document, context.stack
    )
    result = run(spec, client=client, resume=False)
    columns = solve_columns("infinite_array")
    out: list[Outcome] = []
    for i in range(len(points)):
        row = result.derived.loc[i]
        notes = tuple(s for s in str(row["warnings"]).split("\n") if s)
        if row["status"] != "ok":
            out.append((str(row["status"]), {}, notes))
            continue
        rows = result.table.loc[[i]]
        table = {c: rows[c].to_numpy(dtype=float) for c in columns}
        out.append(("ok", table, notes))
    return out
