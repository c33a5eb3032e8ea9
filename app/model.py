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
from dataclasses import dataclass, field
from typing import Any

from core import BuildCancelled, MeshParams, TriMesh, build_mesh
from core.params import (
    ANGULAR_STRUCTURES,
    DOUBLE_STRUCTURES,
    MAX_BARYCENTRIC_LEVELS,
    MAX_UNIFORM_SUBDIVISIONS,
    SPLIT_STRUCTURES,
    STRUCTURES,
)

from .layers import COLOR_BY, DEFAULT_VISIBLE

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


@dataclass(frozen=True)
class ParamSpec:
    """How one numeric parameter is shown: a slider paired with a spin box.

    The slider moves in ``step`` increments between ``minimum`` and ``maximum`` (or in
    quarter decades on a log scale); the spin box shows the exact value with ``unit``.
    ``structures`` lists where the parameter applies (elsewhere the control is disabled).
    """

    name: str
    label: str
    unit: str
    minimum: float
    maximum: float
    step: float
    decimals: int
    structures: tuple[str, ...] = STRUCTURES
    integer: bool = False
    log_scale: bool = False
    optional: bool = False  # ``None`` allowed: shown as "auto" at the minimum
    tooltip: str = ""

    @property
    def slider_max(self) -> int:
        if self.log_scale:
            return int(round(4 * math.log10(self.maximum / self.minimum))) + 1
        return int(round((self.maximum - self.minimum) / self.step))

    def to_slider(self, value: float | None) -> int:
        """Slider position of ``value`` (nearest; clamped to the slider's range)."""
        if value is None:
            return 0
        if self.log_scale:
            if value <= 0:
                return 0
            pos = int(round(4 * math.log10(value / self.minimum))) + 1
        else:
            pos = int(round((value - self.minimum) / self.step))
        return max(0, min(self.slider_max, pos))

    def from_slider(self, pos: int) -> float | int | None:
        """Value at slider position ``pos``."""
        if self.log_scale:
            if pos <= 0:
                return None
            return float(f"{self.minimum * 10 ** ((pos - 1) / 4):.3g}")
        value = self.minimum + pos * self.step
        return int(round(value)) if self.integer else round(value, self.decimals)

    def applies(self, structure: str) -> bool:
        return structure in self.structures


PARAM_SPECS = (
    ParamSpec("inner_radius", "Inner radius", "mm", 0.5, 50.0, 0.1, 3, RING_STRUCTURES,
              tooltip="Radius of the (inner) ring; half side of the inner square ring"),
    ParamSpec("outer_radius", "Outer radius", "mm", 0.5, 60.0, 0.1, 3, DOUBLE_STRUCTURES,
              tooltip="Radius of the outer ring of a double ring"),
    ParamSpec("patch_size", "Patch size", "mm", 0.05, 20.0, 0.05, 3,
              tooltip="Side of a square patch, and width of a ring's track"),
    ParamSpec("angle_step", "Angle step", "°", 0.25, 90.0, 0.25, 3, ANGULAR_STRUCTURES,
              tooltip="Angle between neighbouring patches (paper) or the widest sector "
                      "(conforming)"),
    ParamSpec("subdivisions", "Subdivisions n", "", 1, MAX_UNIFORM_SUBDIVISIONS, 1, 0,
              integer=True,
              tooltip="Segments per primary-triangle edge: n² sub-triangles each (uniform), "
                      "or barycentric levels"),
    ParamSpec("gap_width", "Gap width", "mm", 0.05, 20.0, 0.05, 3, SPLIT_STRUCTURES,
              tooltip="Width of the slots cut through split rings"),
    ParamSpec("gap_angle", "Gap angle", "°", -180.0, 180.0, 1.0, 2, SPLIT_STRUCTURES,
              tooltip="Direction of the slots' centre line, degrees from +x"),
    ParamSpec("tolerance", "Tolerance ε", "mm", 1e-9, 1e-1, 0.0, 9, log_scale=True,
              optional=True,
              tooltip="Welding distance: vertices closer than ε are one vertex (the paper's "
                      "metric constraint). auto = 1e-9 of the structure's size"),
)
SPECS = {s.name: s for s in PARAM_SPECS}
#: Choice parameters: name -> (label, {value: title}).
CHOICES = {
    "structure": ("Structure", STRUCTURE_TITLES),
    "mode": ("Mode", MODE_TITLES),
    "diagonal": ("Diagonal", {"BC": "BC (paper)", "AD": "AD (Makarov)"}),
    "scheme": ("Scheme", {"uniform": "Uniform n × n", "barycentric": "Barycentric levels"}),
}
CHOICE_STRUCTURES = {"diagonal": tuple(s for s in STRUCTURES if s != "triangle")}


def applies(name: str, structure: str) -> bool:
    """Whether parameter ``name`` has an effect on ``structure``."""
    if name in SPECS:
        return SPECS[name].applies(structure)
    return structure in CHOICE_STRUCTURES.get(name, STRUCTURES)


def subdivisions_limit(scheme: str) -> int:
    return MAX_UNIFORM_SUBDIVISIONS if scheme == "uniform" else MAX_BARYCENTRIC_LEVELS


def named_parameter(message: str) -> str | None:
    """The first parameter a core error message names as ``name=value``."""
    for match in re.finditer(r"\b(\w+)=", message):
        if match.group(1) in MeshParams.__dataclass_fields__:
            return match.group(1)
    return None


# -- results -------------------------------------------------------------------------------


@dataclass
class MeshResult:
    """One finished (or failed) mesh build."""

    generation: int
    params: MeshParams | None
    mesh: TriMesh | None = None
    stats: dict[str, Any] = field(default_factory=dict)
    seconds: float = 0.0
    scene: Any = None  # app.scene.SceneData, prepared off the GUI thread
    error: str | None = None
    source: str = "parameters"  # or the path of an imported mesh file
    cancelled: bool = False  # abandoned because a newer request or Cancel came
    timings: dict[str, float] = field(default_factory=dict)  # stage -> seconds


def compute(
    params: MeshParams,
    generation: int = 0,
    prepare: Callable[[TriMesh], Any] | None = None,
    cancel: Callable[[], bool] | None = None,
) -> MeshResult:
    """Build the mesh and its statistics (and ``prepare(mesh)``, e.g. the scene datasets).

    Never raises: a failure comes back as ``MeshResult.error``, a build abandoned because
    ``cancel()`` returned True (checked by the core between its stages and here between
    build, statistics and ``prepare``) as ``MeshResult.cancelled``. ``seconds`` is the
    time of ``build_mesh`` plus the statistics (topology), what a user waits for;
    ``timings`` has each stage.
    """
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
        return MeshResult(generation, params, error="cancelled", cancelled=True,
                          timings=timings)
    except Exception as exc:  # noqa: BLE001 - reported in the window, never a crash
        log.exception("meshing failed for %s", params)
        return MeshResult(generation, params, error=f"meshing failed: {exc}")
    return MeshResult(generation, params, mesh, stats, seconds, scene, timings=timings)


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
    for key in ("patches", "vertices", "triangles", "edges", "interior_edges",
                "boundary_edges", "junction_edges", "euler_characteristic"):
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
    """A parameter combination the core refused: which control to mark, and why."""

    name: str
    message: str


class AppModel:
    """Parameters with undo/redo, the last good mesh, layer visibility and colouring.

    ``params`` is always valid (the last combination the core accepted); ``draft`` holds
    what the controls show, which may be invalid while ``error`` says why.

    Events (callbacks): ``params_changed(params)``, ``draft_changed(draft)``,
    ``error_changed(error or None)``, ``history_changed()``, ``result_changed(result)``,
    ``layer_changed(name, visible)``, ``color_by_changed(key)``,
    ``build_failed(message)``.
    """

    def __init__(self, params: MeshParams | None = None) -> None:
        self.params = params if params is not None else MeshParams()
        self.draft: dict[str, Any] = self.params.to_dict()
        self.error: ParamError | None = None
        self.undo_stack: list[MeshParams] = []
        self.redo_stack: list[MeshParams] = []
        self._merging: str | None = None
        self.result: MeshResult | None = None
        self.generation = 0
        self.layers: dict[str, bool] = dict(DEFAULT_VISIBLE)
        self.color_by = "none"
        self.params_changed = Event()
        self.draft_changed = Event()
        self.error_changed = Event()
        self.history_changed = Event()
        self.result_changed = Event()
        self.layer_changed = Event()
        self.color_by_changed = Event()
        self.build_failed = Event()

    # -- parameters ---------------------------------------------------------------

    def set_value(self, name: str, value: Any, merge: bool = False) -> bool:
        """Change one parameter as a user did; True if the core accepted the combination.

        ``merge=True`` folds consecutive changes of the same parameter into one undo step
        (a slider drag); :meth:`end_merge` ends such a run.
        """
        if name not in MeshParams.__dataclass_fields__:
            raise ValueError(f"name={name!r} is not a parameter")
        self.draft[name] = value
        self.draft_changed.emit(dict(self.draft))
        try:
            params = MeshParams.from_dict(self.draft)
        except (ValueError, TypeError) as exc:
            message = str(exc)
            mark = name if name in SPECS else (named_parameter(message) or name)
            self._set_error(ParamError(mark, message))
            return False
        self._commit(params, merge_name=name if merge else None)
        return True

    def end_merge(self) -> None:
        """The slider was released: the next change starts a new undo step."""
        self._merging = None

    def set_params(self, params: MeshParams) -> None:
        """Replace every parameter (preset, parameter file, reset) as one undo step."""
        if not isinstance(params, MeshParams):
            raise TypeError(f"params must be a MeshParams, got {type(params).__name__}")
        self._commit(params, merge_name=None, force=True)

    def reset(self) -> None:
        """Back to the defaults (the paper's Fig. 12(a)); undoable."""
        self.set_params(MeshParams())

    def _commit(self, params: MeshParams, merge_name: str | None, force: bool = False) -> None:
        changed = params != self.params
        if changed:
            if not (merge_name is not None and merge_name == self._merging):
                self.undo_stack.append(self.params)
                self.redo_stack.clear()
            self._merging = merge_name
        self._apply(params, changed or force)

    def _apply(self, params: MeshParams, changed: bool) -> None:
        self.params = params
        self.draft = params.to_dict()
        self._set_error(None)
        self.draft_changed.emit(dict(self.draft))
        if changed:
            self.generation += 1
            self.params_changed.emit(params)
        self.history_changed.emit()

    def _set_error(self, error: ParamError | None) -> None:
        if error != self.error:
            self.error = error
            self.error_changed.emit(error)

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
        self.redo_stack.append(self.params)
        self._merging = None
        self._apply(self.undo_stack.pop(), True)

    def redo(self) -> None:
        if not self.redo_stack:
            return
        self.undo_stack.append(self.params)
        self._merging = None
        self._apply(self.redo_stack.pop(), True)

    # -- results ------------------------------------------------------------------

    def set_result(self, result: MeshResult) -> bool:
        """Accept a finished build; stale (older generation) and failed ones are not shown.

        Returns whether the result became the current mesh.
        """
        if result.generation != self.generation:
            log.debug("dropped stale mesh of generation %d", result.generation)
            return False
        if result.error is not None or result.mesh is None:
            self.build_failed.emit(result.error or "meshing failed")
            return False
        self.result = result
        self.result_changed.emit(result)
        return True

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
