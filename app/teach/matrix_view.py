"""The connectivity matrix of the paper's Eq. 27: a spy plot and, for small meshes, the table.

Entry (i, j) is 1 when triangles i and j share an edge. The spy plot draws any size: the
matrix itself up to :data:`DENSE_LIMIT` triangles, above that an occupancy image of at
most :data:`IMAGE_BINS` pixels a side (a pixel is dark when any entry in its block is
nonzero), so a 23,040 × 23,040 matrix costs one ``bincount``. Meshes up to
:data:`TABLE_LIMIT` triangles also get the 0/1 table. Hovering or clicking a cell emits
``cell_hovered`` / ``cell_clicked`` (row, column); :meth:`MatrixView.highlight_row` marks
a triangle's row. A hidden view only remembers that it is stale and redraws when shown.

The event loop is never held long: the picture of a mesh of more than
:data:`WORKER_TRIANGLES` triangles is computed in a worker thread (:func:`matrix_picture`,
numpy and scipy only), the figure is drawn once when the view is shown (a hidden canvas
does not draw) and its layout is placed from font metrics (:meth:`MatrixView.place_axes`)
rather than by matplotlib's constrained layout at every draw, which took half of each
draw's time.

A hover stays cheap at any size: the cell box and the row band are matplotlib "animated"
artists blitted over a cached picture of the plot (no full redraw), and the text under
the plot names the two triangles and the edge they share. A click offers *Zoom to*
(``zoom_requested``): at the zoom a big mesh is seen whole, its triangles are below a
pixel.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np
import scipy.sparse as sp
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure
from matplotlib.font_manager import FontProperties
from matplotlib.patches import Rectangle
from PySide6.QtCore import (
    QAbstractTableModel,
    QModelIndex,
    QPersistentModelIndex,
    Qt,
    Signal,
)
from PySide6.QtGui import QBrush, QColor, QFont
from PySide6.QtWidgets import (
    QAbstractItemView,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QPushButton,
    QTableView,
    QTabWidget,
    QVBoxLayout,
    QWidget,
)

from barymesh import TriMesh
from barymesh.app.jobs import Jobs
from barymesh.app.view.canvas import ShownCanvas

log = logging.getLogger(__name__)

DENSE_LIMIT = 600
IMAGE_BINS = 600
TABLE_LIMIT = 64
ONE_COLOR = "#1f4e9c"
ROW_COLOR = "#f28e2b"
CELL_COLOR = "#e0001b"
#: Meshes of more triangles get their picture in a worker thread: the occupancy image of
#: 1,049,760 triangles costs about 240 ms, Fig. 12(a)'s (23,040) about 5 ms.
WORKER_TRIANGLES = 100_000
#: Font sizes (points, before the presentation scale) and the margins of the spy plot.
TICK_FONT = 8
LABEL_FONT = 9
TITLE_FONT = 10
MARGIN_PX = 6


def occupancy_image(matrix: sp.csr_matrix, bins: int) -> np.ndarray:
    """(b, b) bool: whether each block of a square sparse matrix holds a nonzero.

    >>> occupancy_image(sp.eye(4, format="csr"), 2).astype(int).tolist()
    [[1, 0], [0, 1]]
    """
    coo = sp.coo_matrix(matrix)
    n = max(coo.shape[0], 1)
    b = max(1, min(int(bins), n))
    r = (coo.row.astype(np.int64) * b) // n
    c = (coo.col.astype(np.int64) * b) // n
    counts = np.bincount(r * b + c, minlength=b * b)
    return counts.reshape(b, b) > 0


@dataclass(frozen=True, eq=False)
class MatrixPicture:
    """What the spy plot shows of one mesh (plain arrays: made in any thread).

    Attributes
    ----------
    matrix : (T, T) scipy.sparse.csr_matrix
        The Eq. 27 connectivity matrix.
    picture : (b, b) float64
        The 0/1 matrix itself (T up to :data:`DENSE_LIMIT`) or its occupancy image.
    interior : int
        Interior edges of the mesh.
    """

    matrix: sp.csr_matrix
    picture: np.ndarray
    interior: int


def matrix_picture(mesh: TriMesh) -> MatrixPicture:
    """The connectivity matrix of ``mesh`` and the picture the spy plot draws of it."""
    matrix = sp.csr_matrix(mesh.connectivity)
    if matrix.shape[0] <= DENSE_LIMIT:
        picture = (matrix.toarray() != 0).astype(np.float64)
    else:
        picture = occupancy_image(matrix, IMAGE_BINS).astype(np.float64)
    return MatrixPicture(matrix, picture, len(mesh.interior_edges))


def _picture_or_error(mesh: TriMesh) -> MatrixPicture | BaseException:
    """:func:`matrix_picture` for a worker thread: an exception is returned, not raised."""
    try:
        return matrix_picture(mesh)
    except Exception as exc:  # noqa: BLE001 - reported on the GUI thread
        return exc


class ConnectivityTableModel(QAbstractTableModel):
    """The dense 0/1 matrix for a :class:`QTableView` (small meshes only)."""

    def __init__(self, parent: Any = None) -> None:
        super().__init__(parent)
        self.dense = np.zeros((0, 0), dtype=np.int8)
        self._bold = QFont()
        self._bold.setBold(True)
        self._one = QBrush(QColor("#c6d8f0"))
        self._zero = QBrush(QColor("#9a9a9a"))

    def set_matrix(self, dense: np.ndarray) -> None:
        self.beginResetModel()
        self.dense = np.asarray(dense, dtype=np.int8)
        self.endResetModel()

    def rowCount(self, parent: QModelIndex | QPersistentModelIndex = QModelIndex()) -> int:  # noqa: B008, N802
        return 0 if parent.isValid() else self.dense.shape[0]

    def columnCount(self, parent: QModelIndex | QPersistentModelIndex = QModelIndex()) -> int:  # noqa: B008, N802
        return 0 if parent.isValid() else self.dense.shape[1]

    def data(
        self, index: QModelIndex | QPersistentModelIndex, role: int = Qt.ItemDataRole.DisplayRole
    ) -> Any:
        if not index.isValid():
            return None
        value = int(self.dense[index.row(), index.column()])
        if role == Qt.ItemDataRole.DisplayRole:
            return str(value)
        if role == Qt.ItemDataRole.TextAlignmentRole:
            return int(Qt.AlignmentFlag.AlignCenter)
        if role == Qt.ItemDataRole.BackgroundRole and value:
            return self._one
        if role == Qt.ItemDataRole.ForegroundRole and not value:
            return self._zero
        if role == Qt.ItemDataRole.FontRole and value:
            return self._bold
        if role == Qt.ItemDataRole.ToolTipRole:
            i, j = index.row(), index.column()
            return f"T{i} and T{j} share an edge" if value else f"T{i} and T{j} share no edge"
        return None

    def headerData(
        self,
        section: int,
        orientation: Qt.Orientation,  # noqa: N802
        role: int = Qt.ItemDataRole.DisplayRole,
    ) -> Any:
        if role == Qt.ItemDataRole.DisplayRole:
            return str(section)
        return None


class MatrixView(QWidget):
    """Spy plot (and table) of the Eq. 27 connectivity matrix; see the module docstring."""

    cell_hovered = Signal(int, int)
    cell_clicked = Signal(int, int)
    zoom_requested = Signal()

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.mesh: TriMesh | None = None
        self.matrix: sp.csr_matrix | None = None
        self.stale = False
        self.row: int | None = None
        self.cell: tuple[int, int] | None = None
        self._hover: tuple[int, int] | None = None
        self.font_scale = 1.0
        self._background: Any = None
        self.full_draws = 0  # complete redraws of the spy plot (a hover blits instead)
        self.blits = 0

        self.picture: MatrixPicture | None = None
        self._token: object | None = None  # the picture being computed in a worker
        self.jobs = Jobs(self, threads=None, name="barymesh-matrix")

        self.figure = Figure(figsize=(4, 4), dpi=100)
        self.canvas = ShownCanvas(self.figure)
        self.canvas.setMinimumSize(220, 220)
        self.axes = self.figure.add_subplot(1, 1, 1)
        cmap = ListedColormap(["white", ONE_COLOR])
        self.image = self.axes.imshow(
            np.zeros((1, 1)), cmap=cmap, vmin=0, vmax=1, interpolation="nearest", aspect="equal"
        )
        self.row_band = Rectangle(
            (-0.5, -0.5),
            1,
            1,
            facecolor=ROW_COLOR,
            alpha=0.35,
            edgecolor="none",
            visible=False,
            animated=True,
        )
        self.cell_box = Rectangle(
            (-0.5, -0.5),
            1,
            1,
            facecolor="none",
            edgecolor=CELL_COLOR,
            linewidth=2.0,
            visible=False,
            animated=True,
        )
        self.axes.add_patch(self.row_band)
        self.axes.add_patch(self.cell_box)
        self.canvas.mpl_connect("motion_notify_event", self._mouse_moved)
        self.canvas.mpl_connect("button_press_event", self._mouse_pressed)
        self.canvas.mpl_connect("draw_event", self._drawn)
        self.canvas.mpl_connect("resize_event", lambda _event: self.place_axes())

        self.table_model = ConnectivityTableModel(self)
        self.table = QTableView(self)
        self.table.setModel(self.table_model)
        self.table.setMouseTracking(True)
        self.table.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.table.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        self.table.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        for header in (self.table.horizontalHeader(), self.table.verticalHeader()):
            header.setSectionResizeMode(QHeaderView.ResizeMode.Fixed)
            header.setDefaultSectionSize(26)
            header.setMinimumSectionSize(18)
        self.table.entered.connect(lambda i: self._table_cell(i, False))
        self.table.clicked.connect(lambda i: self._table_cell(i, True))
        self.caption = QLabel(self)
        self.caption.setWordWrap(True)
        self.table_note = QLabel(
            f"The 0/1 table is shown for meshes up to {TABLE_LIMIT} triangles.", self
        )
        self.table_note.setWordWrap(True)
        self.cell_label = QLabel(self)
        self.cell_label.setObjectName("matrix_cell")
        self.cell_label.setWordWrap(True)
        # two lines reserved: the plot above keeps its size while the text changes
        self.cell_label.setMinimumHeight(2 * self.cell_label.fontMetrics().lineSpacing() + 4)
        self.zoom_button = QPushButton("Zoom to the cell's triangles", self)
        self.zoom_button.setToolTip(
            "Frame the two triangles of the clicked cell in the 3D "
            "view (Z zooms to the selection too)"
        )
        self.zoom_button.setEnabled(False)
        self.zoom_button.clicked.connect(self.zoom_requested.emit)

        self.tabs = QTabWidget(self)
        self.tabs.addTab(self.canvas, "Spy plot")
        table_page = QWidget(self)
        table_layout = QVBoxLayout(table_page)
        table_layout.setContentsMargins(0, 0, 0, 0)
        table_layout.addWidget(self.table, 1)
        table_layout.addWidget(self.table_note)
        self.tabs.addTab(table_page, "0/1 table")
        layout = QVBoxLayout(self)
        layout.addWidget(self.caption)
        layout.addWidget(self.tabs, 1)
        cell_row = QHBoxLayout()
        cell_row.addWidget(self.cell_label, 1)
        cell_row.addWidget(self.zoom_button)
        layout.addLayout(cell_row)
        self._style_axes()

    # -- data ------------------------------------------------------------------------

    def set_mesh(self, mesh: TriMesh | None) -> None:
        """A new mesh: redraw now if shown, else when shown."""
        self.mesh = mesh
        self.row = self.cell = self._hover = None
        self.cell_label.setText("")
        self.zoom_button.setEnabled(False)
        self.stale = True
        self._token = None  # a picture still being computed is of an older mesh
        if self.isVisible():
            self._refresh_soon()

    def showEvent(self, event: Any) -> None:  # noqa: N802 - Qt's name
        super().showEvent(event)
        # before the first layout and paint: the caption's new text is laid out with the
        # rest and the canvas draws once, at its final size
        self._refresh_if_stale()

    def _refresh_if_stale(self) -> None:
        if self.stale and self._token is None and self.isVisible():
            self._refresh_soon()

    @property
    def computing(self) -> bool:
        """Whether a worker thread is computing the picture of the mesh."""
        return self._token is not None

    def _refresh_soon(self) -> None:
        """:meth:`refresh` here for a small mesh, else the picture in a worker thread."""
        mesh = self.mesh
        if mesh is None or mesh.n_triangles <= WORKER_TRIANGLES:
            self.refresh()
            return
        token = self._token = object()
        self.caption.setText(f"Computing the {mesh.n_triangles:,} × {mesh.n_triangles:,} matrix…")
        self.jobs.submit(partial(_picture_or_error, mesh), self._picture_ready, token, mesh)

    def _picture_ready(self, token: object, mesh: TriMesh, picture: Any) -> None:
        if token is not self._token or mesh is not self.mesh:
            return  # a newer mesh came meanwhile
        self._token = None
        if isinstance(picture, BaseException):
            log.error("connectivity failed", exc_info=picture)
            self.stale = False
            self.caption.setText(f"No connectivity matrix: {picture}")
            return
        self._show_picture(mesh, picture)

    def refresh(self) -> None:
        """Redraw the spy plot and the table from the current mesh (on this thread)."""
        self._token = None
        mesh = self.mesh
        if mesh is None or mesh.n_triangles == 0:
            self.stale = False
            self.matrix = self.picture = None
            self.image.set_data(np.zeros((1, 1)))
            self.caption.setText("No mesh.")
            self.table_model.set_matrix(np.zeros((0, 0)))
            self.canvas.draw_idle()
            return
        try:
            picture = matrix_picture(mesh)
        except Exception:  # noqa: BLE001 - the window keeps the last good view
            self.stale = False
            log.exception("connectivity failed")
            return
        self._show_picture(mesh, picture)

    def _show_picture(self, mesh: TriMesh, picture: MatrixPicture) -> None:
        """Put ``picture`` of ``mesh`` into the plot, the caption and the table."""
        self.stale = False
        self.picture = picture
        matrix = self.matrix = picture.matrix
        n = matrix.shape[0]
        self.image.set_data(picture.picture)
        self.image.set_extent((-0.5, n - 0.5, n - 0.5, -0.5))
        self.axes.set_xlim(-0.5, n - 0.5)
        self.axes.set_ylim(n - 0.5, -0.5)
        self.axes.title.set_text(f"Eq. 27: {n:,} × {n:,}, {matrix.nnz:,} nonzeros")
        interior = picture.interior
        self.caption.setText(
            f"Entry (i, j) = 1 when triangles i and j share an edge. {matrix.nnz:,} ones "
            f"= 2 × {interior:,} interior edges"
            + ("" if matrix.nnz == 2 * interior else " (plus junction pairs)")
            + ". Hover or click a cell to see its triangles."
        )
        small = n <= TABLE_LIMIT
        self.table_model.set_matrix(matrix.toarray() != 0 if small else np.zeros((0, 0)))
        self.table.setVisible(small)
        self.table_note.setVisible(not small)
        self.row_band.set_visible(False)
        self.cell_box.set_visible(False)
        self.place_axes()
        self.canvas.draw_idle()

    def nonzeros(self) -> int:
        """Ones the spy plot shows (counted in the drawn picture when it is the matrix)."""
        if self.matrix is None:
            return 0
        if self.matrix.shape[0] <= DENSE_LIMIT:
            image = self.image.get_array()
            assert image is not None  # drawn with the matrix
            return int(np.count_nonzero(image))
        return int(self.matrix.nnz)

    def table_nonzeros(self) -> int:
        """Ones in the 0/1 table (0 when the mesh is too big for a table)."""
        return int(np.count_nonzero(self.table_model.dense))

    # -- highlights ------------------------------------------------------------------

    def highlight_row(self, row: int | None) -> None:
        """Mark triangle ``row``'s row (a triangle picked in the 3D view)."""
        n = 0 if self.matrix is None else self.matrix.shape[0]
        self.row = row if row is not None and 0 <= row < n else None
        if self.row is None:
            self.row_band.set_visible(False)
            self.table.clearSelection()
        else:
            height = max(1.0, n / 300)  # at least a few pixels on a big matrix
            self.row_band.set_bounds(-0.5, self.row - 0.5 * height, n, height)
            self.row_band.set_visible(True)
            if self.table_model.dense.size:
                self.table.selectRow(self.row)
                self.table.scrollTo(self.table_model.index(self.row, 0))
        self._blit()

    def highlight_cell(self, row: int | None, col: int | None) -> None:
        n = 0 if self.matrix is None else self.matrix.shape[0]
        if row is None or col is None or not (0 <= row < n and 0 <= col < n):
            self.cell = None
            self.cell_box.set_visible(False)
        else:
            self.cell = (row, col)
            size = max(1.0, n / 100)
            self.cell_box.set_bounds(col - 0.5 * size, row - 0.5 * size, size, size)
            self.cell_box.set_visible(True)
        self.cell_label.setText(self.cell_text())
        self._blit()

    def cell_text(self) -> str:
        """What the cell under the mouse means: its two triangles and their shared edge."""
        if self.cell is None or self.mesh is None:
            return ""
        i, j = self.cell
        if i == j:
            return f"T{i} (the diagonal: a triangle and itself)"
        te = self.mesh.triangle_edges
        common = np.intersect1d(te[i], te[j])
        if len(common):
            return f"T{i} and T{j} share edge {int(common[0])}: entry 1"
        return f"T{i} and T{j} share no edge: entry 0"

    # -- drawing -----------------------------------------------------------------------

    def _drawn(self, _event: Any) -> None:
        """After a full redraw: keep its picture for blitting and draw the marks over it."""
        self.full_draws += 1
        self._background = self.canvas.copy_from_bbox(self.figure.bbox)
        self._draw_marks()

    def _draw_marks(self) -> None:
        for artist in (self.row_band, self.cell_box):
            if artist.get_visible():
                self.axes.draw_artist(artist)

    def _blit(self) -> None:
        """Redraw only the row band and the cell box over the cached plot."""
        if self._background is None or not self.isVisible():
            self.canvas.draw_idle()
            return
        self.canvas.restore_region(self._background)
        self._draw_marks()
        self.canvas.blit(self.figure.bbox)
        self.blits += 1

    def set_font_scale(self, scale: float) -> None:
        self.font_scale = float(scale)
        self._style_axes()
        self.place_axes()
        self.canvas.draw_idle()

    def _style_axes(self) -> None:
        s = self.font_scale
        self.axes.tick_params(
            labelsize=TICK_FONT * s, top=True, labeltop=True, bottom=False, labelbottom=False
        )
        self.axes.set_xlabel("triangle j", fontsize=LABEL_FONT * s)
        self.axes.xaxis.set_label_position("top")
        self.axes.set_ylabel("triangle i", fontsize=LABEL_FONT * s)
        # a title at a fixed offset above the axes (place_axes sets it): matplotlib
        # would otherwise measure the top tick labels at every draw to lift it over them
        self.axes.set_title(self.axes.get_title(), fontsize=TITLE_FONT * s, y=1.0)

    def place_axes(self) -> None:
        """The square axes and its title placed in the canvas from font metrics.

        What constrained layout found at every draw (about half of each draw's time),
        computed here in a few text measurements: room on the left for the row label
        and the widest row number, on top for the title, the column label and the
        column numbers; the square as large as fits, centred.
        """
        width, height = self.figure.bbox.width, self.figure.bbox.height
        if width < 2 or height < 2:
            return
        s, pt = self.font_scale, self.figure.dpi / 72.0
        n = 0 if self.matrix is None else self.matrix.shape[0]
        renderer = self.canvas.get_renderer()

        def text_size(text: str, points: float) -> tuple[float, float]:
            w, h, _d = renderer.get_text_width_height_descent(
                text, FontProperties(size=points), ismath=False
            )
            return w, h

        # the widest tick number: as many digits as n (up to 1e6, then 0.2 … ×1e6)
        digits = "8" * (len(str(max(n, 1))) if n < 1_000_000 else 3)
        tick_w, tick_h = text_size(digits, TICK_FONT * s)
        _label_w, label_h = text_size("triangle j", LABEL_FONT * s)
        _title_w, title_h = text_size("Eq. 27: 8", TITLE_FONT * s)
        ticks = (3.5 + 3.5) * pt  # tick length and pad (matplotlib's defaults)
        label_pad = 4.0 * pt
        top_of_axes = ticks + tick_h + label_pad + label_h  # numbers and label over it
        left = MARGIN_PX + label_h + label_pad + tick_w + ticks
        top = MARGIN_PX + title_h + 6.0 * pt + top_of_axes
        right = MARGIN_PX + 0.5 * tick_w
        bottom = MARGIN_PX + 0.5 * tick_h
        side = max(min(width - left - right, height - top - bottom), 4.0)
        x0 = left + 0.5 * (width - left - right - side)
        y0 = bottom + 0.5 * (height - top - bottom - side)
        self.axes.set_position((x0 / width, y0 / height, side / width, side / height))
        self.axes.set_title(
            self.axes.get_title(), fontsize=TITLE_FONT * s, y=1.0, pad=top_of_axes / pt + 6.0
        )

    # -- mouse -----------------------------------------------------------------------

    def cell_at(self, x: float | None, y: float | None) -> tuple[int, int] | None:
        """The (row, column) under data coordinates (x, y), or None outside."""
        if self.matrix is None or x is None or y is None:
            return None
        n = self.matrix.shape[0]
        col, row = int(np.floor(x + 0.5)), int(np.floor(y + 0.5))
        if not (0 <= row < n and 0 <= col < n):
            return None
        return self._snapped(row, col)

    def _snapped(self, row: int, col: int) -> tuple[int, int]:
        """On a big matrix, a zero cell next to a one (within a few pixels) means the one."""
        m = self.matrix
        assert m is not None  # a click on a drawn matrix
        cols = m.indices[m.indptr[row] : m.indptr[row + 1]]
        if len(cols) == 0 or col in cols:
            return row, col
        nearest = int(cols[np.argmin(np.abs(cols - col))])
        reach = max(m.shape[0] / 150, 3.0 * self._columns_per_pixel())
        return (row, nearest) if abs(nearest - col) <= reach else (row, col)

    def _columns_per_pixel(self) -> float:
        """Matrix columns under one screen pixel of the spy plot at its present size."""
        try:
            x0, _ = self.axes.transData.inverted().transform((0.0, 0.0))
            x1, _ = self.axes.transData.inverted().transform((1.0, 0.0))
        except (ValueError, np.linalg.LinAlgError):  # a collapsed axes: no scale
            return 0.0
        step = abs(float(x1 - x0))
        return step if np.isfinite(step) else 0.0

    def _mouse_moved(self, event: Any) -> None:
        cell = self.cell_at(event.xdata, event.ydata) if event.inaxes is self.axes else None
        if cell is not None and cell != self._hover:
            self._hover = cell
            self.cell_hovered.emit(*cell)

    def _mouse_pressed(self, event: Any) -> None:
        if event.inaxes is not self.axes:
            return
        cell = self.cell_at(event.xdata, event.ydata)
        if cell is not None:
            self.cell_clicked.emit(*cell)
            self._offer_zoom(*cell)

    def _table_cell(self, index: QModelIndex, clicked: bool) -> None:
        if not index.isValid():
            return
        if clicked:
            self.cell_clicked.emit(index.row(), index.column())
            self._offer_zoom(index.row(), index.column())
        else:
            self.cell_hovered.emit(index.row(), index.column())

    def _offer_zoom(self, row: int, col: int) -> None:
        self.zoom_button.setEnabled(True)
        self.zoom_button.setText(f"Zoom to T{row}" if row == col else f"Zoom to T{row} and T{col}")
