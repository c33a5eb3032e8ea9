"""GUI thread only: the one place a mesh result becomes what the 3D view draws.

A result of the model carries its scene data (:mod:`barymesh.app.view.scene_data`: numpy
arrays made in a worker thread), or none yet. :class:`ScenePresenter` decides what the
view shows of it and when:

* the scene data of a new mesh (made here if the worker made none), for the Detail
  choice (a dense mesh's image, or its every triangle), written back to
  ``MeshResult.scene`` so that Undo back to it shows the same data at once;
* the requests to the meshing controller, each with a token that a newer request
  replaces: the full detail of the part in view once the camera rests, and the scene
  again when a colouring needs per-triangle values the image was made without;
* the render requests: a new mesh's first paint from a timer (the event loop gets a turn
  between the new datasets and their render), a camera at rest, a finished request.

It gets the plotter, the scene's actors (:class:`barymesh.app.view.scene.MeshScene`) and
the model; what the window does around a new mesh (the tools told, the camera framed)
it passes in as two callables, so the presenter never sees the window.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from PySide6.QtCore import QEvent, QObject, QTimer
from PySide6.QtWidgets import QApplication, QWidget

from barymesh import TriMesh
from barymesh.app.model import AppModel, MeshResult
from barymesh.app.view.framing import CameraWatch, rect_inside, visible_rect
from barymesh.app.view.overview import DETAIL_TRIANGLES
from barymesh.app.view.scene_data import needs_triangles, scene_data
from barymesh.app.worker import MeshController, release_memory

#: A new mesh above this many triangles (or after one) hands its freed pages back to the
#: system; trimming after every small mesh would only cost time.
RELEASE_TRIANGLES = 200_000


class PaintCounter(QObject):
    """Counts the paint events of a widget (``paints``) and when the last one came;
    ``after_paint`` is called once each paint is done (from the event loop)."""

    def __init__(self, widget: QWidget, after_paint: Callable[[], None] | None = None) -> None:
        super().__init__(widget)
        self.paints = 0
        self.last = 0.0
        self.after_paint = after_paint
        widget.installEventFilter(self)

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:  # noqa: N802 - Qt's name
        if event.type() == QEvent.Type.Paint:
            self.paints += 1
            self.last = time.perf_counter()
            if self.after_paint is not None:
                QTimer.singleShot(0, self, self.after_paint)  # after the paint itself
        return False


class ScenePresenter(QObject):
    """The scene of one window's 3D view: its data, its requests and its paints.

    Parameters
    ----------
    plotter : pyvistaqt.QtInteractor
        The 3D view: its size (the image of a dense mesh), its paints, its camera.
    scene : barymesh.app.view.scene.MeshScene
        The actors the scene data goes into.
    model : AppModel
        The result on screen, the Detail choice and the colouring.
    mesh_changed : callable
        ``mesh_changed(mesh)``: a new mesh is in the scene (the window tells its tools).
    frame : callable
        ``frame()``: frame the mesh from above (the window knows the margins its panels
        keep); called when a new mesh is another structure, much larger or smaller, or
        grew out of a view that held the last one.
    parent : QObject
        Owns the presenter and its timers (the window).

    Notes
    -----
    The meshing controller is made after the panels (its signals follow theirs), so it is
    given later, by :meth:`attach_controller`.
    """

    def __init__(
        self,
        plotter: Any,
        scene: Any,
        model: AppModel,
        *,
        mesh_changed: Callable[[TriMesh], None],
        frame: Callable[[], None],
        parent: QObject,
    ) -> None:
        super().__init__(parent)
        self.plotter, self.scene, self.model = plotter, scene, model
        self.mesh_changed, self.frame = mesh_changed, frame
        self.controller: MeshController | None = None
        self.closed = False
        self._camera_key: tuple[Any, ...] | None = None
        self._camera_bounds: np.ndarray | None = None
        #: seconds the last new mesh took on the GUI thread, from its data to its actors
        self.last_frame_seconds = 0.0
        self.paint_counter = PaintCounter(plotter)  # one paint per new mesh
        #: the scene data in the actors (a result's ``scene`` when it is on screen)
        self.shown_scene: Any = None
        self._last_triangles = 0
        # once the camera rests, the part in view of a dense mesh gets its full detail
        self.rest_timer = QTimer(self)
        self.rest_timer.setSingleShot(True)
        self.rest_timer.setInterval(250)
        self.rest_timer.timeout.connect(self.camera_rested)
        self._detail_token: tuple[int, tuple[float, ...]] | None = None
        self._paint_timer = QTimer(self)  # a new mesh's first paint (see show)
        self._paint_timer.setSingleShot(True)
        self._paint_timer.setInterval(1)
        self._paint_timer.timeout.connect(self._paint_new_mesh)
        self._painted_before: int | None = None  # paints when a new mesh came
        # any camera change drawn (a key, Zoom to selection, a tool's zoom), not only the
        # mouse's: the detail is asked for once it rests
        self.camera_watch = CameraWatch(plotter, self._camera_drawn)
        self._scene_token: tuple[int, str] | None = None

    def attach_controller(self, controller: MeshController) -> None:
        """Ask ``controller`` for detail and scene data, and tell it of each paint (a
        build's result may wait for the paint of the mesh before it)."""
        self.controller = controller
        controller.paint_pending = lambda: self.paint_pending
        self.paint_counter.after_paint = self._view_painted
        controller.detail_ready.connect(self._detail_ready)
        controller.scene_ready.connect(self._scene_ready)

    def close(self) -> None:
        """The window closes: nothing more is drawn or asked for."""
        self.closed = True
        self.rest_timer.stop()

    def request_render(self) -> None:
        """Schedule one repaint of the 3D view.

        pyvistaqt's widget renders the scene in its paintGL anyway; calling
        ``plotter.render()`` as well would draw every frame twice.
        """
        self.plotter.update()

    # -- a new mesh ------------------------------------------------------------------------

    def show(self, result: MeshResult) -> None:
        """Put ``result`` in the view: its scene data in the actors (unless they hold it
        already: Undo back to the mesh on screen), the camera framed if the mesh is
        another, and its first paint asked for once the panels have relaid out."""
        assert result.mesh is not None  # a result shown holds its mesh
        start = time.perf_counter()
        if result.scene is None:
            result.scene = scene_data(result.mesh)
        result.scene = self.scene_for_detail(result)
        same = result.scene is self.shown_scene  # Undo back to the mesh on screen
        self.shown_scene = result.scene
        self._detail_token = None
        if not same:
            self.scene.update(result.scene)
            self.complete_scene(result)
            self.mesh_changed(result.mesh)
        p = result.params
        key = (
            result.source,
            p.structure if p else None,
            result.cell.name if result.cell is not None else None,
        )
        bounds = np.asarray(result.scene.bounds)
        if key != self._camera_key or self._bounds_jumped(bounds) or self._left_view(bounds):
            self.frame()
        self._camera_key, self._camera_bounds = key, bounds
        if not same:
            # panels that grew with the new numbers relayout now, not after the paint:
            # then the view is painted once, at its final size
            painted = self.paint_counter.paints
            for _ in range(6):  # label -> panel -> dock -> window: one level per round
                QApplication.sendPostedEvents(None, QEvent.Type.LayoutRequest)
            if self.paint_counter.paints == painted:  # a resize may have painted it already
                # painted from a timer: the event loop gets a turn between the new
                # datasets and their first render (two blocks, not one of both)
                self._painted_before = painted
                self._paint_timer.start()
            # after a large mesh its arrays are free now: hand the pages back (off this
            # thread; trimming after every small mesh would only cost time)
            big = max(result.mesh.n_triangles, self._last_triangles) > RELEASE_TRIANGLES
            self._last_triangles = result.mesh.n_triangles
            if big:
                QTimer.singleShot(
                    0, lambda: threading.Thread(target=release_memory, daemon=True).start()
                )
            if self.scene.reduced:
                self.rest_timer.start()
        self.last_frame_seconds = time.perf_counter() - start

    def _paint_new_mesh(self) -> None:
        if not self.closed and self.paint_counter.paints == self._painted_before:
            self.request_render()

    def _view_painted(self) -> None:
        if not self.closed and self.controller is not None:
            self.controller.painted()  # a build's result may wait for this paint

    @property
    def paint_pending(self) -> bool:
        """Whether the mesh on screen still waits for its first paint (asked for by a
        1 ms timer after it came, see :meth:`show`)."""
        return self.paint_counter.paints == self._painted_before and self.plotter.isVisible()

    def _bounds_jumped(self, bounds: np.ndarray) -> bool:
        old = self._camera_bounds
        if old is None:
            return True
        size_old = max(old[1] - old[0], old[3] - old[2], 1e-12)
        size_new = max(bounds[1] - bounds[0], bounds[3] - bounds[2], 1e-12)
        return not 0.8 <= size_new / size_old <= 1.25

    def _left_view(self, bounds: np.ndarray) -> bool:
        """Whether the new mesh leaves the view the old one was wholly inside (a patch
        grown past the view's edge): then the view frames it again."""
        old = self._camera_bounds
        if old is None:
            return False
        view = visible_rect(self.plotter)
        return rect_inside(old, view) and not rect_inside(bounds, view)

    # -- detail and colouring ------------------------------------------------------------------

    def scene_for_detail(self, result: MeshResult) -> Any:
        """The scene data of ``result`` for the Detail choice: "full" draws a dense mesh's
        every triangle (built here, on the GUI thread: the choice warns of its cost);
        "auto" goes back to the image of a mesh built so."""
        scene, mesh = result.scene, result.mesh
        assert mesh is not None  # a result shown holds its mesh
        if self.model.detail == "full" and scene.overview is not None:
            return scene_data(
                mesh, detail_limit=max(mesh.n_triangles, 1), color_by=self.model.color_by
            )
        if (
            self.model.detail == "auto"
            and scene.overview is None
            and mesh.n_triangles > DETAIL_TRIANGLES
        ):
            return scene_data(
                mesh, color_by=self.model.color_by, pixels=tuple(self.plotter.window_size)
            )
        return scene

    def set_detail(self, mode: str) -> None:
        """The Detail choice changed: the mesh on screen is drawn so."""
        if self.closed:
            return
        self.scene.set_detail(mode)
        result = self.model.result
        if result is not None and result.mesh is not None and result.scene is not None:
            scene = self.scene_for_detail(result)
            if scene is not result.scene:
                result.scene = scene
                self.shown_scene = scene
                self._detail_token = None
                self.scene.update(scene)
        self.request_render()

    def set_color_by(self, key: str) -> None:
        """The faces are coloured by ``key`` (made again by the worker if the image of a
        dense mesh lacks its values, :meth:`complete_scene`); the caller renders."""
        self.scene.set_color_by(key)
        if self.model.result is not None:
            self.complete_scene(self.model.result)

    def complete_scene(self, result: MeshResult) -> None:
        """A dense paper mesh's image is made without per-triangle values while it is
        shown solid or by patch count (:func:`barymesh.app.view.scene_data.scene_data`): a
        colouring that needs them has the worker make the scene again (plain until it
        comes)."""
        key = self.model.color_by
        if result.mesh is None or not needs_triangles(self.scene.overview, key):
            return
        token = (result.generation, key)
        if token != self._scene_token and self.controller is not None:
            self._scene_token = token
            self.controller.request_scene(result.mesh, token)

    def _scene_ready(self, payload: tuple[Any, Any]) -> None:
        token, data = payload
        if token != self._scene_token:
            return  # a newer request is out
        self._scene_token = None
        result = self.model.result
        if (
            self.closed
            or data is None
            or result is None
            or (result.generation, self.model.color_by) != token
        ):
            return
        result.scene = data
        self.shown_scene = data
        self._detail_token = None
        self.scene.update(data)
        if self.scene.reduced:
            self.rest_timer.start()  # the detail of the part in view, coloured so
        self.request_render()

    # -- the camera at rest --------------------------------------------------------------------

    def camera_moved(self) -> None:
        """The mouse moved the camera: what is drawn follows when it rests."""
        self.rest_timer.start()

    def _camera_drawn(self) -> None:
        if not self.closed:
            self.rest_timer.start()

    def camera_rested(self) -> None:
        """The camera rests: the rulers follow the view, and the full detail of the part
        in view of a dense mesh is asked for (in a thread)."""
        if self.closed:
            return
        if self.scene.settle():
            self.request_render()
        result = self.model.result
        if result is None or result.mesh is None or not self.scene.reduced:
            return
        rect = self.scene.wanted_detail()
        if rect is None or self.controller is None:
            return
        token = (result.generation, rect)
        self._detail_token = token
        self.controller.request_detail(result.mesh, rect, token)

    def _detail_ready(self, payload: tuple[Any, Any]) -> None:
        token, data = payload
        if self.closed or token != self._detail_token or data is None:
            return
        self.scene.show_detail(data)
        self.request_render()
