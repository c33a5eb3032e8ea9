"""The Quality panel: the quality report of the mesh on screen, its worst triangles listed.

Three histograms (smallest angle, aspect ratio, longest edge over the wavelength when the
parameters give a frequency) with their thresholds marked, a few lines of figures, and the
worst triangles by smallest angle: a click on one zooms the view to it and outlines it,
over the worst triangles drawn in red (:class:`barymesh.app.view.quality_layer.WorstTrianglesLayer`,
toggled by the check box here or View → Worst triangles).

The report is :func:`barymesh.quality.quality_report`, measured when the panel is seen (its
dock's ``visibilityChanged`` calls :meth:`QualityPanel.set_seen`) or the red layer is on:
on the GUI thread up to :data:`SYNC_TRIANGLES` triangles (about a millisecond), else in a
worker thread (:class:`barymesh.app.jobs.Jobs`) while the window keeps answering; only
the small report comes back.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from functools import partial
from typing import TYPE_CHECKING, Any

import numpy as np
from PySide6.QtCore import QPointF, QRectF, QSize, Qt, QTimer, Signal
from PySide6.QtGui import QAction, QColor, QFont, QPainter, QPen
from PySide6.QtWidgets import (
    QCheckBox,
    QLabel,
    QListWidget,
    QListWidgetItem,
    QSizePolicy,
    QVBoxLayout,
    QWidget,
)

from barymesh import TriMesh
from barymesh.app.jobs import Jobs
from barymesh.app.view.quality_layer import WorstTrianglesLayer
from barymesh.app.worker import SYNC_TRIANGLES
from barymesh.quality import params_wavelength, quality_report

if TYPE_CHECKING:
    from barymesh.app.model import AppModel
    from barymesh.app.tool_host import ToolHost

log = logging.getLogger(__name__)

GOOD_COLOR = QColor("#4a7fb5")
BAD_COLOR = QColor("#d0021b")
#: How many of the worst triangles the panel lists and draws.
WORST = 20


def measure(mesh: TriMesh, wavelength: float | None) -> dict[str, Any] | str:
    """The quality report, or the reason it failed (never raises: it runs in a thread)."""
    try:
        return quality_report(mesh, wavelength=wavelength, worst=WORST)
    except Exception as exc:  # noqa: BLE001 - shown in the panel, never a crash
        log.exception("the quality report failed")
        return f"The quality report failed: {exc}"


def _tick(value: float) -> str:
    return f"{value:.3g}"


class HistogramView(QWidget):
    """Bars of one histogram of the report, the threshold as a dashed red line.

    Bins on the wrong side of the threshold are red, the others blue; a bin with any
    triangle is at least one pixel high, so a few slivers among thousands still show.
    """

    def __init__(self, title: str, unit: str, bad_side: str, parent: QWidget | None = None):
        super().__init__(parent)
        self.title, self.unit, self.bad_side = title, unit, bad_side  # "below" / "above"
        self.edges = np.empty(0)
        self.counts = np.empty(0, dtype=np.int64)
        self.threshold: float | None = None
        self.above_range = 0
        self.message = ""
        self.setMinimumHeight(96)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)

    def sizeHint(self) -> QSize:  # noqa: N802 - Qt's name
        return QSize(260, 104)

    def set_data(self, figures: dict[str, Any] | None, message: str = "") -> None:
        """``figures``: one entry of the report (with ``histogram`` and ``threshold``)."""
        if figures is None:
            self.edges, self.counts, self.threshold, self.above_range = (
                np.empty(0),
                np.empty(0, dtype=np.int64),
                None,
                0,
            )
        else:
            h = figures["histogram"]
            self.edges = np.asarray(h["edges"], dtype=np.float64)
            self.counts = np.asarray(h["counts"], dtype=np.int64)
            self.threshold = float(figures["threshold"])
            self.above_range = int(h["above_range"])
        self.message = message
        self.update()

    def bar_rect(self) -> QRectF:
        """The plotting area (widget pixels)."""
        return QRectF(8.0, 18.0, max(self.width() - 16.0, 1.0), max(self.height() - 36.0, 1.0))

    def x_of(self, value: float) -> float:
        """Widget x of ``value`` on the bins' axis."""
        r = self.bar_rect()
        lo, hi = float(self.edges[0]), float(self.edges[-1])
        return r.left() + (value - lo) / max(hi - lo, 1e-300) * r.width()

    def paintEvent(self, _event: Any) -> None:  # noqa: N802 - Qt's name
        p = QPainter(self)
        p.setRenderHint(QPainter.RenderHint.Antialiasing, False)
        pal = self.palette()
        text = pal.color(pal.ColorRole.WindowText)
        font = QFont(self.font())
        font.setPointSizeF(max(font.pointSizeF() - 1.0, 7.0))
        p.setFont(font)
        p.setPen(text)
        unit = f" ({self.unit})" if self.unit else ""
        p.drawText(
            QRectF(8, 0, self.width() - 16, 16),
            Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignVCenter,
            f"{self.title}{unit}",
        )
        r = self.bar_rect()
        if len(self.counts) == 0:
            p.setPen(pal.color(pal.ColorRole.PlaceholderText))
            p.drawText(r, Qt.AlignmentFlag.AlignCenter, self.message or "–")
            p.end()
            return
        top = max(int(self.counts.max()), 1)
        p.drawText(
            QRectF(8, 0, self.width() - 16, 16),
            Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter,
            f"peak {top:,}",
        )
        p.setPen(Qt.PenStyle.NoPen)
        for k, count in enumerate(self.counts.tolist()):
            if count == 0:
                continue
            x0, x1 = self.x_of(self.edges[k]), self.x_of(self.edges[k + 1])
            h = max(count / top * r.height(), 1.0)
            centre = 0.5 * (self.edges[k] + self.edges[k + 1])
            bad = self.threshold is not None and (
                centre < self.threshold if self.bad_side == "below" else centre > self.threshold
            )
            p.setBrush(BAD_COLOR if bad else GOOD_COLOR)
            p.drawRect(QRectF(x0, r.bottom() - h, max(x1 - x0 - 1.0, 1.0), h))
        p.setPen(QPen(text, 1))
        p.drawLine(QPointF(r.left(), r.bottom()), QPointF(r.right(), r.bottom()))
        labels = [
            (float(self.edges[0]), Qt.AlignmentFlag.AlignLeft),
            (float(self.edges[-1]), Qt.AlignmentFlag.AlignRight),
        ]
        if self.threshold is not None and self.edges[0] <= self.threshold <= self.edges[-1]:
            x = self.x_of(self.threshold)
            p.setPen(QPen(BAD_COLOR, 1.5, Qt.PenStyle.DashLine))
            p.drawLine(QPointF(x, r.top() - 2), QPointF(x, r.bottom() + 3))
            p.setPen(BAD_COLOR)
            p.drawText(
                QRectF(x - 30, r.bottom() + 2, 60, 14),
                Qt.AlignmentFlag.AlignHCenter,
                _tick(self.threshold),
            )
        p.setPen(text)
        for value, align in labels:
            x = r.left() if align == Qt.AlignmentFlag.AlignLeft else r.right() - 60
            p.drawText(QRectF(x, r.bottom() + 2, 60, 14), align, _tick(value))
        if self.above_range:
            p.setPen(BAD_COLOR)
            p.drawText(
                QRectF(r.right() - 120, r.top(), 120, 14),
                Qt.AlignmentFlag.AlignRight,
                f"+{self.above_range:,} beyond {_tick(self.edges[-1])}",
            )
        p.end()


class QualityPanel(QWidget):
    """Histograms, figures and the worst triangles of the mesh on screen (module docstring).

    Parameters
    ----------
    host : ToolHost
        The window (:class:`barymesh.app.tool_host.ToolHost`): render requests.
    model : AppModel
        Its results (the mesh measured).
    plotter : pyvista plotter
        The 3D view: the red layer goes there.
    view_bounds : callable
        ``view_bounds()``: the bounds of what the view shows, (xmin, xmax, ymin, ymax, …),
        or None (the red layer's outline widths follow them).
    zoom_to_points : callable
        ``zoom_to_points(points)``: frame the view on some points (a chosen triangle).
    parent : QWidget, optional
    """

    #: (token, mesh, report or error text) from a worker thread.
    #: A report is on show (tests, the window).
    report_changed = Signal(object)

    def __init__(
        self,
        host: ToolHost,
        model: AppModel,
        plotter: Any,
        view_bounds: Callable[[], Any],
        zoom_to_points: Callable[[np.ndarray], None],
        parent: QWidget | None = None,
    ) -> None:
        super().__init__(parent)
        self.host, self.model = host, model
        self._view_bounds, self._zoom_to_points = view_bounds, zoom_to_points
        self.layer = WorstTrianglesLayer(plotter)
        self.layer.set_visible(False)
        self.report: dict[str, Any] | None = None
        self.mesh: TriMesh | None = None
        self._result: Any = None
        self._stale = False
        self._token: object | None = None
        self.measuring = False
        self.seen = False  # see set_seen

        box = QVBoxLayout(self)
        box.setContentsMargins(8, 6, 8, 6)
        box.setSpacing(4)
        self.figures = QLabel("–", self)
        self.figures.setObjectName("quality_figures")
        self.figures.setWordWrap(True)
        self.figures.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        box.addWidget(self.figures)
        self.histograms = {
            "min_angle_deg": HistogramView("Smallest angle", "°", "below", self),
            "aspect_ratio": HistogramView("Aspect ratio", "", "above", self),
            "edge_wavelength": HistogramView("Longest edge / λ", "", "above", self),
        }
        for view in self.histograms.values():
            box.addWidget(view)
        self.show_layer = QCheckBox("Draw the worst triangles in red", self)
        self.show_layer.setToolTip("The triangles listed below, filled red in the 3D view")
        self.show_layer.toggled.connect(self.set_layer_visible)
        box.addWidget(self.show_layer)
        heading = QLabel(f"Worst {WORST} by smallest angle (click: zoom to it)", self)
        heading.setStyleSheet("color: #555;")
        box.addWidget(heading)
        self.worst_list = QListWidget(self)
        self.worst_list.setObjectName("quality_worst")
        self.worst_list.setMinimumHeight(160)
        self.worst_list.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.worst_list.itemClicked.connect(self._item_chosen)
        self.worst_list.itemActivated.connect(self._item_chosen)
        box.addWidget(self.worst_list, 1)
        self.act_layer = QAction("&Worst triangles (quality)", self)
        self.act_layer.setCheckable(True)
        self.act_layer.setStatusTip("Draw the quality report's worst triangles in red")
        self.act_layer.toggled.connect(self.show_layer.setChecked)

        self.jobs = Jobs(self, threads=None, name="barymesh-quality")
        model.result_changed.connect(self.mesh_changed)
        self.mesh_changed(model.result)

    # -- measuring ---------------------------------------------------------------------

    def _wanted(self) -> bool:
        return self.seen or self.layer.visible

    @property
    def up_to_date(self) -> bool:
        """The report on show is the mesh on screen's (not waiting, not measuring)."""
        return not self._stale and not self.measuring

    def set_seen(self, seen: bool) -> None:
        """The dock's ``visibilityChanged``: a tab behind another one is not seen (yet it
        counts as visible for Qt), so the report waits until its tab is chosen."""
        self.seen = bool(seen)
        if self.seen and self._stale:
            QTimer.singleShot(0, self._refresh_if_wanted)

    def _refresh_if_wanted(self) -> None:
        # a turn of the event loop later: when the window is first shown every dock is
        # announced visible for a moment before the tabs hide all but the raised one
        if self._stale and self._wanted():
            self.refresh()

    def mesh_changed(self, result: Any) -> None:
        """A new mesh on screen: measure it now if seen, else when the panel is shown."""
        old = self._result
        if result is old or (
            result is not None
            and old is not None
            and result.mesh is not None
            and result.mesh is old.mesh
            and result.params == old.params
            and result.source == old.source
        ):
            self._result = result  # Undo back to the mesh on screen: nothing new to measure
            return
        self._result = result
        self._stale = True
        if self._wanted():
            QTimer.singleShot(0, self._refresh_if_wanted)
        elif self.mesh is not None or self.report is not None:
            self._forget()

    def _forget(self) -> None:
        """Unseen, with a new mesh on screen: drop the old report and mesh now (keeping
        them would keep a dead mesh alive, a million triangles after a large one); the
        new mesh is measured when the panel is shown. Nothing is rendered for it."""
        self._token = None
        self.measuring = False
        self.report, self.mesh = None, None
        self.worst_list.clear()
        self.figures.setText("Measured when this panel is shown.")
        for view in self.histograms.values():
            view.set_data(None)
        self.layer.show(None, [])
        self.report_changed.emit(None)

    def refresh(self) -> None:
        """Measure the mesh on screen (on this thread when small, else in a worker)."""
        self._stale = False
        result = self._result
        mesh = None if result is None else result.mesh
        if mesh is None:
            self._token = None
            self._show(None, None)
            return
        params = result.params if result.source == "parameters" else None
        try:
            wavelength = params_wavelength(params)
        except ValueError:  # a frequency the parameters should have refused: no edge/λ
            wavelength = None
        if mesh.n_triangles <= SYNC_TRIANGLES:
            self._token = None
            self._show(mesh, measure(mesh, wavelength))
            return
        token = object()
        self._token = token
        self.measuring = True
        self.figures.setText(f"Measuring {mesh.n_triangles:,} triangles…")
        self.jobs.submit(partial(measure, mesh, wavelength), self._on_ready, token, mesh)

    def _on_ready(self, token: object, mesh: TriMesh, report: Any) -> None:
        if token is not self._token:  # a newer mesh came meanwhile
            return
        self._token = None
        self._show(mesh, report)

    # -- showing -----------------------------------------------------------------------

    def _show(self, mesh: TriMesh | None, report: dict[str, Any] | str | None) -> None:
        self.measuring = False
        self.worst_list.clear()
        if not isinstance(report, dict):
            self.report, self.mesh = None, None
            self.figures.setText(report or "No mesh")
            for view in self.histograms.values():
                view.set_data(None)
            self.layer.show(None, [])
            self._render()
            self.report_changed.emit(None)
            return
        self.report, self.mesh = report, mesh
        self.figures.setText(figures_text(report))
        for key, view in self.histograms.items():
            view.set_data(report[key])
        # without a frequency there is no edge/λ to draw: the line above says so
        self.histograms["edge_wavelength"].setVisible(report["edge_wavelength"] is not None)
        for rank, row in enumerate(report["worst"], start=1):
            item = QListWidgetItem(worst_text(rank, row), self.worst_list)
            item.setData(Qt.ItemDataRole.UserRole, row["triangle"])
            x, y, _ = row["centroid"]
            item.setToolTip(f"Triangle {row['triangle']:,}, centroid ({x:.6g}, {y:.6g}) mm")
        bounds = self._view_bounds()
        span = None if bounds is None else max(bounds[1] - bounds[0], bounds[3] - bounds[2])
        self.layer.show(mesh, [row["triangle"] for row in report["worst"]], span)
        if self.layer.visible:  # else the view has nothing new to draw
            self._render()
        self.report_changed.emit(report)

    def _render(self) -> None:
        self.host.request_render()

    def set_layer_visible(self, on: bool) -> None:
        """Show or hide the red worst triangles (measuring first if need be)."""
        on = bool(on)
        if self.show_layer.isChecked() != on:
            self.show_layer.setChecked(on)
        if self.act_layer.isChecked() != on:
            self.act_layer.setChecked(on)
        self.layer.set_visible(on)
        if on and self._stale:
            self.refresh()
        self._render()

    def _item_chosen(self, item: QListWidgetItem) -> None:
        self.choose(int(item.data(Qt.ItemDataRole.UserRole)))

    def choose(self, triangle: int) -> None:
        """Zoom the view to ``triangle`` and outline it over the red layer (shown)."""
        mesh = self.mesh
        if mesh is None or not 0 <= triangle < mesh.n_triangles:
            return
        self.set_layer_visible(True)
        self.layer.choose(triangle)
        corners = np.asarray(mesh.points)[mesh.triangles[triangle]]
        self._zoom_to_points(corners)


def figures_text(report: dict[str, Any]) -> str:
    """The report's figures in a few lines (rich text) for the panel."""
    n = report["triangles"]
    a, r, e = report["min_angle_deg"], report["aspect_ratio"], report["edge_wavelength"]

    def share(count: int) -> str:
        pct = f" ({100.0 * count / n:.3g}%)" if n else ""
        text = f"{count:,}{pct}"
        return f'<span style="color:#d0021b"><b>{text}</b></span>' if count else text

    def num(x: float | None, fmt: str) -> str:
        return "undefined" if x is None else format(x, fmt)

    lines = [
        f"Smallest angle <b>{num(a['min'], '.3g')}°</b> "
        f"(median {num(a['percentiles']['50'], '.3g')}°); below {a['threshold']:g}°: "
        f"{share(a['below'])}",
        f"Aspect ratio max <b>{num(r['max'], '.3g')}</b>; above {r['threshold']:g}: "
        f"{share(r['above'])}",
    ]
    if r["degenerate"]:
        lines.append(f"Zero-area triangles: {share(r['degenerate'])}")
    if e is None:
        lines.append("Edge/λ: no frequency set")
    else:
        lines.append(
            f"Longest edge <b>{num(e['max'], '.3g')} λ</b> (λ = {e['wavelength_mm']:.4g}"
            f" mm); above λ/10: {share(e['above'])}"
        )
    return "<br>".join(lines)


def worst_text(rank: int, row: dict[str, Any]) -> str:
    """One line of the worst list: rank, triangle, smallest angle, aspect ratio (edge/λ)."""
    angle, ratio = row["min_angle_deg"], row["aspect_ratio"]
    text = (
        f"{rank}. triangle {row['triangle']:,}: "
        f"{'–' if angle is None else f'{angle:.3g}°'}, "
        f"aspect {'–' if ratio is None else f'{ratio:.3g}'}"
    )
    if row.get("edge_wavelength") is not None:
        text += f", {row['edge_wavelength']:.3g} λ"
    return text
