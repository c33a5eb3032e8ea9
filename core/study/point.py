"""One point of a study: its design checked, its mesh built, solved and its figures derived.

Plain numpy and the mesher: a Dask task (:mod:`barymesh.study.run`) calls
:func:`solve_point`, and so does the serial loop, so the two give the same numbers.

>>> from barymesh.study.spec import parse_spec
>>> spec = parse_spec({"base": {"params": {"structure": "patch", "patch_size": 15.0,
...                                        "subdivisions": 2}},
...                    "axes": {"patch_size": [15.0, -1.0]},
...                    "solve": {"kind": "free_space", "frequencies": "4GHz:12GHz:5"}})
>>> context = StudyContext.of(spec)
>>> ok, bad = (solve_point(context, i, p) for i, p in enumerate(spec.points()))
>>> ok.status, len(ok.table["frequency_hz"]), bad.status[:45]
('ok', 5, 'patch_size=-1.0 is invalid; expected a finite')
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..mom.stack import Stack
from .derive import derived_figures
from .layers import is_stack_path, point_stack
from .spec import Base, Derive, Solve, StudySpec, figure_columns, plane_wave

#: The per-frequency columns of a free-space point, as ``barymesh solve -o x.csv`` names
#: them (:data:`barymesh.app.cli_solve.CSV_COLUMNS`).
FREE_SPACE_COLUMNS = (
    "frequency_hz",
    "extinction_cross_section_m2",
    "scattering_cross_section_m2",
    "absorption_cross_section_m2",
    "input_impedance_real_ohm",
    "input_impedance_imag_ohm",
    "condition_number",
    "residual",
)

#: The per-frequency columns of an infinite-array point: the (0, 0) order's TE and TM
#: reflection and transmission (real and imaginary parts, incident amplitude 1;
#: transmission includes the incident wave), their co-polar magnitudes along the incident
#: polarisation and the co-polar reflection's phase (degrees, in (−180, 180], referred to
#: the stack's top face), and the power not reflected nor transmitted in any propagating
#: order (what a sheet impedance and lossy layers absorb; the power-balance error on a
#: perfect conductor over lossless layers).
INFINITE_ARRAY_COLUMNS = (
    "frequency_hz",
    "reflection_te_real",
    "reflection_te_imag",
    "reflection_tm_real",
    "reflection_tm_imag",
    "transmission_te_real",
    "transmission_te_imag",
    "transmission_tm_real",
    "transmission_tm_imag",
    "reflection_co_abs",
    "reflection_co_phase_deg",
    "transmission_co_abs",
    "absorption",
)


def solve_columns(kind: str) -> tuple[str, ...]:
    """The per-frequency columns of a solve ``kind`` (``frequency_hz`` first)."""
    return FREE_SPACE_COLUMNS if kind == "free_space" else INFINITE_ARRAY_COLUMNS


@dataclass(frozen=True)
class StudyContext:
    """What every task of a study shares (scattered to the workers once): the base
    design, the solve settings, the figures to derive and the layers (None: vacuum)."""

    base: Base
    solve: Solve
    derive: tuple[Derive, ...]
    stack: Stack | None = None

    @classmethod
    def of(cls, spec: StudySpec) -> StudyContext:
        return cls(spec.base, spec.solve, spec.derive, spec.stack)


@dataclass(frozen=True)
class PointResult:
    """One finished point.

    Attributes
    ----------
    index : int
        The point's number in :meth:`barymesh.study.spec.StudySpec.points`.
    values : dict
        Its axis values.
    status : str
        ``"ok"`` or the one-line error.
    table : dict of str to (F,) float64
        The per-frequency columns (empty for an error row).
    derived : dict of str to float
        The derived figures (NaN for an error row).
    unknowns : int
        RWG unknowns of its mesh (0 when it was not built).
    warnings : tuple of str
        Sentences "kind: text": the solve's warnings (``SweepResult.warnings``,
        :attr:`barymesh.mom.PeriodicSweep.warnings`), then the notes of derived figures
        that are NaN for a reason (:func:`barymesh.study.derive.derived_figures`).
    """

    index: int
    values: dict[str, Any]
    status: str
    table: dict[str, np.ndarray] = field(default_factory=dict)
    derived: dict[str, float] = field(default_factory=dict)
    unknowns: int = 0
    warnings: tuple[str, ...] = ()


def one_line(exc: BaseException) -> str:
    """An exception as one line of text (its type when it has no message)."""
    text = " ".join(str(exc).split())
    return text or type(exc).__name__


def split_values(values: dict[str, Any]) -> tuple[dict[str, Any], dict[str, Any]]:
    """A point's values: (geometry paths, incidence keys); the stack's are in neither
    (:func:`barymesh.study.layers.point_stack` reads them)."""
    geometry = {
        k: v for k, v in values.items() if not k.startswith("incidence.") and not is_stack_path(k)
    }
    incidence = {k.split(".", 1)[1]: v for k, v in values.items() if k.startswith("incidence.")}
    return geometry, incidence


def design(context: StudyContext, values: dict[str, Any]) -> Any:
    """The MeshParams or UnitCell of a point; the mesher's ``ValueError`` when refused."""
    geometry, _ = split_values(values)
    return context.base.build(context.base.design(geometry))


def predicted_unknowns(item: Any) -> int:
    """An upper bound of the RWG unknowns of a design: 3/2 of its predicted triangles
    (each unknown is an edge shared by two triangles)."""
    return (3 * int(item.predicted_triangles()) + 1) // 2


def incidence_wave(context: StudyContext, values: dict[str, Any]) -> Any:
    """The point's PlaneWave: the solve's incidence with the point's incidence axes."""
    s = context.solve
    if s.direction is not None:
        return plane_wave({"direction": s.direction, "polarization": s.polarization}, "solve")
    _, incidence = split_values(values)
    return plane_wave({**(s.incidence or {}), **incidence}, "solve")


def error_point(context: StudyContext, index: int, values: dict[str, Any], status: str):
    """An error row: the status and NaN figures."""
    columns = figure_columns(context.derive)
    return PointResult(index, dict(values), status, {}, dict.fromkeys(columns, float("nan")))


def solve_point(
    context: StudyContext,
    index: int,
    values: dict[str, Any],
    memory_limit: float | None = None,
) -> PointResult:
    """Build, solve and derive one point; bad parameters give an error row, not an error.

    Parameters
    ----------
    context : StudyContext
    index : int
        The point's number.
    values : dict
        Its axis values.
    memory_limit : float, optional
        Bytes a solve may use (a Dask worker's memory limit); a larger one is an error row
        (:class:`barymesh.mom.ProblemTooLarge`) before the matrix is allocated.
    """
    try:
        item = design(context, values)
        wave = incidence_wave(context, values)
        stack = point_stack(context.stack, values)
        mesh = _mesh(item)
    except (ValueError, TypeError) as exc:
        return error_point(context, index, values, one_line(exc))
    limit = context.solve.memory_limit
    if memory_limit is not None:
        limit = memory_limit if limit is None else min(limit, memory_limit)
    try:
        solve = _free_space if context.solve.kind == "free_space" else _infinite_array
        table, response, warnings, plane = solve(mesh, context.solve, wave, limit, stack)
    except (ValueError, TypeError, MemoryError, ArithmeticError) as exc:
        point = error_point(context, index, values, one_line(exc))
        return PointResult(**{**point.__dict__, "unknowns": len(mesh.rwg)})
    derived, notes = derived_figures(context.derive, table, response, plane)
    return PointResult(
        index, dict(values), "ok", table, derived, len(mesh.rwg), tuple(warnings) + notes
    )


def solve_both_polarizations(
    context: StudyContext, values: dict[str, Any]
) -> tuple[str, np.ndarray | None, tuple[str, ...]]:
    """The (0, 0) order's full 2 × 2 TE/TM reflection of an infinite-array point, TE and
    TM incidence solved from one fill of the matrix.

    :func:`solve_point` solves the one polarisation its values name; a reflection library
    needs both at every point, and both see the same matrix (the same cell, frequency and
    incidence direction), so they are solved together here
    (:func:`barymesh.mom.periodic_sweep` with ``polarizations="both"``): one fill and one
    LU per frequency instead of two.

    Returns
    -------
    status : str
        ``"ok"``, or the error (one line) that stopped the point, as :func:`solve_point`
        gives it.
    reflection : (F, 2, 2) complex or None
        R[f, out, in] at the stack's top face; columns and rows TE, then TM (incident
        fields of unit amplitude along :func:`barymesh.mom.floquet.te_tm_polarizations`).
    warnings : tuple of str
        The sweep's.
    """
    from ..mom.periodic_sweep import periodic_sweep

    if context.solve.kind != "infinite_array":
        raise ValueError("both polarisations are solved for the infinite array only")
    try:
        item = design(context, values)
        wave = incidence_wave(context, values)
        stack = point_stack(context.stack, values)
        mesh = _mesh(item)
        r = periodic_sweep(
            mesh,
            np.asarray(context.solve.frequencies),
            wave,
            interpolate=context.solve.interpolate,
            polarizations="both",
            memory_limit=context.solve.memory_limit,
            stack=stack,
        )
    except (ValueError, TypeError, MemoryError, ArithmeticError) as exc:
        return one_line(exc), None, ()
    return "ok", r.order_reflection[:, 0, :, :], tuple(r.warnings)


def _mesh(item: Any) -> Any:
    from ..build import build_mesh
    from ..params import MeshParams

    if isinstance(item, MeshParams):
        return build_mesh(item)
    from ..cell import build_cell

    return build_cell(item).mesh


def _free_space(
    mesh: Any, solve: Solve, wave: Any, limit: float | None, stack: Stack | None = None
):
    """σ_ext and the rest over frequency (:func:`barymesh.mom.sweep`): (table, σ_ext, the
    sweep's warnings, 0.0: no reference plane). ``stack`` is None (the spec refuses
    layers in free space)."""
    from ..mom.solve import sweep

    r = sweep(mesh, np.asarray(solve.frequencies), wave, memory_limit=limit)
    ext, sca = r.extinction_cross_section, r.scattering_cross_section
    columns = (
        r.frequencies,
        ext,
        sca,
        ext - sca,
        r.input_impedance.real,
        r.input_impedance.imag,
        r.condition_numbers,
        r.residuals,
    )
    table = {
        name: np.ascontiguousarray(c, dtype=float)
        for name, c in zip(FREE_SPACE_COLUMNS, columns, strict=True)
    }
    return table, ext, r.warnings, 0.0


def _infinite_array(mesh: Any, solve: Solve, wave: Any, limit: float | None, stack: Stack | None):
    """The (0, 0) order over frequency (:func:`barymesh.mom.periodic_sweep`) on ``stack``:
    (table, the reflected power |R_co|² the figures are derived from, the sweep's
    warnings, the height (mm) over the sheet of the plane R is referred to)."""
    from ..mom.periodic_sweep import periodic_sweep

    r = periodic_sweep(
        mesh,
        np.asarray(solve.frequencies),
        wave,
        interpolate=solve.interpolate,
        polarizations="incident",
        memory_limit=limit,
        stack=stack,
    )
    refl, trans = r.reflection, r.transmission  # (F, 2): TE, TM
    r_co, t_co = r.co_polar()
    columns = (
        r.frequencies,
        refl[:, 0].real,
        refl[:, 0].imag,
        refl[:, 1].real,
        refl[:, 1].imag,
        trans[:, 0].real,
        trans[:, 0].imag,
        trans[:, 1].real,
        trans[:, 1].imag,
        np.abs(r_co),
        np.degrees(np.angle(r_co)),
        np.abs(t_co),
        r.absorption,
    )
    table = {
        name: np.ascontiguousarray(c, dtype=float)
        for name, c in zip(INFINITE_ARRAY_COLUMNS, columns, strict=True)
    }
    return table, np.abs(r_co) ** 2, r.warnings, r.reference_planes[0]
