"""Teach → Paper vs conforming: the same parameters meshed both ways, side by side.

One ``QtInteractor`` with two subplots (``shape=(1, 2)``) whose cameras are linked
(``link_views``), each holding a :class:`barymesh.app.view.scene.MeshScene`, and under each half its
statistics: triangles, vertices, interior edges (the RWG unknowns), boundary edges and
the overlap ratio. In paper mode the faces covered by two or more patches are shaded, so
a student sees where the overlapping patches fail to share edges.

The window follows the main window's parameters; both meshes are built in a worker
thread, and a mode the core refuses (a conforming double ring whose rings overlap, say)
shows its message in its half while the other half still draws.
"""

from __future__ import annotations

import dataclasses
import logging
import os
import sys
import threading
from functools import partial
from typing import Any

import numpy as np
import pyvista as pv
from PySide6.QtCore import Qt, QTimer, Signal
from PySide6.QtWidgets import QHBoxLayout, QLabel, QVBoxLayout, QWidget

from barymesh import MeshParams, TriMesh
from barymesh.app.jobs import Jobs
from barymesh.app.model import AppModel, MeshResult, compute
from barymesh.app.teach.following_view import FollowingView
from barymesh.app.view.framing import frame_from_above
from barymesh.app.view.gl_info import tune_multi_samples
from barymesh.app.view.polydata import Layer
from barymesh.app.view.scene import MeshScene
from barymesh.app.view.scene_data import scene_data

log = logging.getLogger(__name__)

MODES = ("paper", "conforming")
TITLES = {
    "paper": "Paper mode: overlapping patches",
    "conforming": "Conforming mode: one watertight mesh",
}
#: Faces covered by 2 and by 3 or more patches (drawn just over the faces, under every
#: edge layer: the triangle and shared edges of overlapping patches stay visible on the
#: shading, where they tangle).
COVERAGE_COLORS = ("#c6b9e4", "#7a5fb5")
#: Coverage is computed when triangles × patches stays below this (a few hundred ms).
COVERAGE_LIMIT = 100_000_000
_CHUNK = 4_000_000
LAYERS_SHOWN = {"labels": False, "patch_outlines": False, "centroids": False}


def patch_coverage(mesh: TriMesh) -> np.ndarray | None:
    """How many paper-mode patches cover each triangle's centroid.

    Returns
    -------
    (T,) int32, or None
        None when the mesh has no patch rectangles (conforming) or the count would take
        too long (more than :data:`COVERAGE_LIMIT` triangle–patch pairs).
    """
    rects = mesh.patch_rects
    if rects is None or len(rects) == 0 or mesh.n_triangles == 0:
        return None
    rects = np.asarray(rects, dtype=np.float64)
    if mesh.n_triangles * len(rects) > COVERAGE_LIMIT:
        return None
    c = np.asarray(mesh.centroids)[:, :2]
    out = np.zeros(len(c), dtype=np.int32)
    step = max(1, _CHUNK // len(rects))
    for lo in range(0, len(c), step):
        x = c[lo : lo + step, 0:1]
        y = c[lo : lo + step, 1:2]
        inside = (x > rects[:, 0]) & (x < rects[:, 2]) & (y > rects[:, 1]) & (y < rects[:, 3])
        out[lo : lo + step] = inside.sum(axis=1)
    return out


def coverage_faces(mesh: TriMesh, coverage: np.ndarray | None, dz: float) -> Layer:
    """Faces covered by two or more patches, with a cell array ``coverage`` (2 or 3 = 3+)
    (plain arrays, made in the worker; only the points those faces use)."""
    if coverage is None:
        return Layer()
    keep = coverage >= 2
    if not keep.any():
        return Layer()
    tri = np.asarray(mesh.triangles)[keep]
    used, local = np.unique(tri, return_inverse=True)
    pts = np.array(np.asarray(mesh.points)[used], dtype=np.float64)
    pts[:, 2] += dz
    return Layer(
        pts,
        faces=local.reshape(tri.shape).astype(np.int64),
        cell_data={"coverage": np.minimum(coverage[keep], 3).astype(np.float64)},
    )


@dataclasses.dataclass
class Half:
    """What one half shows: a result (mesh, stats, scene data) or an error."""

    mode: str
    result: MeshResult | None = None
    error: str | None = None
    overlap: Layer | None = None
    covered: float | None = None  # fraction of the triangles covered twice or more
    covered3: float | None = None  # fraction covered three times or more


def compute_half(params: MeshParams, mode: str) -> Half:
    """Mesh ``params`` in ``mode`` (never raises; errors come back as text)."""
    try:
        p = dataclasses.replace(params, mode=mode)
    except (ValueError, TypeError) as exc:
        return Half(mode, error=str(exc))
    result = compute(p, prepare=scene_data)
    if result.error is not None:
        return Half(mode, error=result.error)
    assert result.mesh is not None  # no error: a mesh
    half = Half(mode, result)
    if mode == "paper":
        coverage = patch_coverage(result.mesh)
        size = max(
            result.scene.bounds[1] - result.scene.bounds[0],
            result.scene.bounds[3] - result.scene.bounds[2],
            1e-9,
        )
        # just above the faces (z = 0), under every edge layer (from 1e-4 of the size up)
        half.overlap = coverage_faces(result.mesh, coverage, 0.8e-4 * size)
        if coverage is not None:
            half.covered = float(np.mean(coverage >= 2))
            half.covered3 = float(np.mean(coverage >= 3))
    return half


#: A build still running after this long (ms) says so under the halves.
BUSY_NOTE_MS = 300
#: The nice value of the compare window's worker thread (Linux): its meshing yields
#: the cores to the GUI thread and to llvmpipe's render threads, which draw the main
#: window's new mesh at the same time (on two cores they shared them evenly).
WORKER_NICE = 10


def background_priority() -> None:
    """Lower the calling thread's scheduling priority to :data:`WORKER_NICE` (Linux
    only: a thread's nice value is its own there; elsewhere nothing happens)."""
    if not hasattr(os, "setpriority") or not sys.platform.startswith("linux"):
        return
    try:
        tid = threading.get_native_id()
        if os.getpriority(os.PRIO_PROCESS, tid) < WORKER_NICE:
            os.setpriority(os.PRIO_PROCESS, tid, WORKER_NICE)
    except OSError:  # not allowed: the thread keeps its priority
        pass


def compute_halves(params: MeshParams, generation: int) -> tuple[int, list[Half]]:
    """Both halves for ``params`` (runs on a worker thread, at a lowered priority),
    tagged with ``generation``."""
    background_priority()
    return generation, [compute_half(params, mode) for mode in MODES]


def stats_html(half: Half) -> str:
    """The statistics under one half, as rich text."""
    if half.error is not None:
        return f"<span style='color:#d0021b'>{half.error}</span>"
    assert half.result is not None  # no error: a result
    s = half.result.stats
    t, n = s["triangles"], s["interior_edges"]
    rows = [
        ("Triangles", f"{t:,}"),
        ("Vertices", f"{s['vertices']:,}"),
        ("Interior edges = RWG unknowns N", f"<b>{n:,}</b>"),
        ("Boundary edges", f"{s['boundary_edges']:,}"),
        ("Shared edges per triangle", f"{n / t:.2f}" if t else "–"),
    ]
    if s.get("junction_edges"):
        rows.append(
            ("Junction edges", f"<span style='color:#d0021b'>{s['junction_edges']:,}</span>")
        )
    ratio = s.get("overlap_ratio")
    rows.append(("Overlap ratio", "–" if ratio is None else f"{100 * ratio:.1f} %"))
    if half.covered is not None:
        # the legend of the shading: one swatch, one count each
        three = half.covered3 or 0.0
        rows.append(("Triangles under 2+ patches", f"{100 * half.covered:.1f} %"))
        rows.append(
            (
                f"<span style='color:{COVERAGE_COLORS[0]}'>■</span> under 2 patches",
                f"{100 * (half.covered - three):.1f} %",
            )
        )
        rows.append(
            (
                f"<span style='color:{COVERAGE_COLORS[1]}'>■</span> under 3 or more",
                f"{100 * three:.1f} %",
            )
        )
    body = "".join(f"<tr><td>{k}</td><td align='right'>&nbsp;&nbsp;{v}</td></tr>" for k, v in rows)
    return f"<table cellspacing='1'>{body}</table>"


class CompareView(FollowingView):
    """Paper and conforming mode side by side (see the module docstring).

    Parameters
    ----------
    model : AppModel
        The main window's model; the view follows its parameters.
    parent : QWidget, optional
    """

    shown = Signal()  # both halves drawn for the latest parameters

    def __init__(self, model: AppModel, parent: QWidget | None = None) -> None:
        super().__init__(parent, Qt.WindowType.Window)
        from pyvistaqt import QtInteractor

        self.model = model
        self.setObjectName("compare")
        self.setWindowTitle("barymesh – paper vs conforming")
        self._closed = False
        self.generation = 0
        self.shown_generation = -1
        self.halves: dict[str, Half] = {}
        self._camera_key: tuple[Any, ...] | None = None
        self._drawn_once = False
        self._shown_later: int | None = None  # a generation drawn, its second half pending

        self.plotter = QtInteractor(
            self,
            shape=(1, 2),
            auto_update=False,
            border=True,
            border_color="#c8c8c8",
            border_width=1.0,
        )
        tune_multi_samples(self.plotter)  # no MSAA on llvmpipe: a render costs 8x less
        self.plotter.setMinimumSize(640, 360)
        for key in ("q", "e"):
            self.plotter.clear_events_for_key(key, raise_on_missing=False)
        self.scenes: dict[str, MeshScene] = {}
        self.overlays: dict[str, pv.PolyData] = {}
        self.messages: dict[str, Any] = {}
        for col, mode in enumerate(MODES):
            self.plotter.subplot(0, col)
            scene = MeshScene(self.plotter, visible=LAYERS_SHOWN)
            self.scenes[mode] = scene
            self.plotter.add_text(
                TITLES[mode], position=(0.03, 0.93), viewport=True, font_size=10, color="#202020"
            )
            self.messages[mode] = self.plotter.add_text(
                "", position=(0.05, 0.45), viewport=True, font_size=12, color="#d0021b"
            )
            if mode == "paper":
                self.overlays[mode] = pv.PolyData()
                actor = self.plotter.add_mesh(
                    self.overlays[mode],
                    scalars=None,
                    reset_camera=False,
                    lighting=False,
                    render=False,
                    pickable=False,
                    color=COVERAGE_COLORS[0],
                )
                actor.mapper.lookup_table = pv.LookupTable(
                    cmap=[COVERAGE_COLORS[0], COVERAGE_COLORS[1]], n_values=2
                )
                actor.mapper.SetScalarModeToUseCellFieldData()
                actor.mapper.SelectColorArray("coverage")
                actor.mapper.SetScalarRange(1.5, 3.5)
                actor.mapper.lookup_table.scalar_range = (1.5, 3.5)
                actor.mapper.SetScalarVisibility(True)
                self.overlay_actor = actor
        self.plotter.link_views()
        self.plotter.subplot(0, 0)
        self.plotter.enable_parallel_projection()
        self.plotter.view_xy(render=False)
        for event in ("EndInteractionEvent", "MouseWheelForwardEvent", "MouseWheelBackwardEvent"):
            self.plotter.iren.add_observer(event, self._camera_moved)

        self.stats: dict[str, QLabel] = {}
        row = QHBoxLayout()
        row.setContentsMargins(12, 4, 12, 8)
        for mode in MODES:
            label = QLabel(self)
            label.setTextFormat(Qt.TextFormat.RichText)
            label.setWordWrap(True)
            label.setStyleSheet("font-size: 12pt;")
            label.setAlignment(Qt.AlignmentFlag.AlignTop | Qt.AlignmentFlag.AlignLeft)
            label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
            _reserve_stats_height(label)
            self.stats[mode] = label
            row.addWidget(label, 1)
        self.status = QLabel(self)
        self.status.setStyleSheet("color: #555;")
        # "meshing…" only for a build that lasts: a label change repaints the whole
        # window through GL, the 3D view included (tens of ms on llvmpipe)
        self._busy_note = QTimer(self)
        self._busy_note.setSingleShot(True)
        self._busy_note.setInterval(BUSY_NOTE_MS)
        self._busy_note.timeout.connect(lambda: self.status.setText("meshing both modes…"))
        col_layout = QVBoxLayout(self)
        col_layout.setContentsMargins(0, 0, 0, 0)
        col_layout.addWidget(self.plotter, 1)
        col_layout.addLayout(row)
        col_layout.addWidget(self.status)

        self.jobs = Jobs(self, name="barymesh-compare")  # one pair of meshes at a time
        self._running = False
        self._pending: MeshParams | None = None
        self._frame_bounds: tuple[float, float, float, float] | None = None
        self._add_presentation_key()
        self.resize(1400, 800)
        model.params_changed.connect(self._params_changed)
        self._follow_cells()
        self.request(model.params)

    # -- meshing -------------------------------------------------------------------------

    def _params_changed(self, params: MeshParams) -> None:
        if not self._closed:
            self.request(params)

    def request(self, params: MeshParams) -> None:
        """Mesh ``params`` both ways in the worker (the latest request wins)."""
        self.generation += 1
        self._pending = params
        if not self.status.text():
            self._busy_note.start()
        self._start()

    def _start(self) -> None:
        if self._running or self._pending is None or self._closed:
            return
        params, self._pending = self._pending, None
        self._running = True
        self.jobs.submit(partial(compute_halves, params, self.generation), self._finished)

    def _finished(self, payload: tuple[int, list[Half]]) -> None:
        self._running = False
        if self._closed:
            return
        generation, halves = payload
        if self._pending is not None:
            self._start()  # a newer request is waiting: this result is stale
            return
        self.show_halves(halves)
        self._busy_note.stop()
        if self.status.text():
            self.status.setText("")
        if self._unrevealed:  # the first meshes: shown once the second half is drawn
            self._shown_later = generation
        else:
            self._mark_shown(generation)

    def _mark_shown(self, generation: int) -> None:
        self.shown_generation = generation
        self.shown.emit()

    def _reveal(self) -> None:
        super()._reveal()
        generation, self._shown_later = self._shown_later, None
        if generation is not None and not self._closed:
            self._mark_shown(generation)

    @property
    def busy(self) -> bool:
        """Whether meshes are being made or drawn (the first's second half waits for its
        pass: :meth:`_reveal`)."""
        return self._running or self._pending is not None or self._shown_later is not None

    # -- drawing -------------------------------------------------------------------------

    def show_halves(self, halves: list[Half]) -> None:
        """Draw both halves (datasets copied into the existing actors) and one render."""
        bounds = []
        for col, half in enumerate(halves):
            self.halves[half.mode] = half
            self.plotter.subplot(0, col)
            scene = self.scenes[half.mode]
            message = self.messages[half.mode]
            if half.error is not None:
                for actor in scene.actors.values():
                    actor.SetVisibility(False)
                scene.axes.SetVisibility(False)
                scene.scalar_bar.SetVisibility(False)
                message.SetInput(_wrapped(f"Cannot mesh in {half.mode} mode:\n{half.error}"))
                message.SetVisibility(True)
                if half.mode in self.overlays:
                    self.overlays[half.mode].copy_from(pv.PolyData(), deep=True)
            else:
                assert half.result is not None  # no error: a result
                message.SetVisibility(False)
                scene.update(half.result.scene)  # each half with its rulers in mm
                bounds.append(half.result.scene.bounds)
                if half.mode in self.overlays:
                    overlap = half.overlap.polydata() if half.overlap is not None else pv.PolyData()
                    self.overlays[half.mode].copy_from(overlap, deep=True)
            self.stats[half.mode].setText(
                f"<b style='font-size:13pt'>{TITLES[half.mode]}</b><br>{stats_html(half)}"
            )
        if not self._drawn_once:  # the first meshes: the conforming half a pass later
            self._drawn_once = True
            self._draw_in_two_passes([self.plotter.renderers[1]])
        if bounds:
            b = np.asarray(bounds)
            union = (b[:, 0].min(), b[:, 1].max(), b[:, 2].min(), b[:, 3].max())
            key = tuple(round(float(v), 6) for v in union)
            if key != self._camera_key:
                self._camera_key = key
                self.frame(union)
        self._camera_moved()

    def frame(self, bounds: tuple[float, float, float, float]) -> None:
        """Both halves from above on the union of their extents (linked cameras), fitted
        to a half's width and height, rulers included."""
        self._frame_bounds = bounds
        self.plotter.subplot(0, 0)
        frame_from_above(self.plotter, bounds, top=0.1)  # room for the half's title

    def refit(self) -> None:
        if not self._closed and self._frame_bounds is not None:
            self.frame(self._frame_bounds)
            self._camera_moved()

    def _camera_moved(self, *_args: Any) -> None:
        if self._closed:
            return
        for col, mode in enumerate(MODES):
            self.plotter.subplot(0, col)
            if self.halves.get(mode) is not None and self.halves[mode].error is None:
                self.scenes[mode].fit_marker_sizes()
        self.plotter.subplot(0, 0)
        self.plotter.update()  # one paint, by the widget (a render here drew it twice)

    def stats_of(self, mode: str) -> dict[str, Any] | None:
        """The statistics shown for ``mode`` (None when that mode failed)."""
        half = self.halves.get(mode)
        return None if half is None or half.result is None else half.result.stats

    def _stop(self) -> None:
        self._busy_note.stop()
        self._pending = self._shown_later = None
        self.jobs.close()  # a running pair winds down in its thread; its result goes nowhere


#: The rows of a paper half's statistics: five counts, the overlap ratio and the three
#: coverage rows (junction edges add one more, rarely).
STATS_ROWS = 9


def _reserve_stats_height(label: QLabel) -> None:
    """Give ``label`` the height of the tallest statistics at once: the 3D view above
    keeps its size when the first statistics come (else it is resized and painted twice,
    shaders compiled the first time, right after the meshes)."""
    row = "<tr><td>Triangles under 2+ patches</td><td align='right'>&nbsp;&nbsp;100.0 %</td></tr>"
    label.setText(
        f"<b style='font-size:13pt'>{TITLES['paper']}</b><br>"
        f"<table cellspacing='1'>{row * STATS_ROWS}</table>"
    )
    label.setMinimumHeight(label.sizeHint().height())
    label.setText("")


def _wrapped(text: str, width: int = 48) -> str:
    """Break long error messages into lines for the 3D view."""
    import textwrap

    return "\n".join(textwrap.fill(line, width) for line in text.splitlines())
