"""The window's unit-cell tools: cell files and presets, the Elements dock (elements,
lattice, array preview) and the export of an array, wired to the model.

:class:`CellTools` gets the window's :class:`barymesh.app.tool_host.ToolHost` and what it
uses of the window and of the View tools; the window adds :meth:`CellTools.add_to_menus`
to its File and Cell menus.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from pathlib import Path
from typing import Any

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction
from PySide6.QtWidgets import QDockWidget, QFileDialog, QMenu, QVBoxLayout, QWidget

from barymesh import TriMesh
from barymesh.app.edit.array_preview import ArrayPreview
from barymesh.app.edit.drag_tool import ElementDragger
from barymesh.app.edit.elements_panel import ElementsPanel
from barymesh.app.edit.lattice_panel import LatticePanel
from barymesh.app.model import AppModel, ClickTools, MeshResult
from barymesh.app.model.cell_document import CellState
from barymesh.app.tool_host import ToolHost
from barymesh.app.view.framing import FramedCamera, frame_from_above
from barymesh.cell import Element, Lattice, UnitCell

log = logging.getLogger(__name__)
CELL_FILTER = "Unit cells (*.cell.json);;All files (*)"


class CellTools:
    """Cell files, presets, the Elements dock and the array preview of one window.

    Parameters
    ----------
    host : ToolHost
        The window: actions, the Elements dock, status, settings, file errors, renders.
    model : AppModel
    plotter : pyvistaqt.QtInteractor
        The 3D view (the array preview draws in it).
    scene : barymesh.app.view.scene.MeshScene
        Its rulers and markers follow the preview's extent.
    framing : FramedCamera
        The window's framed camera: a framed cell is framed again with its copies.
    clicks : ClickTools
        The view's click tools: the drag tool is one of them.
    controls, parameters_dock : QWidget, QDockWidget
        The Parameters panel, disabled when no element is selected, and its dock, whose
        title names the element it edits.
    run_export : callable
        ``run_export(path, unit, make, what, done, wrote=...) -> bool`` of the window:
        ``make()`` in a worker thread, then the file written there, with progress.
    world_at, picker
        The View tools' ``world_at(pos)`` and the Teach tools' picker, for the drag tool.
    """

    def __init__(
        self,
        host: ToolHost,
        model: AppModel,
        plotter: Any,
        scene: Any,
        framing: FramedCamera,
        clicks: ClickTools,
        *,
        controls: QWidget,
        parameters_dock: QDockWidget,
        run_export: Callable[..., bool],
        world_at: Callable[[Any], tuple[Any, Any]],
        picker: Any,
    ) -> None:
        self.host = host
        self.model = model
        self.plotter, self.scene, self.framing = plotter, scene, framing
        self.controls, self.parameters_dock = controls, parameters_dock
        self.run_export = run_export
        box = QWidget(host.widget)
        col = QVBoxLayout(box)
        col.setContentsMargins(0, 0, 0, 0)
        self.elements = ElementsPanel(self.model, box)
        self.lattice = LatticePanel(self.model, box)
        col.addWidget(self.elements, 1)
        col.addWidget(self.lattice)
        self.dock = host.add_dock(
            "Elements", box, Qt.DockWidgetArea.LeftDockWidgetArea, scroll=True
        )
        if self.model.cell_state is None:  # shown when a cell is opened (or from the menu)
            self.dock.hide()
        self.preview = ArrayPreview(plotter)
        a = host.add_action
        self.act_open = a(
            "Open c&ell…",
            self.open_cell_dialog,
            "Ctrl+Shift+O",
            "Open a unit cell (*.cell.json): its elements, lattice and pixels",
        )
        self.act_save = a(
            "Sa&ve cell…",
            self.save_cell_dialog,
            "Ctrl+Shift+S",
            "Save the unit cell (hidden elements included) as *.cell.json",
        )
        self.act_new = a(
            "&New cell from this structure",
            self.new_cell_from_structure,
            tip="A unit cell holding the structure of the Parameters panel, on a "
            "square lattice a little larger than it",
        )
        self.act_export_array = a(
            "Export &array mesh…",
            self.export_array_dialog,
            tip="Weld n1 x n2 copies of the cell (the preview's) into one mesh and write it",
        )
        self.dragger = ElementDragger(
            host, model, plotter, clicks, world_at, picker, lambda: self.elements.snap_grid
        )
        self.preset_actions: dict[str, QAction] = {}
        self.model.cell_changed.connect(self._cell_changed)
        self.model.result_changed.connect(self._result_changed)
        self.lattice.copies_changed.connect(self._copies_changed)
        self._cell_changed(self.model.cell_state)

    def add_to_menus(self, file: QMenu, cell: QMenu, after: QAction | None = None) -> None:
        """Open / Save cell into File (after ``after``, Save parameters), the rest into
        Cell."""
        anchor = next((act for act in file.actions() if act is after), None)
        after = file.actions()[file.actions().index(anchor) + 1] if anchor else None
        # None inserts at the end (Qt's nullptr), which PySide6's stub leaves out
        file.insertActions(after, [self.act_open, self.act_save])  # type: ignore[arg-type]
        presets = cell.addMenu("Cell &presets")
        try:
            from barymesh.cell import cell_preset_names

            names = cell_preset_names()
        except Exception as exc:  # noqa: BLE001 - a broken preset folder must not stop the window
            log.warning("cell presets unavailable: %s", exc)
            names = []
        for name in names:
            act = presets.addAction(name)
            act.triggered.connect(lambda _=False, n=name: self.load_cell_preset(n))
            self.preset_actions[name] = act
        if not names:
            presets.addAction("(no cell presets found)").setEnabled(False)
        cell.addActions([self.act_new, self.act_open, self.act_save])
        cell.addSeparator()
        cell.addActions(
            [
                self.elements.act_duplicate,
                self.elements.act_delete,
                self.elements.act_up,
                self.elements.act_down,
            ]
        )
        cell.addAction(self.dragger.act)
        cell.addAction(self.act_export_array)
        cell.addSeparator()
        cell.addAction(self.dock.toggleViewAction())

    # -- files and presets ---------------------------------------------------------------

    def open_cell_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(
            self.host.widget, "Open cell", str(self.host.setting("paths/cell", "")), CELL_FILTER
        )
        if path:
            self.host.set_setting("paths/cell", path)
            self.open_cell_file(path)

    def open_cell_file(self, path: str | Path) -> bool:
        """Open a cell file; an invalid one is one sentence naming the file and the place
        in it (``elements[1].inner_radius``), and the window keeps what it shows."""
        from barymesh.cell import load_cell

        try:
            cell = load_cell(path)
        except (ValueError, OSError) as exc:
            self.host.file_error(f"Could not open {Path(path).name}", exc, path)
            return False
        self.open_cell(cell, f"Opened {Path(path).name}")
        return True

    def load_cell_preset(self, name: str) -> bool:
        from barymesh.cell import load_cell_preset

        try:
            cell = load_cell_preset(name)
        except (ValueError, OSError) as exc:
            self.host.file_error(f"Could not load cell preset {name}", exc)
            return False
        self.open_cell(cell, f"Cell preset {name}: {cell.description}")
        return True

    def open_cell(self, cell: UnitCell, message: str) -> None:
        self.model.set_cell(cell)
        self.dock.show()
        self.dock.raise_()
        self.host.show_status(message, 8000)

    def save_cell_dialog(self) -> None:
        if self.model.cell is None:
            self.host.show_status("No unit cell is open: nothing to save")
            return
        start = str(self.host.setting("paths/cell", f"{self.model.cell.name}.cell.json"))
        path, _ = QFileDialog.getSaveFileName(self.host.widget, "Save cell", start, CELL_FILTER)
        if path:
            if not path.lower().endswith(".json"):
                path += ".cell.json"
            self.host.set_setting("paths/cell", path)
            self.save_cell_file(path)

    def save_cell_file(self, path: str | Path) -> bool:
        from barymesh.cell import save_cell

        cell = self.model.cell
        if cell is None:
            self.host.show_status("No unit cell is open: nothing to save")
            return False
        try:
            save_cell(cell, path)
        except (ValueError, OSError) as exc:
            self.host.file_error(f"Could not save {Path(path).name}", exc, path)
            return False
        self.host.show_status(f"Saved {path}", 5000)
        return True

    def new_cell_from_structure(self) -> None:
        """The Parameters panel's structure as the one element of a new cell, centred on
        a square lattice 1.25 times its larger side."""
        result = self.model.result
        params = self.model.params
        mesh = result.mesh if result is not None and result.params == params else None
        if mesh is None or not mesh.n_vertices:
            from barymesh import build_mesh

            try:
                mesh = build_mesh(params)
            except (ValueError, TypeError) as exc:
                self.model.set_cell_error(f"could not mesh the structure: {exc}")
                return
        lo, hi = mesh.points[:, :2].min(axis=0), mesh.points[:, :2].max(axis=0)
        centre, size = (lo + hi) / 2, float((hi - lo).max())
        element = Element(
            params, position=(-float(centre[0]), -float(centre[1])), name=params.structure
        )
        cell = UnitCell(
            Lattice.rectangular(round(1.25 * size, 6)),
            (element,),
            mode=params.mode,
            name=params.structure,
        )
        self.open_cell(cell, f"New cell of the {params.structure}")

    # -- the array -------------------------------------------------------------------------

    def export_array_dialog(self) -> None:
        state = self.model.cell_state
        if state is None:
            self.host.show_status("No unit cell is open: no array to export")
            return
        n1, n2 = self.lattice.copies
        start = str(self.host.setting("paths/array", f"{state.cell.name}-{n1}x{n2}.msh"))
        from barymesh.io import export_filters, filter_extension

        # only what write_mesh writes (it offered .nas and .ply, then "cannot write .nas")
        path, chosen = QFileDialog.getSaveFileName(
            self.host.widget, f"Export {n1} x {n2} array mesh", start, ";;".join(export_filters())
        )
        if path:
            if not Path(path).suffix:
                path += filter_extension(chosen) or ".msh"
            self.host.set_setting("paths/array", path)
            self.export_array(path)

    def export_array(
        self,
        path: str | Path,
        unit: str | None = None,
        done: Callable[[bool], None] | None = None,
    ) -> bool:
        """Weld the preview's n1 x n2 copies of the cell (:func:`barymesh.cell.tile`) and write
        them (the format from the extension), both in a worker thread with progress and
        Cancel (the window's ``run_export``). Returns whether the export started."""
        from barymesh.cell import tile

        state = self.model.cell_state
        if state is None:
            self.host.show_status("No unit cell is open: no array to export")
            return False
        n1, n2 = self.lattice.copies
        result = self.model.result
        base = (
            result.cell_mesh
            if result is not None and result.cell == state.visible
            else state.visible
        )

        made = {}

        def make() -> TriMesh:  # worker thread: numpy only
            made["array"] = tile(base, n1, n2)
            return made["array"].mesh

        def wrote(mesh: TriMesh, described: str) -> str:  # GUI thread, once written
            self.last_array = made["array"]
            return f"Wrote the {n1} x {n2} array ({mesh.n_triangles:,} triangles): {described}"

        return self.run_export(path, unit, make, f"the {n1} x {n2} array", done, wrote=wrote)

    # -- model -> window ---------------------------------------------------------------------

    def _cell_changed(self, state: CellState | None) -> None:
        editable = state is None or state.selected is not None
        self.controls.setEnabled(editable)
        if state is None:
            self.parameters_dock.setWindowTitle("Parameters")
            if self.preview.clear():
                self.host.request_render()
        elif state.selected is not None:
            name = state.elements[state.selected].name
            self.parameters_dock.setWindowTitle(f"Parameters – element {name}")
        else:
            self.parameters_dock.setWindowTitle("Parameters – no element selected")
        for act in (self.act_save, self.act_export_array, self.dragger.act):
            act.setEnabled(state is not None)

    def _result_changed(self, result: MeshResult) -> None:
        self._draw_preview(result, reframe=False)

    def _copies_changed(self, _n1: int, _n2: int) -> None:
        self._draw_preview(self.model.result, reframe=True)

    def _draw_preview(self, result: MeshResult | None, reframe: bool) -> None:
        if self.host.closed:
            return
        cell = result.cell if result is not None else None
        if cell is None:  # a structure: no outline (and no extra paint of the view)
            if self.preview.clear():
                self.host.request_render()
            return
        assert result is not None  # it holds the cell
        # a freshly framed mesh (not a camera the user moved) is framed with its copies
        was_framed = self.framing.holds(exact=True)
        self.preview.show(result.mesh, cell.lattice, *self.lattice.copies)
        if self.preview.bounds is not None:  # rulers (and R) span the cell and its copies
            self.scene.show_rulers(self.preview.bounds)
        if (reframe or was_framed) and self.preview.bounds is not None:
            frame_from_above(self.plotter, self.preview.bounds)
            self.scene.fit_marker_sizes()
            self.framing.remember()
        self.host.request_render()
