"""The window's state without Qt: parameters, undo/redo, layers and the current mesh.

Widgets translate a user action into one call here and copy state back when an event
announces a change (the napari split between ``components`` and ``_qt``). Everything in
this module can be tested without a display.

>>> model = AppModel()
>>> model.set_value("subdivisions", 2)
True
>>> model.params.subdivisions, model.can_undo
(2, True)
>>> model.set_value("outer_radius", 1.0)   # smaller than inner_radius: refused
False
>>> model.error.name, model.params.outer_radius
('outer_radius', 9.0)
>>> model.undo(); model.params.subdivisions
4
"""

from __future__ import annotations

import logging
import math
import re
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

from barymesh import BuildCancelled, MeshParams, TriMesh, build_mesh
from barymesh.app.edit.cell_document import CellState, CellTarget
from barymesh.app.view.layers import COLOR_BY, DEFAULT_VISIBLE, DETAIL_MODES
from barymesh.cell import UnitCell, build_cell
from barymesh.params import (
    ANGULAR_STRUCTURES,
    DOUBLE_STRUCTURES,
    MAX_BARYCENTRIC_LEVELS,
    MAX_UNIFORM_SUBDIVISIONS,
    SPLIT_STRUCTURES,
    STRUCTURES,
)

log = logging.getLogger(__name__)
_COLOR_KEYS = tuple(COLOR_BY)


class Event:
    """A list of callbacks called with the same arguments: the model's only signal type."""

    def __init__(self) -> None:
        self._callbacks: list[Callable[..., Any]] = []

    def connect(self, callback: Callable[..., Any]) -> None:
        self._callbacks.append(callback)

    def disconnect(self, callback: Callable[..., Any]) -> None:
        self._callbacks.remove(callback)

    def emit(self, *args: Any) -> None:
        for callback in list(self._callbacks):
            callback(*args)


# -- parameters shown as controls -------------------------------------------------------

STRUCTURE_TITLES = {
    "patch": "Square patch",
    "triangle": "Triangle",
    "ring": "Ring",
    "double_ring": "Double ring",
    "split_ring": "Split ring",
    "split_double_ring": "Doubly split double ring (circular)",
    "square_split_double_ring": "Doubly split double ring (square)",
}
MODE_TITLES = {"paper": "Paper (overlapping patches)", "conforming": "Conforming (watertight)"}
RING_STRUCTURES = tuple(s for s in STRUCTURES if s not in ("patch", "triangle"))
NOT_TRIANGLE = tuple(s for s in STRUCTURES if s != "triangle")


#: A logarithmic slider spans this many decades each side of the value it is centred on
#: (:meth:`ParamSpec.around`); the typed field takes anything beyond.
SLIDER_DECADES = 1


@dataclass(frozen=True)
class ParamSpec:
    """How one parameter is shown: a field that takes typed values, and maybe a slider.

    The field takes any value and hands it to the core, which accepts or refuses it; the
    slider only offers convenient values between ``minimum`` and ``maximum``: linearly in
    ``step`` increments, or, with ``per_decade > 0``, on a logarithmic scale of that many
    positions per decade (values rounded to three significant figures). ``optional``
    parameters may be ``None``, typed as an empty field or ``empty_text`` and sitting at
    slider position 0. ``structures`` lists where the parameter applies.
    """

    name: str
    label: str
    unit: str
    minimum: float
    maximum: float
    step: float = 0.0
    per_decade: int = 0
    structures: tuple[str, ...] = STRUCTURES
    integer: bool = False
    optional: bool = False
    empty_text: str = "auto"
    slider: bool = True
    tooltip: str = ""
    #: The field shows value / scale in ``unit`` (frequency: Hz shown in GHz, scale 1e9).
    scale: float = 1.0
    #: The slider spans :data:`SLIDER_DECADES` each side of the value, not the whole
    #: range (lengths, the angle step: :meth:`around`).
    follows_value: bool = False

    @property
    def log_scale(self) -> bool:
        return self.per_decade > 0

    @property
    def _offset(self) -> int:
        return 1 if self.optional else 0

    @property
    def slider_max(self) -> int:
        if self.log_scale:
            decades = math.log10(self.maximum / self.minimum)
            return self._offset + math.ceil(self.per_decade * decades - 1e-9)
        return self._offset + int(round((self.maximum - self.minimum) / self.step))

    def to_slider(self, value: Any) -> int:
        """Slider position of ``value`` (nearest; clamped to the slider's range)."""
        if value is None or isinstance(value, str):
            return 0
        try:
            value = float(value)
        except (TypeError, ValueError, OverflowError):
            return 0
        if not math.isfinite(value):
            return self.slider_max if value > 0 else 0
        if value >= self.maximum:
            return self.slider_max
        if self.log_scale:
            if value <= 0:
                return 0
            pos = self._offset + int(round(self.per_decade * math.log10(value / self.minimum)))
        else:
            pos = self._offset + int(round((value - self.minimum) / self.step))
        return max(0, min(self.slider_max, pos))

    def from_slider(self, pos: int) -> float | int | None:
        """Value at slider position ``pos``."""
        if self.optional and pos <= 0:
            return None
        if pos >= self.slider_max:
            value = self.maximum
        elif self.log_scale:
            value = self.minimum * 10 ** ((pos - self._offset) / self.per_decade)
            value = float(f"{value:.3g}")
        else:
            value = round(self.minimum + (pos - self._offset) * self.step, 10)
        return int(round(value)) if self.integer else float(value)

    @property
    def windowed(self) -> bool:
        """Whether the slider shows a window around the value rather than the whole range
        (a logarithmic scale over more than ``2 * SLIDER_DECADES`` decades)."""
        return (
            self.follows_value
            and self.slider
            and self.log_scale
            and self.maximum > self.minimum * 10 ** (2 * SLIDER_DECADES) * (1 + 1e-9)
        )

    def around(self, value: Any) -> ParamSpec:
        """The slider's spec centred on ``value``: :data:`SLIDER_DECADES` each side.

        Within ``minimum`` … ``maximum`` (at an end the window keeps its width, shifted
        inwards). Itself when not :attr:`windowed` or ``value`` is not a positive number.

        >>> spec = SPECS["patch_size"]
        >>> w = spec.around(10.0)
        >>> w.minimum, w.maximum, w.from_slider(w.to_slider(10.0)), w.slider_max
        (1.0, 100.0, 10.0, 96)
        >>> spec.around(0.02).minimum, spec.around(0.02).maximum
        (0.01, 1.0)
        """
        if not self.windowed or isinstance(value, (str, bool)) or value is None:
            return self
        try:
            centre = float(value)
        except (TypeError, ValueError, OverflowError):
            return self
        if not math.isfinite(centre) or centre <= 0:
            return self
        factor = 10.0**SLIDER_DECADES
        lo, hi = centre / factor, centre * factor
        if lo < self.minimum:
            lo, hi = self.minimum, self.minimum * factor**2
        elif hi > self.maximum:
            lo, hi = self.maximum / factor**2, self.maximum
        return replace(self, minimum=lo, maximum=hi)

    def holds(self, value: Any) -> bool:
        """Whether ``value`` is a number on this spec's slider (``minimum`` … ``maximum``)."""
        try:
            v = float(value)
        except (TypeError, ValueError, OverflowError):
            return False
        return self.minimum * (1 - 1e-9) <= v <= self.maximum * (1 + 1e-9)

    def applies(self, structure: str) -> bool:
        return structure in self.structures


#: Lengths span what the presets use (0.5 mm split-ring tracks to Makarov's 1000 mm plate)
#: with room on both sides, so their sliders are logarithmic.
_LENGTH = {
    "unit": "mm",
    "minimum": 0.01,
    "maximum": 10_000.0,
    "per_decade": 48,
    "follows_value": True,
}

PARAM_SPECS = (
    ParamSpec(
        "inner_radius",
        "Inner radius",
        structures=RING_STRUCTURES,
        **_LENGTH,
        tooltip="Radius of the (inner) ring; half side of the inner square ring",
    ),
    ParamSpec(
        "outer_radius",
        "Outer radius",
        structures=DOUBLE_STRUCTURES,
        **_LENGTH,
        tooltip="Radius of the outer ring of a double ring",
    ),
    ParamSpec(
        "patch_size",
        "Patch size",
        **_LENGTH,
        tooltip="Side of a square patch, and width of a ring's track",
    ),
    ParamSpec(
        "angle_step",
        "Angle step",
        "°",
        0.001,
        360.0,
        per_decade=48,
        structures=ANGULAR_STRUCTURES,
        follows_value=True,
        tooltip="Angle between neighbouring patches (paper) or the widest sector "
        "(conforming), in (0, 360]",
    ),
    ParamSpec(
        "subdivisions",
        "Subdivisions n",
        "",
        1,
        MAX_UNIFORM_SUBDIVISIONS,
        1,
        integer=True,
        tooltip="Segments per primary-triangle edge: n² sub-triangles each (uniform), "
        "or barycentric levels",
    ),
    ParamSpec(
        "gap_width",
        "Gap width",
        structures=SPLIT_STRUCTURES,
        **_LENGTH,
        tooltip="Width of the slots cut through split rings",
    ),
    ParamSpec(
        "gap_angle",
        "Gap angle",
        "°",
        -180.0,
        180.0,
        1.0,
        structures=SPLIT_STRUCTURES,
        tooltip="Direction of the slots' centre line, degrees from +x",
    ),
    ParamSpec(
        "tolerance",
        "Tolerance ε",
        "mm",
        1e-9,
        1e-1,
        per_decade=4,
        optional=True,
        tooltip="Welding distance: vertices closer than ε are one vertex (the paper's "
        "metric constraint). auto (empty) = 1e-9 of the structure's size",
    ),
    ParamSpec(
        "frequency",
        "Frequency",
        "GHz",
        0.0,
        math.inf,
        optional=True,
        empty_text="off",
        slider=False,
        scale=1e9,
        tooltip="Size the mesh for this frequency: the smallest subdivisions whose edges "
        "are all at most λ / cells per wavelength; off (empty) = subdivisions n",
    ),
)
#: The Advanced group: rarely changed parameters.
ADVANCED_SPECS = (
    ParamSpec(
        "patch_width",
        "Patch height w",
        optional=True,
        empty_text="square",
        structures=NOT_TRIANGLE,
        **_LENGTH,
        tooltip="Height of a rectangular patch; square (empty) = the patch size",
    ),
    ParamSpec(
        "max_triangles",
        "Triangle budget",
        "",
        1,
        1e9,
        integer=True,
        slider=False,
        tooltip="Meshes predicted above this many triangles are refused before they are built",
    ),
    ParamSpec(
        "cells_per_wavelength",
        "Cells per λ",
        "",
        1.0,
        math.inf,
        slider=False,
        tooltip="With a frequency: edges at most λ / this (10 is the common rule, "
        "Feko's standard 12)",
    ),
    ParamSpec(
        "relative_permittivity",
        "Permittivity εr",
        "",
        1.0,
        math.inf,
        slider=False,
        tooltip="With a frequency: the wavelength in a medium of this εr, λ = c0 / (f √εr)",
    ),
    ParamSpec(
        "max_edge",
        "Largest edge",
        "mm",
        0.0,
        math.inf,
        optional=True,
        empty_text="off",
        slider=False,
        tooltip="The smallest subdivisions whose edges are all at most this; with a "
        "frequency too, the stricter of the two; off (empty) = no limit",
    ),
)
SPECS = {s.name: s for s in PARAM_SPECS + ADVANCED_SPECS}
#: Choice parameters: name -> (label, {value: title}).
CHOICES = {
    "structure": ("Structure", STRUCTURE_TITLES),
    "mode": ("Mode", MODE_TITLES),
    "diagonal": ("Diagonal", {"BC": "BC (paper)", "AD": "AD (Makarov)"}),
    "scheme": ("Scheme", {"uniform": "Uniform n × n", "barycentric": "Barycentric levels"}),
}
CHOICE_STRUCTURES = {"diagonal": NOT_TRIANGLE}
#: Parameters typed as coordinates in the Advanced group: name -> (label, structures).
POINT_PARAMS = {
    "origin": ("Origin x, y", STRUCTURES),
    "triangle_vertices": ("Triangle A; B; C", ("triangle",)),
}


def applies(name: str, structure: str) -> bool:
    """Whether parameter ``name`` has an effect on ``structure``."""
    if name in SPECS:
        return SPECS[name].applies(structure)
    if name in POINT_PARAMS:
        return structure in POINT_PARAMS[name][1]
    return structure in CHOICE_STRUCTURES.get(name, STRUCTURES)


def subdivisions_limit(scheme: str) -> int:
    return MAX_UNIFORM_SUBDIVISIONS if scheme == "uniform" else MAX_BARYCENTRIC_LEVELS


def carried_subdivisions(n: Any, old_scheme: str, new_scheme: str) -> Any:
    """The subdivisions of ``new_scheme`` closest to ``n`` of ``old_scheme`` in triangles.

    Uniform n makes n² sub-triangles per primary triangle, barycentric L levels 6^L; the
    result is the one whose count is nearest on a log scale, within the new scheme's range.
    Anything but a valid integer comes back unchanged (the core refuses it).

    >>> carried_subdivisions(16, "uniform", "barycentric"), carried_subdivisions(3, "barycentric", "uniform")
    (3, 15)
    """  # noqa: E501
    if old_scheme == new_scheme or isinstance(n, bool) or not isinstance(n, int):
        return n
    if not 1 <= n <= subdivisions_limit(old_scheme):
        return n
    log_count = 2 * math.log(n) if old_scheme == "uniform" else n * math.log(6)
    if new_scheme == "uniform":
        best = round(math.exp(log_count / 2))
    else:
        best = round(log_count / math.log(6))
    return max(1, min(subdivisions_limit(new_scheme), best))


def named_parameter(message: str) -> str | None:
    """The first parameter a core error message names as ``name=value``."""
    for match in re.finditer(r"\b(\w+)=", message):
        if match.group(1) in MeshParams.__dataclass_fields__:
            return match.group(1)
    return None


def _carry_note(n: int, m: int, old_scheme: str, new_scheme: str) -> str:
    def what(k: int, scheme: str) -> str:
        if scheme == "uniform":
            return f"n = {k} ({k * k} sub-triangles per primary triangle)"
        return f"{k} barycentric level{'s' if k > 1 else ''} ({6**k} sub-triangles)"

    return f"{new_scheme} scheme: {what(n, old_scheme)} carried over as {what(m, new_scheme)}"


# -- typed values ----------------------------------------------------------------------------

_NUMBER = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?")
_INTEGER = re.compile(r"[+-]?\d+")


def format_value(value: Any) -> str:
    """The text a field shows for ``value``: exact, shortest, with a decimal point.

    >>> format_value(4.5), format_value(1000.0), format_value(1e-9), format_value(None)
    ('4.5', '1000', '1e-09', '')
    """
    if value is None:
        return ""
    if isinstance(value, str):
        return value
    if isinstance(value, (tuple, list)):
        if value and isinstance(value[0], (tuple, list)):
            return "; ".join(format_value(p) for p in value)
        return ", ".join(format_value(v) for v in value)
    if isinstance(value, int):
        return str(value)
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text


@dataclass(frozen=True)
class Reading:
    """What a typed text was read as: a number, ``None`` (empty), or the text itself.

    ``value`` is the text unchanged when it is not a number, so that the core's refusal
    names what the user typed. ``note`` says how the text was read when that is not
    obvious (the locale's decimal separator).
    """

    value: Any
    note: str | None = None


def _locale_note(text: str, value: Any, decimal_point: str) -> str:
    if decimal_point == ".":
        why = "a dot is always read as the decimal separator"
    else:
        why = f"{decimal_point!r} is this system's decimal separator"
    return f"read {text.strip()!r} as {format_value(value)} ({why})"


def read_number(text: str, spec: ParamSpec | None = None, decimal_point: str = ".") -> Reading:
    """Read a typed number exactly: no clamping, no rounding, no guessing.

    A dot is always the decimal separator; the locale's own ``decimal_point`` is accepted
    as well. Where the locale's separator is not a dot, the note says which one was read.
    Group separators, which differ between locales, are not accepted: such text is
    returned unchanged for the core to refuse.

    >>> read_number("4.5").value, read_number("1e-3").value, read_number("-3").value
    (4.5, 0.001, -3.0)
    >>> r = read_number("4,5", decimal_point=","); r.value, r.note
    (4.5, "read '4,5' as 4.5 (',' is this system's decimal separator)")
    >>> read_number("4.5", decimal_point=",").note
    "read '4.5' as 4.5 (a dot is always read as the decimal separator)"
    >>> read_number("4,5").value
    '4,5'
    """
    s = text.strip()
    if spec is not None and spec.unit and s.endswith(spec.unit):
        s = s[: -len(spec.unit)].strip()
    if spec is not None and spec.optional and s.lower() in ("", spec.empty_text.lower()):
        return Reading(None)
    localized = decimal_point not in (".", "") and decimal_point in s and "." not in s
    if localized:
        s = s.replace(decimal_point, ".")
    if spec is not None and spec.integer and _INTEGER.fullmatch(s):
        value: Any = int(s)
    elif _NUMBER.fullmatch(s):
        value = float(s)
        if spec is not None and spec.integer and math.isfinite(value) and value.is_integer():
            value = int(value)
    else:
        return Reading(text.strip())
    if localized:
        return Reading(value, _locale_note(text, value, decimal_point))
    if decimal_point not in (".", "") and "." in s:
        return Reading(value, _locale_note(text, value, "."))
    return Reading(value)


def read_points(text: str, count: int, decimal_point: str = ".") -> Reading:
    """Read ``count`` points typed as ``x, y; x, y; ...`` (``x y`` works too).

    With a decimal comma the coordinates are separated by spaces only. Anything that is
    not ``count`` pairs of numbers comes back as the text for the core to refuse.

    >>> read_points("1, 2", 1).value, read_points("0 0; 4 0; 0 3", 3).value
    ((1.0, 2.0), ((0.0, 0.0), (4.0, 0.0), (0.0, 3.0)))
    """
    s = text.strip()
    if count > 1 and s == "":
        return Reading(None)
    points, notes = [], []
    for part in s.split(";"):
        if decimal_point == ",":
            coords = part.split()
        else:
            coords = [c for c in re.split(r"[,\s]+", part.strip()) if c]
        readings = [read_number(c, None, decimal_point) for c in coords]
        if len(readings) != 2 or not all(isinstance(r.value, float) for r in readings):
            return Reading(s)
        points.append(tuple(r.value for r in readings))
        notes += [r.note for r in readings if r.note]
    if len(points) != count:
        return Reading(s)
    value = points[0] if count == 1 else tuple(points)
    which = decimal_point if decimal_point in s else "."
    return Reading(value, _locale_note(s, value, which) if notes else None)


# -- results -------------------------------------------------------------------------------


@dataclass
class MeshResult:
    """One finished (or failed) mesh build."""

    generation: int
    params: MeshParams | None
    mesh: TriMesh | None = None
    stats: dict[str, Any] = field(default_factory=dict)
    seconds: float = 0.0
    scene: Any = None  # barymesh.app.view.scene.SceneData, prepared off the GUI thread
    error: str | None = None
    source: str = "parameters"  # or the path of an imported mesh file
    cancelled: bool = False  # abandoned because a newer request or Cancel came
    timings: dict[str, float] = field(default_factory=dict)  # stage -> seconds
    cell: UnitCell | None = None  # the (visible) unit cell meshed instead of ``params``
    cell_mesh: Any = None  # its barymesh.cell.CellMesh: parts, periodic pairs, notes
    cell_stats: dict[str, Any] = field(default_factory=dict)  # CellMesh.stats()

    @property
    def target(self) -> MeshParams | CellTarget | None:
        """What was built, as :meth:`AppModel.build_target` asks for it."""
        return CellTarget(self.cell) if self.cell is not None else self.params


def compute(
    params: MeshParams | CellTarget,
    generation: int = 0,
    prepare: Callable[[TriMesh], Any] | None = None,
    cancel: Callable[[], bool] | None = None,
) -> MeshResult:
    """Build the mesh and its statistics (and ``prepare(mesh)``, e.g. the scene datasets).

    Never raises: a failure comes back as ``MeshResult.error``, a build abandoned because
    ``cancel()`` returned True (checked by the core between its stages and here between
    build, statistics and ``prepare``) as ``MeshResult.cancelled``. ``seconds`` is the
    time of ``build_mesh`` plus the statistics (topology), what a user waits for;
    ``timings`` has each stage. A unit cell (a :class:`barymesh.app.edit.cell_document.CellTarget`
    in place of ``params``) is built by :func:`compute_cell`.
    """
    if isinstance(params, CellTarget):
        return compute_cell(params.cell, generation, prepare, cancel)
    timings: dict[str, float] = {}

    def check() -> None:
        if cancel is not None and cancel():
            raise BuildCancelled("the build was cancelled")

    try:
        start = time.perf_counter()
        mesh = build_mesh(params, cancel=cancel)
        timings["build"] = time.perf_counter() - start
        check()
        stats = mesh.stats()
        seconds = time.perf_counter() - start
        timings["statistics"] = seconds - timings["build"]
        check()
        scene = None
        if prepare is not None:
            begin = time.perf_counter()
            scene = prepare(mesh)
            timings["scene"] = time.perf_counter() - begin
            check()
    except BuildCancelled:
        return MeshResult(generation, params, error="cancelled", cancelled=True, timings=timings)
    except Exception as exc:  # noqa: BLE001 - reported in the window, never a crash
        log.exception("meshing failed for %s", params)
        return MeshResult(generation, params, error=f"meshing failed: {exc}")
    return MeshResult(generation, params, mesh, stats, seconds, scene, timings=timings)


def compute_cell(
    cell: UnitCell,
    generation: int = 0,
    prepare: Callable[[TriMesh], Any] | None = None,
    cancel: Callable[[], bool] | None = None,
) -> MeshResult:
    """:func:`compute` of a unit cell: :func:`barymesh.cell.build_cell`, the whole cell's
    statistics, every part's and the periodic match (``cell_stats``). A refusal of the
    core (overlapping elements in conforming mode) comes back as ``error``."""
    timings: dict[str, float] = {}

    def check() -> None:
        if cancel is not None and cancel():
            raise BuildCancelled("the build was cancelled")

    try:
        start = time.perf_counter()
        cell_mesh = build_cell(cell)
        timings["build"] = time.perf_counter() - start
        check()
        mesh = cell_mesh.mesh
        stats = mesh.stats()
        seconds = time.perf_counter() - start
        timings["statistics"] = seconds - timings["build"]
        cell_stats = cell_mesh.stats()
        check()
        scene = None
        if prepare is not None:
            begin = time.perf_counter()
            scene = prepare(mesh)
            timings["scene"] = time.perf_counter() - begin
            check()
    except BuildCancelled:
        return MeshResult(
            generation, None, error="cancelled", cancelled=True, timings=timings, cell=cell
        )
    except ValueError as exc:  # the core's refusal: overlapping elements, a tolerance
        return MeshResult(generation, None, error=f"cell {cell.name!r}: {exc}", cell=cell)
    except Exception as exc:  # noqa: BLE001 - reported in the window, never a crash
        log.exception("meshing failed for cell %r", cell.name)
        return MeshResult(generation, None, error=f"meshing failed: {exc}", cell=cell)
    return MeshResult(
        generation,
        None,
        mesh,
        stats,
        seconds,
        scene,
        timings=timings,
        cell=cell,
        cell_mesh=cell_mesh,
        cell_stats=cell_stats,
    )


def mom_matrix_bytes(unknowns: int) -> int:
    """Memory of a dense N x N complex128 MoM impedance matrix: 16 N² bytes."""
    return 16 * int(unknowns) ** 2


def format_bytes(n: float) -> str:
    """``1536 -> '1.5 KiB'``, binary prefixes as memory is sold."""
    for unit in ("B", "KiB", "MiB", "GiB", "TiB"):
        if abs(n) < 1024 or unit == "TiB":
            return f"{n:,.0f} {unit}" if unit == "B" else f"{n:,.1f} {unit}"
        n /= 1024
    return f"{n:.1f} TiB"  # pragma: no cover


def format_seconds(s: float) -> str:
    return f"{s * 1e3:,.1f} ms" if s < 1 else f"{s:,.2f} s"


#: Statistics panel rows: key -> label.
STAT_LABELS = {
    "patches": "Patches",
    "vertices": "Vertices",
    "triangles": "Triangles",
    "edges": "Edges",
    "interior_edges": "Interior edges (RWG unknowns N)",
    "boundary_edges": "Boundary edges",
    "junction_edges": "Junction edges",
    "min_edge": "Shortest edge",
    "max_edge": "Longest edge",
    "min_angle_deg": "Smallest angle",
    "max_aspect_ratio": "Largest aspect ratio",
    "overlap_ratio": "Overlap ratio (paper mode)",
    "euler_characteristic": "Euler characteristic V − E + F",
    "mesh_time": "Mesh time",
    "mom_memory": "Dense MoM matrix (16 N² bytes)",
}


def stats_texts(result: MeshResult | None) -> dict[str, str]:
    """The statistics panel's text for every key of :data:`STAT_LABELS`."""
    if result is None or result.mesh is None:
        return dict.fromkeys(STAT_LABELS, "–")
    s = result.stats
    out = {}
    for key in (
        "patches",
        "vertices",
        "triangles",
        "edges",
        "interior_edges",
        "boundary_edges",
        "junction_edges",
        "euler_characteristic",
    ):
        out[key] = f"{s[key]:,}"
    out["min_edge"] = f"{s['min_edge']:.4g} mm"
    out["max_edge"] = f"{s['max_edge']:.4g} mm"
    out["min_angle_deg"] = f"{s['min_angle_deg']:.2f}°"
    out["max_aspect_ratio"] = f"{s['max_aspect_ratio']:.3f}"
    ratio = s.get("overlap_ratio")
    out["overlap_ratio"] = "–" if ratio is None else f"{100 * ratio:.2f} %"
    out["mesh_time"] = format_seconds(result.seconds) if result.source == "parameters" else "–"
    out["mom_memory"] = format_bytes(mom_matrix_bytes(s["interior_edges"]))
    return {key: out[key] for key in STAT_LABELS}


# -- the model -----------------------------------------------------------------------------


@dataclass(frozen=True)
class ParamError:
    """A value the core refused: which control to mark, and the core's message."""

    name: str
    message: str


_REFUSALS = (ValueError, TypeError, OverflowError)


class AppModel:
    """Parameters with undo/redo, the last good mesh, layer visibility and colouring.

    ``params`` is always valid and describes the mesh on screen (or the one being built):
    the last combination the core accepted and built. A value the core refuses, typed or
    built, is kept in ``refused`` (the control keeps showing it) with the core's message in
    ``errors`` under the same name, until it is corrected, reverted (Esc) or replaced.
    Other changes meanwhile are taken on their own. ``notes`` say how a value was read or
    carried over (a decimal comma, a scheme change).

    Events (callbacks): ``params_changed(params)``, ``draft_changed(draft)``,
    ``error_changed(error or None)``, ``history_changed()``, ``result_changed(result)``,
    ``layer_changed(name, visible)``, ``color_by_changed(key)``,
    ``detail_changed(mode)``, ``build_failed(message)``.

    A unit cell (:attr:`cell_state`, see :mod:`barymesh.app.edit.cell_document`) replaces the one
    structure when one is open: ``params`` are then the selected element's, every edit of
    the cell or of those parameters is one undo step (the undo stack holds parameters and
    cell states alike), and the cell is what is built. Cell events:
    ``cell_changed(state or None)`` and ``cell_error_changed(message or None)`` (an edit
    or a build of the cell the core refused; the last good cell stays).
    """

    def __init__(self, params: MeshParams | None = None, cell: UnitCell | None = None) -> None:
        self.params = params if params is not None else MeshParams()
        self.cell_state: CellState | None = None
        if cell is not None:
            self.cell_state = CellState.of(cell)
            self.params = self.cell_state.params or self.params
        self.shown_state: CellState | None = None  # of the last cell mesh shown
        self.cell_error: str | None = None
        self.refused: dict[str, Any] = {}
        self.errors: dict[str, ParamError] = {}
        self._announced: dict[str, ParamError] = {}
        self.notes: dict[str, str] = {}
        self.undo_stack: list[MeshParams | CellState] = []
        self.redo_stack: list[MeshParams | CellState] = []
        self._merging: str | None = None
        self.result: MeshResult | None = None
        self.shown_params: MeshParams | None = None  # of the last parametric mesh shown
        self.generation = 0
        self.layers: dict[str, bool] = dict(DEFAULT_VISIBLE)
        self.color_by = "none"
        self.detail = "auto"  # level of detail, a key of DETAIL_MODES
        self.params_changed = Event()
        self.draft_changed = Event()
        self.error_changed = Event()
        self.history_changed = Event()
        self.result_changed = Event()
        self.layer_changed = Event()
        self.color_by_changed = Event()
        self.detail_changed = Event()
        self.build_failed = Event()
        self.cell_changed = Event()
        self.cell_error_changed = Event()

    # -- parameters ---------------------------------------------------------------

    @property
    def draft(self) -> dict[str, Any]:
        """What the controls show: ``params`` with the refused values in their place."""
        return {**self.params.to_dict(), **self.refused}

    @property
    def error(self) -> ParamError | None:
        """The latest refusal still standing (``None`` when every value is taken)."""
        return next(reversed(self.errors.values()), None)

    def set_text(self, name: str, text: str, decimal_point: str = ".") -> bool:
        """A value typed into the field of ``name``: read exactly, then :meth:`set_value`.

        ``decimal_point`` is the system locale's (a dot is always accepted too). Text that
        is not a number goes to the core as typed, so its refusal quotes it.
        """
        if name in POINT_PARAMS:
            count = 1 if name == "origin" else 3
            reading = read_points(text, count, decimal_point)
        else:
            spec = SPECS.get(name)
            reading = read_number(text, spec, decimal_point)
            if spec is not None and spec.scale != 1 and isinstance(reading.value, float):
                reading = Reading(reading.value * spec.scale, reading.note)  # GHz -> Hz
        return self.set_value(name, reading.value, note=reading.note)

    def set_value(
        self, name: str, value: Any, merge: bool = False, note: str | None = None
    ) -> bool:
        """Change one parameter as a user did; True if the core accepted it.

        The change is tried together with the values refused so far (fixing one side of a
        combination takes both), then on its own against ``params``. If the core refuses
        it, ``params`` stay, and ``value`` is kept in :attr:`refused` with the core's
        message under ``name``. ``merge=True`` folds consecutive changes of the same
        parameter into one undo step (a slider drag); :meth:`end_merge` ends such a run.
        """
        if name not in MeshParams.__dataclass_fields__:
            raise ValueError(f"name={name!r} is not a parameter")
        changes = {name: value}
        carried = None
        if name == "scheme":
            draft = self.draft
            n = draft["subdivisions"]
            m = carried_subdivisions(n, draft["scheme"], value)
            if m != n:
                changes["subdivisions"] = m
                carried = _carry_note(n, m, draft["scheme"], value)
        for key in changes:
            self.notes.pop(key, None)
        base = self.params.to_dict()
        pending = {k: v for k, v in self.refused.items() if k not in changes}
        try:
            params = MeshParams.from_dict({**base, **pending, **changes})
            self.refused.clear()
            self.errors.clear()
        except _REFUSALS:
            try:
                params = MeshParams.from_dict({**base, **changes})
            except _REFUSALS as exc:
                self.refused[name] = value
                self.errors.pop(name, None)
                self.errors[name] = ParamError(name, str(exc))
                if note:
                    self.notes[name] = note
                self.draft_changed.emit(self.draft)
                self._errors_changed()
                return False
            for key in changes:
                self.refused.pop(key, None)
                self.errors.pop(key, None)
            for key, pending_value in pending.items():  # still refused? say why, anew
                try:
                    params = MeshParams.from_dict({**params.to_dict(), key: pending_value})
                    self.refused.pop(key)
                    self.errors.pop(key, None)
                except _REFUSALS as exc:
                    self.errors[key] = ParamError(key, str(exc))
        try:
            state = self._with_params(params)
        except _REFUSALS as exc:  # the cell refuses it (a mode an element cannot take)
            self.refused[name] = value
            self.errors.pop(name, None)
            self.errors[name] = ParamError(name, str(exc))
            self.draft_changed.emit(self.draft)
            self._errors_changed()
            return False
        if note:
            self.notes[name] = note
        if carried:
            self.notes["subdivisions"] = carried
        self._commit(state, merge_name=name if merge else None)
        return True

    def _with_params(self, params: MeshParams) -> MeshParams | CellState:
        """The state with ``params``: the selected element's in a cell."""
        if self.cell_state is None:
            return params
        return self.cell_state.with_params(params)

    def _state(self) -> MeshParams | CellState:
        """What an undo step restores: the parameters, or the cell state."""
        return self.cell_state if self.cell_state is not None else self.params

    def build_target(self) -> MeshParams | CellTarget:
        """What the mesh on screen should be: the parameters, or the cell's visible part."""
        if self.cell_state is None:
            return self.params
        return CellTarget(self.cell_state.visible)

    def revert(self, name: str) -> None:
        """Drop the refused value of ``name`` (Esc in its field): show ``params`` again."""
        self.notes.pop(name, None)
        self.refused.pop(name, None)
        self.errors.pop(name, None)
        self.draft_changed.emit(self.draft)
        self._errors_changed()

    def end_merge(self) -> None:
        """The slider was released: the next change starts a new undo step."""
        self._merging = None

    def set_params(self, params: MeshParams) -> None:
        """Replace every parameter (preset, parameter file, reset) as one undo step.

        An open cell is left: the window shows this one structure again (undoable)."""
        if not isinstance(params, MeshParams):
            raise TypeError(f"params must be a MeshParams, got {type(params).__name__}")
        self._forget_refusals()
        self._commit(params, merge_name=None, force=True)

    def reset(self) -> None:
        """Back to the defaults (the paper's Fig. 12(a)); undoable."""
        self.set_params(MeshParams())

    def _forget_refusals(self) -> None:
        self.refused.clear()
        self.notes.clear()
        self.errors.clear()

    def _commit(
        self, state: MeshParams | CellState, merge_name: str | None, force: bool = False
    ) -> None:
        changed = state != self._state()
        if changed:
            if not (merge_name is not None and merge_name == self._merging):
                self.undo_stack.append(self._state())
                self.redo_stack.clear()
            self._merging = merge_name
        self._apply(state, changed or force)

    def _apply(self, state: MeshParams | CellState, changed: bool) -> None:
        was_cell = self.cell_state
        if isinstance(state, CellState):
            self.cell_state = state
            self.params = state.params or self.params
        else:
            self.cell_state = None
            self.params = state
        if was_cell is not self.cell_state:  # a cell edited, opened or left
            if changed:
                self._set_cell_error(None)
            self.cell_changed.emit(self.cell_state)
        self.draft_changed.emit(self.draft)
        self._errors_changed()
        if changed:
            self.generation += 1
            self.params_changed.emit(self.params)
        self.history_changed.emit()

    # -- the unit cell ------------------------------------------------------------

    @property
    def cell(self) -> UnitCell | None:
        """The open unit cell (hidden elements included), or None."""
        return None if self.cell_state is None else self.cell_state.cell

    def set_cell(self, cell: UnitCell) -> None:
        """Open ``cell`` (a cell file, a preset) as one undo step; its first element is
        selected."""
        if not isinstance(cell, UnitCell):
            raise TypeError(f"cell must be a UnitCell, got {type(cell).__name__}")
        self._forget_refusals()
        self._commit(CellState.of(cell), merge_name=None, force=True)

    def edit_cell(self, edit: Callable[[CellState], CellState]) -> bool:
        """Apply one edit of the Elements or Lattice panel as one undo step.

        ``edit(state)`` returns the new state or raises ``ValueError``/``TypeError``: then
        the cell stays as it is and the message is the :attr:`cell_error`. Returns whether
        the edit was taken.
        """
        if self.cell_state is None:
            self._set_cell_error("no unit cell is open")
            return False
        try:
            state = edit(self.cell_state)
        except _REFUSALS as exc:
            self._set_cell_error(str(exc))
            return False
        self._forget_refusals()
        self._commit(state, merge_name=None)
        return True

    def select_element(self, k: int | None) -> None:
        """Make element ``k`` the one the Parameters panel edits (not an undo step)."""
        if self.cell_state is None or k == self.cell_state.selected:
            return
        self.cell_state = self.cell_state.with_selected(k)
        self._forget_refusals()
        self.params = self.cell_state.params or self.params
        self.cell_changed.emit(self.cell_state)
        self.draft_changed.emit(self.draft)
        self._errors_changed()

    def _set_cell_error(self, message: str | None) -> None:
        if message != self.cell_error:
            self.cell_error = message
            self.cell_error_changed.emit(message)

    def _errors_changed(self) -> None:
        """Announce the refusals when they differ from the last announcement."""
        if self.errors != self._announced:
            self._announced = dict(self.errors)
            self.error_changed.emit(self.error)

    @property
    def can_undo(self) -> bool:
        return bool(self.undo_stack)

    @property
    def can_redo(self) -> bool:
        return bool(self.redo_stack)

    def undo(self) -> None:
        """Back to the parameters before the last accepted change (no-op if none)."""
        if not self.undo_stack:
            return
        self.redo_stack.append(self._state())
        self._merging = None
        self._forget_refusals()
        self._apply(self.undo_stack.pop(), True)

    def redo(self) -> None:
        if not self.redo_stack:
            return
        self.undo_stack.append(self._state())
        self._merging = None
        self._forget_refusals()
        self._apply(self.redo_stack.pop(), True)

    # -- results ------------------------------------------------------------------

    def set_result(self, result: MeshResult) -> bool:
        """Accept a finished build; stale (older generation) and failed ones are not shown.

        A failed build is not committed: ``params`` go back to those of the mesh on
        screen and the value that failed is kept as refused, with the core's message
        under its control. Returns whether the result became the current mesh.
        """
        if result.generation != self.generation:
            log.debug("dropped stale mesh of generation %d", result.generation)
            return False
        if result.error is not None or result.mesh is None:
            message = result.error or "meshing failed"
            if result.cell is not None:
                self._refuse_cell_build(message)
            else:
                self._refuse_build(result.params, message.removeprefix("meshing failed: "))
            self.build_failed.emit(message)
            return False
        self.result = result
        if result.params is not None:
            self.shown_params = result.params
        self.shown_state = self.cell_state if result.cell is not None else None
        self.result_changed.emit(result)
        return True

    def _refuse_build(self, failed: MeshParams | None, message: str) -> None:
        good = self.shown_params
        named = named_parameter(message)
        if failed is None or good is None or failed == good:
            marks = [named or "structure"]  # nothing to go back to: mark what is shown
        else:
            changed = [
                k for k in MeshParams.__dataclass_fields__ if getattr(failed, k) != getattr(good, k)
            ]
            marks = [named] if named in changed else changed
            for key in marks:
                self.refused[key] = failed.to_dict()[key]
            if self.undo_stack and self.undo_stack[-1] == good:
                self.undo_stack.pop()
            self.params = good
            self._merging = None
        for key in marks:
            self.errors.pop(key, None)
            self.errors[key] = ParamError(key, message)
        self.draft_changed.emit(self.draft)
        self._errors_changed()
        self.history_changed.emit()

    def _refuse_cell_build(self, message: str) -> None:
        """The core refused the cell (overlapping elements): back to what is on screen (a
        cell, or the structure before a cell was opened), the refused edit dropped from
        the history, the message kept."""
        shown = self.result
        good: MeshParams | CellState | None = None
        if shown is not None and shown.cell is not None:
            good = self.shown_state
        elif shown is not None and shown.source == "parameters":
            good = shown.params
        if good is not None and good != self._state():
            if self.undo_stack and self.undo_stack[-1] == good:
                self.undo_stack.pop()
            if isinstance(good, CellState):
                self.cell_state = good
                self.params = good.params or self.params
            else:
                self.cell_state, self.params = None, good
            self._merging = None
            self._forget_refusals()
            self.cell_changed.emit(self.cell_state)
            self.draft_changed.emit(self.draft)
            self._errors_changed()
            self.history_changed.emit()
        self._set_cell_error(message)

    @property
    def file_source(self) -> str | None:
        """The path of the mesh file on screen, or ``None`` for the parametric mesh."""
        if self.result is None or self.result.source == "parameters":
            return None
        return self.result.source

    def return_to_parameters(self) -> None:
        """Leave a mesh file: build ``params`` again (the panel's explicit button)."""
        self.generation += 1
        self.params_changed.emit(self.params)

    def show_imported(self, mesh: TriMesh, path: str) -> MeshResult:
        """Show a mesh read from a file (until the next parameter change)."""
        self.generation += 1
        result = MeshResult(self.generation, None, mesh, mesh.stats(), 0.0, source=path)
        return result

    # -- layers -------------------------------------------------------------------

    def set_layer_visible(self, name: str, visible: bool) -> None:
        if name not in self.layers:
            raise ValueError(f"layer={name!r} is unknown; expected one of {', '.join(self.layers)}")
        visible = bool(visible)
        if self.layers[name] != visible:
            self.layers[name] = visible
            self.layer_changed.emit(name, visible)

    def set_color_by(self, key: str) -> None:
        if key not in _COLOR_KEYS:
            raise ValueError(
                f"color_by={key!r} is unknown; expected one of {', '.join(_COLOR_KEYS)}"
            )
        if key != self.color_by:
            self.color_by = key
            self.color_by_changed.emit(key)

    def set_detail(self, mode: str) -> None:
        """Level of detail: "auto" or "full" (see :data:`barymesh.app.view.layers.DETAIL_MODES`)."""
        if mode not in DETAIL_MODES:
            raise ValueError(
                f"detail={mode!r} is unknown; expected one of {', '.join(DETAIL_MODES)}"
            )
        if mode != self.detail:
            self.detail = mode
            self.detail_changed.emit(mode)

    # -- persistence ----------------------------------------------------------------

    def view_state(self) -> dict[str, Any]:
        """Layers and colouring as a JSON-ready dict (for QSettings)."""
        return {"layers": dict(self.layers), "color_by": self.color_by}

    def restore_view_state(self, state: Any) -> None:
        """Apply :meth:`view_state` output; unknown or malformed entries are ignored."""
        if not isinstance(state, dict):
            return
        layers = state.get("layers")
        if isinstance(layers, dict):
            for name, visible in layers.items():
                if name in self.layers and isinstance(visible, bool):
                    self.set_layer_visible(name, visible)
        if state.get("color_by") in _COLOR_KEYS:
            self.set_color_by(state["color_by"])
