"""Teach → Construction step by step: the paper's construction of one patch, one step a click.

A window of its own (its own ``QtInteractor``) next to the main window, following the main
window's parameters (patch size and width, subdivisions n, diagonal, origin; or the
triangle structure). The steps come from :func:`barymesh.teach.construction.construction_steps`;
this module only draws them: the actors of every layer are created once and each step
copies its data into them (``copy_from``), then renders once.

A separate window rather than a mode of the main view: the main view keeps its mesh, its
camera and its picking, the construction keeps a stable frame across steps, and both can
be shown side by side on a projector.
"""

from __future__ import annotations

import logging
from typing import Any

import numpy as np
import pyvista as pv
from PySide6.QtCore import QEvent, Qt, QTimer, Signal
from PySide6.QtGui import QKeySequence, QShortcut
from PySide6.QtWidgets import (
    QComboBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSlider,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from barymesh import MeshParams
from barymesh.app.model import AppModel
from barymesh.app.model.layers import LAYERS as SCENE_LAYERS
from barymesh.app.teach.following_view import FollowingView
from barymesh.app.view.gl_info import tune_multi_samples
from barymesh.app.view.rulers import nice_span
from barymesh.app.view.scene import MeshScene, add_text_labels
from barymesh.teach.construction import ConstructionStep, construction_steps

log = logging.getLogger(__name__)

BACKGROUND = "white"
COLORS = {
    "primary_0": "#eef3fa",
    "primary_1": "#f7f0e6",
    "subtriangles": "#cfe0f3",
    "segments": "#4a5a6c",
    "highlight": "#d62728",
    "points": "#111111",
    "division_points": "#8a96a3",
    "centroids": "#b0147a",
    "shared_edges": "#f28e2b",
    "labels": "#111111",
}
#: Line widths and point sizes (px).
WIDTHS = {
    "segments": 2.0,
    "highlight": 5.0,
    "points": 13.0,
    "division_points": 9.0,
    "centroids": 9.0,
    "shared_edges": 4.0,
}
LABEL_FONT = 22
#: The rulers' fonts are this many times the main view's; point labels on the left and
#: bottom sides of the patch keep this many pixels more from their points, so that they
#: sit beyond the rulers' tick labels (left: up to four characters, below: one line).
RULER_EMPHASIS = 1.4
RULER_CLEARANCE = {"left": 48.0, "bottom": 26.0}
TITLE_FONT = 10
#: The caption's font size (px) and its distance from the top of the view (px).
CAPTION_PX = 25
CAPTION_TOP_PX = 6
#: Labels are drawn when an edge is cut into at most this many segments, else only the
#: first two levels of halving (m1, m2, m3, m11 … m22) or every few division points.
MAX_LABELLED_SEGMENTS = 8
LAYERS = (
    "primary_0",
    "primary_1",
    "subtriangles",
    "segments",
    "shared_edges",
    "highlight",
    "division_points",
    "points",
    "centroids",
)


def _lines(segments: np.ndarray, z: float) -> pv.PolyData:
    """(m, 2, 2) segments as a PolyData of m line cells at height z."""
    seg = np.asarray(segments, dtype=np.float64).reshape(-1, 2, 2)
    if len(seg) == 0:
        return pv.PolyData()
    pts = np.zeros((2 * len(seg), 3))
    pts[:, :2] = seg.reshape(-1, 2)
    pts[:, 2] = z
    cells = np.column_stack(
        [np.full(len(seg), 2), np.arange(0, 2 * len(seg), 2), np.arange(1, 2 * len(seg), 2)]
    )
    return pv.PolyData(pts, lines=cells.ravel())


def _triangles(tris: np.ndarray, z: float) -> pv.PolyData:
    """(t, 3, 2) triangles as a PolyData of t faces at height z."""
    tri = np.asarray(tris, dtype=np.float64).reshape(-1, 3, 2)
    if len(tri) == 0:
        return pv.PolyData()
    pts = np.zeros((3 * len(tri), 3))
    pts[:, :2] = tri.reshape(-1, 2)
    pts[:, 2] = z
    return pv.PolyData.from_regular_faces(pts, np.arange(3 * len(tri)).reshape(-1, 3))


def _points(xy: np.ndarray, z: float) -> pv.PolyData:
    xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    if len(xy) == 0:
        return pv.PolyData()
    return pv.PolyData(np.column_stack([xy, np.full(len(xy), z)]))


def primary_triangles(params: MeshParams, step: ConstructionStep) -> list[np.ndarray]:
    """The primary triangles, (3, 2) each, from the corner points A, B, C(, D) of a step."""
    corners = np.asarray(step.points[: 3 if step.labels[3:4] != ["D"] else 4])
    if len(corners) == 3:
        return [corners]
    a, b, c, d = corners
    if params.diagonal == "BC":
        return [np.array([a, b, c]), np.array([d, c, b])]
    return [np.array([a, b, d]), np.array([a, d, c])]


def shown_labels(labels: list[str], n: int) -> list[str]:
    """The labels drawn for n segments per edge ("" = not drawn), so they never crowd.

    >>> shown_labels(["A", "m1", "m11", "m111", "ab3"], 16)
    ['A', 'm1', 'm11', '', '']
    """
    if n <= MAX_LABELLED_SEGMENTS:
        return list(labels)
    every = int(np.ceil(n / MAX_LABELLED_SEGMENTS))
    out = []
    for label in labels:
        if label.startswith("m"):
            keep = len(label) <= 3
        elif label[:2] in ("ab", "ac"):
            keep = label[2:].isdigit() and int(label[2:]) % every == 0
        else:
            keep = True
        out.append(label if keep else "")
    return out


def step_datasets(
    params: MeshParams, step: ConstructionStep, index: int, size: float
) -> tuple[dict[str, pv.PolyData], pv.PolyData]:
    """The datasets of every layer for one step, and the label anchors (string array).

    Lines are lifted above the faces and points above the lines so a top view draws them
    in that order. Labels sit outside their point, away from the first primary triangle's
    centroid, so they never cover the dot or the line through it.
    """
    dz = 1e-3 * size
    out: dict[str, pv.PolyData] = {}
    primaries = primary_triangles(params, step)
    four = step.labels[3:4] == ["D"]
    show_primaries = index >= (1 if four else 0) and len(step.triangles) == 0
    for k in range(2):
        tri = primaries[k][None] if show_primaries and k < len(primaries) else np.empty((0, 3, 2))
        out[f"primary_{k}"] = _triangles(tri, 0.0)
    out["subtriangles"] = _triangles(step.triangles, 0.5 * dz)
    out["segments"] = _lines(step.segments, 1 * dz)
    out["shared_edges"] = _lines(step.shared_edges, 2 * dz)
    out["highlight"] = _lines(step.highlight, 3 * dz)
    labels = shown_labels(step.labels, params.segments)
    named = np.array([bool(s) for s in labels], dtype=bool)
    pts = np.asarray(step.points, dtype=np.float64).reshape(-1, 2)
    out["points"] = _points(pts[named], 5 * dz)
    out["division_points"] = _points(pts[~named], 4 * dz)
    out["centroids"] = _points(step.centroids, 6 * dz)

    centre = primaries[0].mean(axis=0)
    keep = np.array([bool(s) for s in labels], dtype=bool)
    direction = pts[keep] - centre
    norm = np.linalg.norm(direction, axis=1, keepdims=True)
    direction = direction / np.where(norm > 0, norm, 1.0)
    anchors = _points(pts[keep], 7 * dz)
    if anchors.n_points:
        anchors.point_data["label"] = np.array([s for s in labels if s], dtype=object)
        anchors.point_data["direction"] = direction
    return out, anchors


def label_offsets(
    labels: list[str],
    direction: np.ndarray,
    font_px: float,
    gap_px: float,
    extra_px: np.ndarray | None = None,
) -> np.ndarray:
    """Pixel offsets (k, 2) that move each centred label box just clear of its point.

    The box (about 0.62 font sizes per character wide, 1.2 high) is pushed along
    ``direction`` until it no longer covers the point and a gap around it: far enough
    horizontally or vertically, whichever comes first. ``extra_px`` (k, 2) adds room
    horizontally and vertically for each label (to clear the rulers' tick labels).
    """
    direction = np.asarray(direction, dtype=np.float64).reshape(-1, 2)
    half_w = 0.5 * (0.62 * font_px * np.array([len(s) for s in labels], dtype=float) + 6)
    half_h = 0.5 * (1.2 * font_px + 4)
    extra = (
        np.zeros((len(direction), 2))
        if extra_px is None
        else np.asarray(extra_px, dtype=np.float64).reshape(-1, 2)
    )
    with np.errstate(divide="ignore"):
        rx = np.where(
            np.abs(direction[:, 0]) > 1e-9,
            (half_w + gap_px + extra[:, 0]) / np.abs(direction[:, 0]),
            np.inf,
        )
        ry = np.where(
            np.abs(direction[:, 1]) > 1e-9,
            (half_h + gap_px + extra[:, 1]) / np.abs(direction[:, 1]),
            np.inf,
        )
    r = np.minimum(rx, ry)
    return direction * r[:, None]


class ConstructionView(FollowingView):
    """The step-by-step construction window (see the module docstring).

    Parameters
    ----------
    model : AppModel
        The main window's model: the construction follows its parameters and its n and
        diagonal controls change them (undoable there).
    parent : QWidget, optional
    """

    step_changed = Signal(int)

    def __init__(self, model: AppModel, parent: QWidget | None = None) -> None:
        super().__init__(parent, Qt.WindowType.Window)
        from pyvistaqt import QtInteractor

        self.model = model
        self.setObjectName("construction")
        self.setWindowTitle("barymesh – construction step by step")
        self.steps: list[ConstructionStep] = []
        self.params: MeshParams | None = None
        self.index = 0
        self._closed = False
        self._frame_key: tuple[Any, ...] | None = None
        self._frame_bounds: tuple[np.ndarray, np.ndarray] | None = None
        self._syncing = True  # the n and diagonal controls copy the model, not the reverse

        self.plotter = QtInteractor(self, auto_update=False)
        tune_multi_samples(self.plotter)  # no MSAA on llvmpipe: a render costs 8x less
        self.plotter.setMinimumSize(480, 400)
        for key in ("q", "e"):
            self.plotter.clear_events_for_key(key, raise_on_missing=False)
        self.plotter.set_background(BACKGROUND)
        self.plotter.theme.allow_empty_mesh = True
        self.plotter.enable_parallel_projection()
        self.label_font = LABEL_FONT
        self.plotter.installEventFilter(self)
        self._create_actors()
        for event in ("EndInteractionEvent", "MouseWheelForwardEvent", "MouseWheelBackwardEvent"):
            self.plotter.iren.add_observer(event, self._camera_moved)

        panel = QWidget(self)
        panel.setFixedWidth(340)
        col = QVBoxLayout(panel)
        self.counter = QLabel(panel)
        self.counter.setStyleSheet("color: #555; font-size: 11pt;")
        self.title = QLabel(panel)
        self.title.setWordWrap(True)
        self.title.setStyleSheet("font-size: 16pt; font-weight: bold;")
        self.description = QLabel(panel)
        self.description.setWordWrap(True)
        self.description.setStyleSheet("font-size: 12pt;")
        self.description.setAlignment(Qt.AlignmentFlag.AlignTop | Qt.AlignmentFlag.AlignLeft)
        self.slider = QSlider(Qt.Orientation.Horizontal, panel)
        self.slider.setTickPosition(QSlider.TickPosition.TicksBelow)
        self.slider.setTickInterval(1)
        self.slider.setPageStep(1)
        self.slider.setAccessibleName("Construction step")
        self.slider.valueChanged.connect(self.set_step)
        self.prev_button = QPushButton("◀ &Previous", panel)
        self.next_button = QPushButton("&Next ▶", panel)
        self.prev_button.setToolTip("Previous step (←, PgUp)")
        self.next_button.setToolTip("Next step (→, PgDn, Space)")
        self.prev_button.clicked.connect(self.previous_step)
        self.next_button.clicked.connect(self.next_step)
        buttons = QHBoxLayout()
        buttons.addWidget(self.prev_button)
        buttons.addWidget(self.next_button)

        form = QFormLayout()
        self.n_spin = QSpinBox(panel)
        self.n_spin.setRange(1, 64)
        self.n_spin.setToolTip("Segments per primary-triangle edge (the paper's n = 4)")
        self.n_spin.valueChanged.connect(
            lambda v: None if self._syncing else self.model.set_value("subdivisions", int(v))
        )
        self.diagonal = QComboBox(panel)
        self.diagonal.addItem("BC (paper)", "BC")
        self.diagonal.addItem("AD (Makarov)", "AD")
        self.diagonal.currentIndexChanged.connect(
            lambda i: (
                None
                if self._syncing
                else self.model.set_value("diagonal", self.diagonal.itemData(i))
            )
        )
        form.addRow("Subdivisions &n", self.n_spin)
        form.addRow("&Diagonal", self.diagonal)

        self.legend = QLabel(panel)
        self.legend.setTextFormat(Qt.TextFormat.RichText)
        self.legend.setText(self._legend_html())
        self.error = QLabel(panel)
        self.error.setWordWrap(True)
        self.error.setStyleSheet("color: #d0021b;")
        self.error.hide()

        col.addWidget(self.counter)
        col.addWidget(self.title)
        col.addWidget(self.description)
        col.addSpacing(8)
        col.addWidget(self.slider)
        col.addLayout(buttons)
        col.addSpacing(16)
        col.addLayout(form)
        col.addSpacing(8)
        col.addWidget(self.legend)
        col.addWidget(self.error)
        col.addStretch(1)

        row = QHBoxLayout(self)
        row.setContentsMargins(0, 0, 6, 6)
        row.addWidget(self.plotter, 1)
        row.addWidget(panel)

        for keys, slot in (
            (("Right", "PgDown", "Space", "N"), self.next_step),
            (("Left", "PgUp", "Backspace", "P"), self.previous_step),
            (("Home",), lambda: self.set_step(0)),
            (("End",), lambda: self.set_step(len(self.steps) - 1)),
        ):
            for key in keys:
                shortcut = QShortcut(QKeySequence(key), self)
                shortcut.setContext(Qt.ShortcutContext.WindowShortcut)
                shortcut.activated.connect(slot)

        self._add_presentation_key()
        self.resize(1200, 800)
        model.params_changed.connect(self._params_changed)
        self._follow_cells()
        self._syncing = False
        self.set_params(model.params)
        self._paint_empty_first()

    # -- actors (created once) -----------------------------------------------------------

    def _create_actors(self) -> None:
        p = self.plotter
        self.datasets: dict[str, pv.PolyData] = {name: pv.PolyData() for name in LAYERS}
        self.actors: dict[str, Any] = {}
        common = {"reset_camera": False, "lighting": False, "render": False, "pickable": False}
        for name in ("primary_0", "primary_1", "subtriangles"):
            self.actors[name] = p.add_mesh(self.datasets[name], color=COLORS[name], **common)
        for name in ("segments", "shared_edges", "highlight"):
            self.actors[name] = p.add_mesh(
                self.datasets[name],
                color=COLORS[name],
                line_width=WIDTHS[name],
                style="wireframe",
                **common,
            )
        for name in ("division_points", "points", "centroids"):
            self.actors[name] = p.add_mesh(
                self.datasets[name],
                color=COLORS[name],
                point_size=WIDTHS[name],
                style="points",
                render_points_as_spheres=True,
                **common,
            )
        self.label_points = pv.PolyData()
        self.label_mapper, self.actors["labels"] = add_text_labels(
            p, self.label_points, COLORS["labels"], LABEL_FONT, background_opacity=0.85
        )
        # a text actor at the size VTK's upper-edge corner annotation drew it (25 px at
        # every window size): the annotation searched its font size again at every new
        # text, re-opening the font each time, more than half of a step's time
        self.caption = p.add_text(
            "", position=(0.5, 1.0), viewport=True, font_size=TITLE_FONT, color="#202020"
        )
        self.caption.prop.font_size = CAPTION_PX
        self.caption.prop.justification_horizontal = "center"
        self.caption.prop.justification_vertical = "top"
        self._place_caption()
        # rulers in mm: the main view's (an empty scene whose only visible part they are)
        self.rulers = MeshScene(p, visible={name: False for name in SCENE_LAYERS})
        self.rulers.set_emphasis(RULER_EMPHASIS)
        # no axis titles (they would sit where the labels of the side points go): the
        # legend says the rulers are in mm
        self.rulers.axes.x_title = " "
        self.rulers.axes.y_title = " "

    @staticmethod
    def _legend_html() -> str:
        def swatch(colour: str, text: str) -> str:
            return f"<span style='color:{colour}'>■</span>&nbsp;{text}"

        return (
            "<div style='font-size:11pt; line-height:140%'>"
            + "<br>".join(
                [
                    swatch(COLORS["highlight"], "new lines of this step"),
                    swatch(COLORS["segments"], "lines so far"),
                    swatch(COLORS["points"], "labelled points"),
                    swatch(COLORS["centroids"], "centroids (quadrature points)"),
                    swatch(COLORS["shared_edges"], "shared edges: one RWG unknown each"),
                    "rulers: x and y in mm",
                ]
            )
            + "</div>"
        )

    # -- parameters and steps ------------------------------------------------------------

    def _params_changed(self, params: MeshParams) -> None:
        if not self._closed:
            self.set_params(params)

    def set_params(self, params: MeshParams) -> bool:
        """Rebuild the steps for ``params``; on failure keep the last good steps."""
        try:
            steps = construction_steps(params)
        except (ValueError, TypeError, MemoryError) as exc:
            self.error.setText(f"No construction for these parameters: {exc}")
            self.error.show()
            return False
        self.error.hide()
        self.params, self.steps = params, steps
        self._syncing = True
        self.n_spin.setValue(params.segments if params.scheme == "uniform" else 4)
        self.diagonal.setCurrentIndex(0 if params.diagonal == "BC" else 1)
        self.diagonal.setEnabled(params.structure != "triangle")
        self.slider.blockSignals(True)
        self.slider.setRange(0, len(steps) - 1)
        self.slider.blockSignals(False)
        self._syncing = False
        self.set_step(min(self.index, len(steps) - 1), force=True)
        return True

    def set_step(self, index: int, force: bool = False) -> None:
        """Show step ``index`` (0-based, clamped)."""
        if not self.steps or self._closed:
            return
        index = int(np.clip(index, 0, len(self.steps) - 1))
        if index == self.index and not force:
            return
        self.index = index
        step = self.steps[index]
        if self.slider.value() != index:
            self.slider.blockSignals(True)
            self.slider.setValue(index)
            self.slider.blockSignals(False)
        self.counter.setText(f"Step {index + 1} of {len(self.steps)}")
        self.title.setText(step.title)
        self.description.setText(step.description)
        self.prev_button.setEnabled(index > 0)
        self.next_button.setEnabled(index < len(self.steps) - 1)
        self._draw(step, index)
        self.step_changed.emit(index)

    def next_step(self) -> None:
        self.set_step(self.index + 1)

    def previous_step(self) -> None:
        self.set_step(self.index - 1)

    @property
    def labels(self) -> list[str]:
        """The labels drawn at the current step."""
        data = self.label_points
        if data.n_points == 0 or "label" not in data.point_data:
            return []
        return [str(s) for s in data.point_data["label"]]

    def _draw(self, step: ConstructionStep, index: int) -> None:
        assert self.params is not None  # set with the steps
        pts = np.asarray(self.steps[-1].points).reshape(-1, 2)
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        size = float(max(hi[0] - lo[0], hi[1] - lo[1], 1e-9))
        sets, anchors = step_datasets(self.params, step, index, size)
        for name in LAYERS:
            self.datasets[name].copy_from(sets[name], deep=True)
        self.label_anchors = anchors
        # a thin grid of many lines reads better thinner
        fine = self.params.segments > 8
        self.actors["segments"].prop.line_width = 1.0 if fine else WIDTHS["segments"]
        self.actors["highlight"].prop.line_width = 2.5 if fine else WIDTHS["highlight"]
        self.actors["shared_edges"].prop.line_width = 2.0 if fine else WIDTHS["shared_edges"]
        self.actors["centroids"].prop.point_size = 4.0 if fine else WIDTHS["centroids"]
        self.actors["points"].prop.point_size = 9.0 if fine else WIDTHS["points"]
        self.actors["division_points"].prop.point_size = 5.0 if fine else WIDTHS["division_points"]
        self.caption.SetInput(f"{index + 1}/{len(self.steps)}  {step.title}")
        key = (round(float(lo[0]), 9), round(float(lo[1]), 9), round(size, 9))
        if key != self._frame_key:
            self._frame_key = key
            self._frame_bounds = (lo, hi)
            self.rulers.show_rulers((lo[0], hi[0], lo[1], hi[1]))
            self.frame(lo, hi)
        self.place_labels()
        self.plotter.update()  # one paint, by the widget (a render here drew it twice)

    def place_labels(self, *_args: Any) -> None:
        """Put every label just outside its point, at the current zoom."""
        anchors = getattr(self, "label_anchors", None)
        if anchors is None or anchors.n_points == 0:
            self.label_points.copy_from(pv.PolyData(), deep=True)
            self.label_mapper.Modified()
            return
        camera = self.plotter.camera
        height = max(self.plotter.window_size[1], 1)
        world_per_px = 2.0 * camera.parallel_scale / height
        labels = [str(s) for s in anchors.point_data["label"]]
        extra = np.zeros((len(labels), 2))
        direction = np.array(anchors.point_data["direction"], dtype=np.float64)
        if self._frame_bounds is not None:  # clear of the rulers' tick labels
            lo, hi = self._frame_bounds
            tol = 1e-9 * float(max(hi[0] - lo[0], hi[1] - lo[1], 1e-9))
            xy = anchors.points[:, :2]
            left = np.abs(xy[:, 0] - lo[0]) <= tol
            bottom = np.abs(xy[:, 1] - lo[1]) <= tol
            inner_x = (xy[:, 0] > lo[0] + tol) & (xy[:, 0] < hi[0] - tol)
            inner_y = (xy[:, 1] > lo[1] + tol) & (xy[:, 1] < hi[1] - tol)
            extra[left, 0] = RULER_CLEARANCE["left"]
            extra[bottom, 1] = RULER_CLEARANCE["bottom"]
            # inside a ruled side, straight out past the tick label at the same place
            direction[left & inner_y] = (-1.0, 0.0)
            direction[bottom & inner_x] = (0.0, -1.0)
        offsets = label_offsets(labels, direction, self.label_font, 0.6 * WIDTHS["points"], extra)
        moved = anchors.copy(deep=True)
        moved.points[:, :2] += offsets * world_per_px
        self.label_points.copy_from(moved, deep=True)
        self.label_mapper.Modified()

    def eventFilter(self, watched: Any, event: QEvent) -> bool:  # noqa: N802 - Qt's name
        if (
            watched is self.plotter
            and event.type() == QEvent.Type.Resize
            and self._frame_bounds is not None
            and not self._closed
        ):
            QTimer.singleShot(0, self._refit)
        return super().eventFilter(watched, event)

    def refit(self) -> None:
        self._refit()

    def _place_caption(self) -> None:
        """The caption centred at the top, :data:`CAPTION_TOP_PX` below the view's edge."""
        height = max(self.plotter.window_size[1], 1)
        self.caption.SetPosition(0.5, 1.0 - CAPTION_TOP_PX / height)

    def _refit(self) -> None:
        if self._closed or self._frame_bounds is None:
            return
        self._place_caption()
        self.frame(*self._frame_bounds)
        self.place_labels()
        self.plotter.update()

    def _camera_moved(self, *_args: Any) -> None:
        self.place_labels()
        self.plotter.update()

    def frame(self, lo: np.ndarray, hi: np.ndarray) -> None:
        """Fit the whole patch, its rulers and room for its labels, from above (kept for
        every step)."""
        p = self.plotter
        size = float(max(hi[0] - lo[0], hi[1] - lo[1], 1e-9))
        (rx0, rx1, _), (ry0, ry1, _) = nice_span(lo[0], hi[0]), nice_span(lo[1], hi[1])
        # the rulers' labels and, past them, the point labels sit left and below; the
        # caption sits on top
        x0, x1 = min(lo[0], rx0) - 0.24 * size, max(hi[0], rx1) + 0.12 * size
        y0, y1 = min(lo[1], ry0) - 0.2 * size, max(hi[1], ry1) + 0.2 * size
        p.view_xy(render=False)
        p.enable_parallel_projection()
        camera = p.camera
        cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
        camera.focal_point = (cx, cy, 0.0)
        camera.position = (cx, cy, 10.0 * size)
        camera.up = (0.0, 1.0, 0.0)
        w, h = (max(v, 1) for v in p.window_size)
        camera.parallel_scale = max((y1 - y0) / 2, (x1 - x0) / 2 * h / w)
        p.renderer.ResetCameraClippingRange()
