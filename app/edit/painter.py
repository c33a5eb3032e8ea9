"""Cell → Paint pixels: paint a coding cell's pixel grid with the mouse, in top view.

A top-level window with its own ``QtInteractor`` looking straight down the z axis
(parallel projection). It shows the mesh that :func:`barymesh.cell.build_cell` makes of the
cell (each set pixel a square patch of 32 triangles, edge-sharing pixels welded), the
pixel grid, the cell outline and, as red dots, the corners where two pixels touch at a
point only (reported by :meth:`barymesh.cell.PixelGrid.corner_contacts`).

Mouse: the left button paints (erases with Erase on), the right button erases; a press,
the drag and the release are one stroke and one undo step. The middle button pans, the
wheel zooms; nothing rotates. A mouse position is turned into a pixel by casting its
ray through the camera onto the plane z = 0 (exact for the parallel projection).

The document (the grid and lattice under undo, the symmetry, the edits) is
:class:`barymesh.app.model.painter_document.PainterDocument` (no Qt); this window draws it,
turns the mouse and its fields into its edits, and rebuilds the mesh in a worker thread
after every stroke, so the window keeps answering on large grids (a 64 x 64 grid is
131,072 triangles). While the build runs, pixels painted or erased since the mesh on
screen are drawn as flat squares over it.

Its parts, one module each: what the worker builds, numpy arrays only
(:mod:`barymesh.app.edit.painter_preview`); the view and its actors, on the GUI thread
(:mod:`barymesh.app.edit.painter_scene`); the Paint and Grid toolbars
(:mod:`barymesh.app.edit.painter_toolbars`); and Cell → Paint pixels… in the main window
(:mod:`barymesh.app.edit.painter_opener`).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Any, cast

import numpy as np
from PySide6.QtCore import QEvent, QObject, QPointF, Qt, QTimer, Signal
from PySide6.QtGui import QCloseEvent, QMouseEvent
from PySide6.QtWidgets import (
    QFileDialog,
    QLabel,
    QMainWindow,
    QVBoxLayout,
    QWidget,
)

from barymesh.app.edit.painter_preview import Built, build_preview
from barymesh.app.edit.painter_scene import COLORS, PainterScene
from barymesh.app.edit.painter_toolbars import PainterToolbars
from barymesh.app.jobs import Jobs
from barymesh.app.model import pixels
from barymesh.app.model.painter_document import (
    NOT_SQUARE,
    SUFFIX,
    NothingToSave,
    PainterDocument,
    PainterState,
    reframes,
)
from barymesh.cell import (
    CellMesh,
    Lattice,
    PixelGrid,
    UnitCell,
)


class PixelPainterWindow(QMainWindow):
    """The pixel painter (see the module docstring).

    Parameters
    ----------
    cell : UnitCell, optional
        The cell to edit; its elements stay as they are (drawn and meshed with the
        pixels). A cell without a grid gets an empty one over the cell
        (:func:`barymesh.app.model.painter_document.blank_grid`).
        Default: the 16 x 16 coding cell preset.
    parent : QWidget, optional
    """

    #: A mesh was drawn for the latest edit.
    built = Signal()
    #: Shown while a 4- or 8-fold symmetry waits for the grid to be square again.
    NOT_SQUARE = NOT_SQUARE

    @property
    def closed(self) -> bool:
        """Whether the painter was closed (its view released)."""
        return self._closed

    def __init__(self, cell: UnitCell | None = None, parent: QWidget | None = None) -> None:
        super().__init__(parent, Qt.WindowType.Window)
        self.setObjectName("pixel_painter")
        self._closed = False
        self.generation = 0
        self.shown_generation = -1
        self.cell_mesh: CellMesh | None = None
        self.last_built: Built | None = None
        self._stroke: dict[str, Any] | None = None

        #: The edited cell, its undo history and symmetry (no Qt: app/model).
        self.document = PainterDocument(cell)
        #: The view and its actors (VTK, on the GUI thread).
        self.scene = PainterScene(self, self.document)
        self.plotter = self.scene.plotter
        self.plotter.installEventFilter(self)
        self.plotter.setMouseTracking(True)
        #: The Paint and Grid toolbars: the actions and the fields.
        self.toolbars = PainterToolbars(self, self)
        self.toolbars.symmetry_box.currentIndexChanged.connect(self._symmetry_chosen)
        for box in (self.toolbars.rows_box, self.toolbars.cols_box):
            box.editingFinished.connect(self._shape_edited)
        self.toolbars.size_box.editingFinished.connect(self._pixel_size_edited)
        # the statistics on a line of their own under the view: in the status bar beside
        # the messages, a long message ran into them (and was cut off under them)
        self.stats_label = QLabel(self)
        self.stats_label.setObjectName("painter_stats")
        self.stats_label.setTextFormat(Qt.TextFormat.RichText)
        self.stats_label.setContentsMargins(6, 3, 6, 3)
        central = QWidget(self)
        column = QVBoxLayout(central)
        column.setContentsMargins(0, 0, 0, 0)
        column.setSpacing(0)
        column.addWidget(self.plotter, 1)
        column.addWidget(self.stats_label)
        self.setCentralWidget(central)

        self.jobs = Jobs(self, name="barymesh-painter")  # one build at a time
        self._running = False
        self._pending: tuple[UnitCell | None, np.ndarray, float, int] | None = None
        self._show_document(reframe=True)
        self.resize(1100, 860)

    # -- the document (barymesh.app.model.painter_document) ------------------------------------

    @property
    def state(self) -> PainterState:
        return self.document.state

    @property
    def history(self) -> list[PainterState]:
        """Every state of the undo history, the current one at :attr:`position`."""
        return self.document.history.states

    @property
    def position(self) -> int:
        return self.document.history.position

    @property
    def grid(self) -> PixelGrid:
        """The pixel grid being painted."""
        return self.document.grid

    @property
    def mask(self) -> np.ndarray:  # type: ignore[override]  # shadows QWidget.mask()
        """(R, C) bool: the grid's mask (row 0 at the bottom)."""
        return self.document.mask

    @property
    def symmetry(self) -> str:
        return self.document.symmetry

    @property
    def path(self) -> Path | None:
        return self.document.path

    def cell(self) -> UnitCell | None:
        """The edited cell (None when it would have no metal: no element, no pixel)."""
        return self.document.cell()

    def open_cell(self, cell: UnitCell) -> None:
        """Edit ``cell`` (a new history)."""
        self.document.open(cell)
        self._show_document(reframe=True)

    def _show_document(self, reframe: bool) -> None:
        self.setWindowTitle(f"barymesh – paint pixels – {self.document.name}")
        self._set_symmetry_box(self.document.symmetry)
        self._state_changed(reframe=reframe)

    def push(self, grid: PixelGrid, lattice: Lattice | None = None) -> bool:
        """Make (grid, lattice) the current state, one undo step (False when unchanged)."""
        old = self.grid
        if not self.document.push(grid, lattice):
            return False
        self._state_changed(reframe=reframes(old, self.grid))
        return True

    def undo(self) -> None:
        old = self.grid
        if self.document.undo():
            self._state_changed(reframe=reframes(old, self.grid))

    def redo(self) -> None:
        old = self.grid
        if self.document.redo():
            self._state_changed(reframe=reframes(old, self.grid))

    def _state_changed(self, reframe: bool = False) -> None:
        grid = self.grid
        for box, value in (
            (self.toolbars.rows_box, grid.shape[0]),
            (self.toolbars.cols_box, grid.shape[1]),
        ):
            box.blockSignals(True)
            box.setValue(value)
            box.blockSignals(False)
        self.toolbars.size_box.blockSignals(True)
        self.toolbars.size_box.setValue(grid.pixel_size)
        self.toolbars.size_box.blockSignals(False)
        note = self.document.follow_shape()
        self._set_symmetry_box(self.document.symmetry)
        if note is not None:
            self.statusBar().showMessage(note, 8000 if note == NOT_SQUARE else 5000)
        elif grid.shape[0] == grid.shape[1] and self.statusBar().currentMessage() == NOT_SQUARE:
            self.statusBar().clearMessage()  # it no longer holds
        self.toolbars.act_undo.setEnabled(self.document.history.can_undo)
        self.toolbars.act_redo.setEnabled(self.document.history.can_redo)
        self.scene.draw_grid()
        if reframe:
            self.reset_view()
        self._draw_pending()
        self._refresh_hover()
        self.request_build()

    # -- edits (each one undo step) ----------------------------------------------------------

    def _edit(self, edit: Callable[[], bool]) -> bool:
        old = self.grid
        try:
            changed = edit()
        except ValueError as exc:
            self.statusBar().showMessage(str(exc), 8000)
            return False
        if changed:
            self._state_changed(reframe=reframes(old, self.grid))
        return changed

    def invert(self) -> bool:
        """The Babinet complement of the grid."""
        return self._edit(self.document.invert)

    def clear(self) -> bool:
        return self._edit(self.document.clear)

    def random_fill(self) -> bool:
        """A random mask under the symmetry mode, from the seed and metal % fields."""
        seed, density = self.toolbars.seed_box.value(), self.toolbars.density_box.value() / 100.0
        return self._edit(lambda: self.document.random_fill(seed, density))

    def fill_at(self, row: int, col: int, value: bool) -> bool:
        """Flood fill the 4-connected region of (row, col) (and its images) with ``value``."""
        return self._edit(lambda: self.document.fill_at(row, col, value))

    def set_grid_size(self, rows: int, cols: int, pixel_size: float) -> bool:
        """Resize the grid (centred) and/or change the pixel size; the grid keeps its centre,
        and a lattice that was the grid's extent follows it."""
        old = self.grid
        try:
            changed = self.document.set_grid_size(rows, cols, pixel_size)
        except ValueError as exc:
            self.statusBar().showMessage(str(exc), 8000)
            self._state_changed()
            return False
        if changed:
            self._state_changed(reframe=reframes(old, self.grid))
        return changed

    def _shape_edited(self) -> None:
        rows, cols = self.toolbars.rows_box.value(), self.toolbars.cols_box.value()
        if (rows, cols) != self.grid.shape:
            self.set_grid_size(rows, cols, self.grid.pixel_size)

    def _pixel_size_edited(self) -> None:
        # the field shows 4 decimals: a pixel size from a file is only changed when typed
        size, grid = self.toolbars.size_box.value(), self.grid
        if abs(size - round(grid.pixel_size, self.toolbars.size_box.decimals())) > 1e-12:
            self.set_grid_size(*grid.shape, size)

    def _symmetry_chosen(self) -> None:
        try:
            note = self.document.choose_symmetry(str(self.toolbars.symmetry_box.currentData()))
        except ValueError as exc:
            self._set_symmetry_box(self.document.symmetry)
            self.statusBar().showMessage(str(exc), 8000)
            return
        self._refresh_hover()
        self.statusBar().showMessage(note, 4000 if note.startswith("Symmetry:") else 8000)

    def _set_symmetry_box(self, mode: str) -> None:
        self.toolbars.symmetry_box.blockSignals(True)
        self.toolbars.symmetry_box.setCurrentIndex(self.toolbars.symmetry_box.findData(mode))
        self.toolbars.symmetry_box.blockSignals(False)

    # -- files -------------------------------------------------------------------------------

    def save_dialog(self) -> None:
        """Save cell…: a ``*.cell.json`` file."""
        start = str(self.path or Path.cwd() / f"{self.document.name}{SUFFIX}")
        path, _ = QFileDialog.getSaveFileName(self, "Save cell", start, f"Cell files (*{SUFFIX})")
        if path:
            self.save(path)

    def save(self, path: str | Path) -> bool:
        try:
            written = self.document.save(path)
        except NothingToSave as exc:
            self.statusBar().showMessage(str(exc), 8000)
            return False
        except (OSError, ValueError) as exc:
            self.statusBar().showMessage(f"Could not save {path}: {exc}", 10000)
            return False
        self.statusBar().showMessage(f"Saved {written}", 6000)
        return True

    def open_dialog(self) -> None:
        """Open cell…: edit a ``*.cell.json`` file."""
        path, _ = QFileDialog.getOpenFileName(
            self,
            "Open cell",
            str(self.path or Path.cwd()),
            f"Cell files (*{SUFFIX});;JSON (*.json)",
        )
        if not path:
            return
        try:
            self.document.open_file(path)
        except (OSError, ValueError) as exc:
            self.statusBar().showMessage(str(exc), 10000)
            return
        self._show_document(reframe=True)

    # -- mouse -------------------------------------------------------------------------------

    def pixel_at(self, pos: QPointF) -> tuple[int, int] | None:
        """The pixel under the widget position ``pos`` (None off the grid): the ray of the
        view through ``pos`` meets z = 0."""
        point = self.scene.ground_point(pos)
        if point is None:
            return None
        g = self.grid
        return pixels.pixel_at(g.shape, g.origin, g.pixel_size, point)

    def pixel_centre(self, row: int, col: int) -> tuple[float, float, float]:
        """World point (mm) of the centre of pixel (row, col)."""
        g = self.grid
        return (
            g.origin[0] + (col + 0.5) * g.pixel_size,
            g.origin[1] + (row + 0.5) * g.pixel_size,
            0.0,
        )

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:  # noqa: N802 - Qt's name
        if watched is not self.plotter or self._closed:
            return False
        kind = event.type()
        mouse = cast(QMouseEvent, event)  # read in the mouse events' branches only
        if kind in (QEvent.Type.MouseButtonPress, QEvent.Type.MouseButtonDblClick):
            if mouse.button() in (Qt.MouseButton.LeftButton, Qt.MouseButton.RightButton):
                self._press(mouse.position(), mouse.button() == Qt.MouseButton.RightButton)
                return True
        elif kind == QEvent.Type.MouseMove:
            if self._stroke is not None:
                self._move(mouse.position())
                return True
            self._hover(self.pixel_at(mouse.position()))
        elif kind == QEvent.Type.Leave:
            self._hover(None)
        elif kind == QEvent.Type.MouseButtonRelease:
            if mouse.button() in (Qt.MouseButton.LeftButton, Qt.MouseButton.RightButton):
                self._release()
                return True
        elif kind == QEvent.Type.KeyPress:
            return True  # VTK's own keys (w, s, 3, q, e, …) would change the view
        return False

    def _press(self, pos: QPointF, right: bool) -> None:
        if self._stroke is not None:
            self._release()
        value = not (right or self.toolbars.act_erase.isChecked())
        pixel = self.pixel_at(pos)
        if self.toolbars.act_fill.isChecked():
            if pixel is not None:
                self.fill_at(*pixel, value)
            return
        try:
            pixels.check_symmetry(self.symmetry, self.mask.shape)
        except ValueError as exc:
            self.statusBar().showMessage(str(exc), 8000)
            return
        self._stroke = {"start": self.mask, "value": value, "pixels": [], "last": None}
        if pixel is not None:
            self._add_to_stroke(pixel)

    def _move(self, pos: QPointF) -> None:
        pixel = self.pixel_at(pos)
        if pixel is not None and self._stroke is not None and pixel != self._stroke["last"]:
            self._add_to_stroke(pixel)

    def _hover(self, pixel: tuple[int, int] | None) -> None:
        """Outline the pixel under the mouse and its images under the symmetry mode."""
        if pixel == self._hovered:
            return
        self._hovered = pixel
        cells = np.empty((0, 2), dtype=np.int64)
        if pixel is not None:
            cells = self.document.orbit(pixel)
        self.scene.draw_hover(cells)

    _hovered: tuple[int, int] | None = None

    def _refresh_hover(self) -> None:
        pixel, self._hovered = self._hovered, (-1, -1)
        shape = self.mask.shape
        if pixel is not None and not (0 <= pixel[0] < shape[0] and 0 <= pixel[1] < shape[1]):
            pixel = None
        self._hover(pixel)

    def _add_to_stroke(self, pixel: tuple[int, int]) -> None:
        stroke = self._stroke
        assert stroke is not None  # a stroke under way
        last = stroke["last"]
        new = pixels.pixel_line(last, pixel) if last is not None else np.array([pixel])
        stroke["pixels"].extend(map(tuple, new.tolist()))
        stroke["last"] = pixel
        stroke["mask"] = self.document.painted(stroke["start"], stroke["pixels"], stroke["value"])
        self._draw_pending(stroke["mask"])

    def _release(self) -> None:
        stroke, self._stroke = self._stroke, None
        if stroke is None or "mask" not in stroke:
            return
        if not self.push(self.grid.replaced(mask=stroke["mask"])):
            self._draw_pending()

    # -- meshing -----------------------------------------------------------------------------

    def request_build(self) -> None:
        """Mesh the current cell in the worker (the latest request wins)."""
        self.generation += 1
        try:
            cell = self.cell()
        except ValueError as exc:
            self.statusBar().showMessage(str(exc), 8000)
            return
        self._pending = (cell, self.mask, self.scene.dz, self.generation)
        self._start()

    def _start(self) -> None:
        if self._running or self._pending is None or self._closed:
            return
        cell, mask, dz, generation = self._pending
        self._pending = None
        self._running = True
        self.jobs.submit(partial(build_preview, cell, mask, dz, generation), self._finished)

    def _finished(self, built: Built) -> None:
        self._running = False
        if self._closed:
            return
        if self._pending is not None:
            self._start()  # a newer edit is waiting: this result is stale
            return
        self.show_built(built)
        self.shown_generation = built.generation
        self.built.emit()

    @property
    def busy(self) -> bool:
        return self._running or self._pending is not None

    def wait_built(self, timeout_ms: int = 30_000) -> None:
        """Block until the mesh of the latest edit is on screen (for scripts and tests)."""
        from PySide6.QtWidgets import QApplication

        end = time.monotonic() + timeout_ms / 1000
        while (self.busy or self.shown_generation != self.generation) and time.monotonic() < end:
            QApplication.processEvents()
            time.sleep(0.005)

    # -- drawing (barymesh.app.edit.painter_scene) ---------------------------------------------

    def _draw_pending(self, mask: np.ndarray | None = None) -> None:
        """Pixels that differ from the mesh on screen, as flat squares over it; and the
        corner contacts of ``mask`` (default: the current one)."""
        mask = self.mask if mask is None else mask
        self.scene.draw_pending(mask)
        self._show_stats(mask)

    def show_built(self, built: Built) -> None:
        """Draw the mesh ``built`` (the faces and every triangle edge)."""
        self.last_built = built
        if built.error is not None:  # keep the last good mesh
            self.statusBar().showMessage(f"Cannot mesh this cell: {built.error}", 10000)
            return
        self.cell_mesh = built.cell_mesh
        self.scene.show_mesh(built)
        self._draw_pending()

    def _show_stats(self, mask: np.ndarray) -> None:
        g = self.grid
        set_pixels = int(mask.sum())
        lattice = self.state.lattice
        if lattice.kind == "rectangular":
            cell = f"Cell {lattice.a1[0]:.6g} × {lattice.a2[1]:.6g} mm"
        else:
            cell = f"Cell {lattice.kind}, {lattice.area:.6g} mm²"
        parts = [cell, f"Pixels <b>{set_pixels:,}</b> of {mask.size:,}"]
        built = self.last_built
        current = (
            built is not None
            and built.stats is not None
            and np.array_equal(built.mask, mask)
            and built.error is None
        )
        if current:
            assert built is not None and built.stats is not None  # current
            s = built.stats
            parts += [
                f"Triangles <b>{s['triangles']:,}</b>",
                f"Vertices {s['vertices']:,}",
                f"RWG unknowns {s['interior_edges']:,}",
            ]
        elif set_pixels == 0 and not self.document.has_elements:
            parts.append("no metal")
        else:
            parts.append("meshing…")
        contacts = len(g.replaced(mask=mask).corner_contacts())
        if contacts:
            parts.append(
                f"<span style='color:{COLORS['contacts']}'>● <b>{contacts}</b> "
                "corner-only contact(s)</span>"
            )
        self.stats_label.setText(" &nbsp;·&nbsp; ".join(parts))
        self.stats_label.setToolTip(
            "Red dots: pixels that touch at a corner only, a junction risk for solvers"
            if contacts
            else ""
        )

    def reset_view(self) -> None:
        """Frame the cell and the grid from above (R)."""
        self.scene.reset_view()

    def view_image(self) -> np.ndarray:
        """The 3D view as an (h, w, 3) uint8 array."""
        return self.scene.image()

    # -- closing -----------------------------------------------------------------------------

    def showEvent(self, event: Any) -> None:  # noqa: N802 - Qt's name
        super().showEvent(event)
        QTimer.singleShot(0, self._first_frame)

    def _first_frame(self) -> None:
        if not self._closed and not self._framed:
            self._framed = True
            self.reset_view()

    _framed = False

    def closeEvent(self, event: QCloseEvent) -> None:  # noqa: N802 - Qt's name
        self.shutdown()
        super().closeEvent(event)

    def shutdown(self) -> None:
        """Stop the worker and release the GL context (idempotent)."""
        if self._closed:
            return
        self._closed = True
        self._pending = None
        self.jobs.close()  # a running build winds down in its thread; its result goes nowhere
        self.scene.close()  # its timers stopped, its GL context released
