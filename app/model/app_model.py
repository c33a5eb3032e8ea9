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
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from barymesh import MeshParams, TriMesh
from barymesh.app.model.build import MeshResult
from barymesh.app.model.cell_document import CellState, CellTarget
from barymesh.app.model.events import Event
from barymesh.app.model.layers import COLOR_BY, DEFAULT_VISIBLE, DETAIL_MODES
from barymesh.app.model.specs import (
    POINT_PARAMS,
    SPECS,
    carried_subdivisions,
    carry_note,
    named_parameter,
)
from barymesh.app.model.typed_text import Reading, read_number, read_points
from barymesh.cell import UnitCell

log = logging.getLogger(__name__)
_COLOR_KEYS = tuple(COLOR_BY)


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

    Events (callbacks): ``params_changed(params)``, ``params_replaced(params)`` (a whole
    new set: :meth:`set_params`, after ``params_changed``), ``draft_changed(draft)``,
    ``error_changed(error or None)``, ``history_changed()``, ``result_changed(result)``,
    ``layer_changed(name, visible)``, ``color_by_changed(key)``,
    ``detail_changed(mode)``, ``build_failed(message)``.

    A unit cell (``cell_state``, see :mod:`barymesh.app.model.cell_document`) replaces the one
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
        self.params_replaced = Event()
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
        it, ``params`` stay, and ``value`` is kept in ``refused`` with the core's
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
                carried = carry_note(n, m, draft["scheme"], value)
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
        self.params_replaced.emit(self.params)

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
                self.set_cell_error(None)
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
        the cell stays as it is and the message is the ``cell_error``. Returns whether
        the edit was taken.
        """
        if self.cell_state is None:
            self.set_cell_error("no unit cell is open")
            return False
        try:
            state = edit(self.cell_state)
        except _REFUSALS as exc:
            self.set_cell_error(str(exc))
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

    def set_cell_error(self, message: str | None) -> None:
        """Say why the cell (or a cell made of the structure) could not be made; ``None``
        clears it. Announced as ``cell_error_changed`` when it changes."""
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
        self.set_cell_error(message)

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
        """Level of detail: "auto" or "full" (:data:`barymesh.app.model.layers.DETAIL_MODES`)."""
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
