"""Meshing without freezing the window: coalesced requests, worker threads, cancellation.

:class:`MeshController` listens to ``AppModel.params_changed``. Requests arriving in one
burst (a slider drag) are coalesced by a zero-delay timer: the latest parameters win.
Small meshes (up to :data:`SYNC_TRIANGLES`) are built on the GUI thread, faster than a
thread hop; larger ones in a worker thread that also computes the statistics and the
scene arrays (:func:`barymesh.app.view.scene_data.scene_data`), while the window keeps answering.

A newer request (for a build of :data:`CANCEL_TRIANGLES` or more; a shorter one
finishes and is shown first), Undo or :meth:`MeshController.cancel` abandons the running
build cooperatively: its ``cancel`` callable (checked by ``barymesh.build_mesh`` between its
stages and by :func:`barymesh.app.model.compute` between build, statistics and scene) returns
True, and the new build starts at once beside it; at most one abandoned build winds
down at a time. Parameters equal to those of the mesh on screen (Undo of a change still
being built) need no build at all; those of one of the last few small meshes
(:data:`RECENT_COUNT`, Undo after a cancel) only the mesh, with the scene kept. Results
that are no longer the model's latest generation are dropped by ``AppModel.set_result``.

:meth:`MeshController.estimate` predicts a build's time from the speed of the recent
large builds on this machine (triangles per second).

A build's result that comes while the view has yet to paint the one before it waits for
that paint (:attr:`MeshController.paint_pending`, :meth:`MeshController.painted`): a
result is delivered by a posted event, and Qt handled it in the same turn of the event
loop as the paint already asked for, one block of both (150 ms in a drag of the paper's
Fig. 12(a)) where each alone is well under 100 ms.
"""

from __future__ import annotations

import ctypes
import dataclasses
import functools
import logging
import time
from collections.abc import Callable
from functools import partial
from typing import Any

from PySide6.QtCore import QObject, QTimer, Signal

from barymesh import MeshParams, TriMesh
from barymesh.app.jobs import Jobs
from barymesh.app.model import AppModel, MeshResult, compute
from barymesh.app.model.cell_document import CellTarget
from barymesh.app.view.scene_data import detail_data, scene_data

log = logging.getLogger(__name__)

#: Meshes up to this many triangles are built on the GUI thread (well within a frame).
SYNC_TRIANGLES = 5_000
#: A newer request abandons a running build of at least this many triangles; a smaller
#: one finishes and is shown first (during a slider drag every build would otherwise be
#: abandoned by the next mouse move and nothing shown until the drag stops).
CANCEL_TRIANGLES = 200_000
#: Builds of at least this many triangles feed the speed estimate.
_RATE_MIN_TRIANGLES = 100_000
#: The scene arrays of the last few meshes of up to this many triangles are kept (not
#: the meshes): Undo back to one of them (also right after cancelling a long build, whose
#: scene stage runs on for seconds beside whatever starts next) rebuilds only the mesh,
#: a few hundredths of a second, and reuses them.
RECENT_TRIANGLES = 100_000
RECENT_COUNT = 4
#: A build's result waits at most this long (ms) for the paint of the one before it
#: (see :attr:`MeshController.paint_pending`).
PAINT_WAIT_MS = 250


@dataclasses.dataclass(eq=False)
class BuildJob:
    """One build in a worker thread."""

    params: MeshParams | CellTarget
    generation: int
    triangles: int
    started: float
    cancelled: bool = False


@functools.lru_cache(maxsize=1)
def _malloc_trim() -> Callable[[int], int] | None:
    try:
        return ctypes.CDLL(None).malloc_trim  # glibc
    except (OSError, AttributeError):
        return None


def release_memory() -> None:
    """Give freed heap pages back to the system (glibc's ``malloc_trim``; no-op elsewhere)."""
    trim = _malloc_trim()
    if trim is not None:
        trim(0)


def _kept_scene(scene: object, _mesh: object) -> object:
    """``prepare`` of a rebuild whose scene arrays were kept (the build is deterministic)."""
    return scene


def _scene_or_none(mesh: TriMesh, **kwargs: Any) -> object:
    """:func:`barymesh.app.view.scene_data.scene_data`, or None if it fails (logged;
    never raises)."""
    try:
        return scene_data(mesh, **kwargs)
    except Exception:  # noqa: BLE001 - the colouring stays plain, the window lives on
        log.exception("making the scene again failed")
        return None


class MeshController(QObject):
    """Turns parameter changes into mesh results for the model (see module docstring)."""

    busy_changed = Signal(bool)
    #: (job or None): a worker build started (a BuildJob) or the last one ended (None).
    job_changed = Signal(object)
    #: (token, SceneData or None) from :meth:`request_detail`.
    detail_ready = Signal(object)
    #: (token, SceneData or None) from :meth:`request_scene`.
    scene_ready = Signal(object)

    def __init__(
        self, model: AppModel, parent: QObject | None = None, sync_triangles: int = SYNC_TRIANGLES
    ) -> None:
        super().__init__(parent)
        # builds, detail and scene requests in threads of their own: an abandoned build
        # winds down beside the next; after stop() nothing is delivered (app/jobs.py)
        self.jobs = Jobs(self, threads=None, name="barymesh-build")
        self.model = model
        self.sync_triangles = sync_triangles
        self._pending: tuple[MeshParams | CellTarget, int] | None = None
        self.current: BuildJob | None = None
        self._stale: list[BuildJob] = []
        self.rate: float | None = None  # triangles per second of recent large builds
        #: (key, scene) of the last small meshes delivered, newest last (see _recent_key)
        self._recent: list[tuple[tuple[object, ...], object]] = []
        self.last_request_time = 0.0
        self.builds = 0  # results handed to the model
        #: the 3D view's size in pixels (set by the window): the scene arrays made in the
        #: worker follow it (an overview's texels, its lines), not the mesh
        self.view_size: Callable[[], tuple[int, int]] | None = None
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setInterval(0)
        self._timer.timeout.connect(self._flush)
        #: whether the view has yet to paint the last result (set by the window); a
        #: result held meanwhile is handed on by :meth:`painted`, or after PAINT_WAIT_MS
        self.paint_pending: Callable[[], bool] | None = None
        self._held: tuple[BuildJob, MeshResult] | None = None
        self._paint_wait = QTimer(self)
        self._paint_wait.setSingleShot(True)
        self._paint_wait.setInterval(PAINT_WAIT_MS)
        self._paint_wait.timeout.connect(self._release)
        model.params_changed.connect(self._on_params_changed)

    @property
    def busy(self) -> bool:
        return self.current is not None

    @property
    def stopping(self) -> bool:
        """Whether a cancelled build is still running to its next checkpoint."""
        return bool(self._stale)

    def request(self) -> None:
        """Mesh the model's current parameters (coalesced with other requests)."""
        # the parameters, or a unit cell's visible elements (a CellTarget): compute()
        # builds either
        self._pending = (self.model.build_target(), self.model.generation)
        self.last_request_time = time.perf_counter()
        if self.current is not None and self.current.triangles >= CANCEL_TRIANGLES:
            self.current.cancelled = True  # a newer request: the long build is stale
        self._timer.start()

    def _on_params_changed(self, _params: MeshParams) -> None:
        self.request()

    def flush(self) -> None:
        """Start the pending request now (tests, scripted runs)."""
        self._timer.stop()
        self._flush()

    def painted(self) -> None:
        """The view painted: a result held for that paint is handed on at the event loop's
        next turn for timers (a zero timer, not a posted call: Qt handles posted calls
        before timers, and the result's handling joined the paint's block)."""
        if self._held is not None:
            self._paint_wait.start(0)

    def _release(self) -> None:
        self._paint_wait.stop()
        payload, self._held = self._held, None
        if payload is not None:
            self._finished(payload, held=True)

    def estimate(self, triangles: int) -> float | None:
        """Seconds a build of ``triangles`` should take here (None before any large one)."""
        return None if not self.rate else triangles / self.rate

    def _flush(self) -> None:
        if self._pending is None:
            return
        params, generation = self._pending
        shown = self.model.result
        if (
            shown is not None
            and shown.mesh is not None
            and shown.target == params
            and shown.source == "parameters"
        ):
            # back to what is on screen (Undo during a build): nothing to build
            self._pending = None
            self._abandon_current()
            self.model.set_result(dataclasses.replace(shown, generation=generation))
            return
        was_busy = self.current is not None
        if was_busy:
            assert self.current is not None  # was_busy
            if not self.current.cancelled or self._stale:
                return  # a short build finishes first / one is already winding down
            self._abandon_current(announce=False)
        self._pending = None
        triangles = params.predicted_triangles()
        prepare: Callable[..., object] = partial(
            scene_data,
            color_by=self.model.color_by,
            pixels=self.view_size() if self.view_size else None,
        )
        kept = self._recent_scene(params)
        if kept is not None:  # a small mesh shown a moment ago (Undo): its scene as it was
            prepare = partial(_kept_scene, kept)
        # an explicit tolerance can make the weld slow or fail: never on the GUI thread;
        # nor a sized mesh, whose triangles depend on the subdivisions the mesher picks
        if triangles <= self.sync_triangles and params.tolerance is None and not params.sized:
            self._deliver(compute(params, generation, prepare=prepare))
            if was_busy:
                self.busy_changed.emit(False)
                self.job_changed.emit(None)
            return
        job = BuildJob(params, generation, triangles, time.perf_counter())

        def cancelled(job: BuildJob = job) -> bool:
            return job.cancelled  # set by a newer request (long builds), Cancel or Undo

        if kept is None:  # the scene's stages stop an abandoned build too
            prepare = partial(prepare, cancel=cancelled)
        self.current = job
        if not was_busy:
            self.busy_changed.emit(True)
        self.job_changed.emit(job)
        self.jobs.submit(
            partial(compute, params, generation, prepare=prepare, cancel=cancelled),
            self._built,
            job,
        )

    def _abandon_current(self, announce: bool = True) -> None:
        job = self.current
        if job is None:
            return
        job.cancelled = True
        self._stale.append(job)
        self.current = None
        if announce:
            self.busy_changed.emit(False)
            self.job_changed.emit(None)

    def cancel(self) -> bool:
        """Abandon the running build (Cancel, Esc); True if there was one."""
        self._pending = None
        self._timer.stop()
        if self.current is None:
            return False
        self._abandon_current()
        return True

    def _deliver(self, result: MeshResult) -> None:
        if result.cancelled:
            return
        if (
            result.error is None
            and result.mesh is not None
            and result.params is not None
            and result.params.predicted_triangles() >= _RATE_MIN_TRIANGLES
        ):
            spent = sum(result.timings.values()) or result.seconds
            if spent > 0:
                rate = result.mesh.n_triangles / spent
                self.rate = rate if self.rate is None else 0.5 * (self.rate + rate)
        if self.model.set_result(result):  # dropped there if stale
            self.builds += 1
            self._remember(result)

    def _recent_key(self, target: object) -> tuple[object, ...]:
        """What a kept result must match: the target, the colouring and the view size its
        scene arrays were made for."""
        return (target, self.model.color_by, self.view_size() if self.view_size else None)

    def _remember(self, result: MeshResult) -> None:
        if (
            result.error is not None
            or result.mesh is None
            or result.scene is None
            or result.source != "parameters"
            or result.mesh.n_triangles > RECENT_TRIANGLES
        ):
            return
        key = self._recent_key(result.target)
        self._recent = [(k, s) for k, s in self._recent if k != key][-(RECENT_COUNT - 1) :]
        self._recent.append((key, result.scene))

    def _recent_scene(self, target: object) -> object | None:
        key = self._recent_key(target)
        return next((s for k, s in reversed(self._recent) if k == key), None)

    def _built(self, job: BuildJob, result: MeshResult) -> None:
        self._finished((job, result))

    def _finished(self, payload: tuple[BuildJob, MeshResult], held: bool = False) -> None:
        job, result = payload
        if (
            not held
            and job is self.current
            and self.paint_pending is not None
            and self.paint_pending()
        ):
            self._held = payload  # after the paint of the mesh before it (module docstring)
            self._paint_wait.start(PAINT_WAIT_MS)
            return
        was_current = job is self.current
        if was_current:
            self.current = None
            if (
                self._pending is not None
                and not result.cancelled
                and result.error is None
                and result.generation != self.model.generation
            ):
                # the value moved on (a drag) and its build follows: show this one meanwhile
                result = dataclasses.replace(result, generation=self.model.generation)
            self._deliver(result)
        elif job in self._stale:
            self._stale.remove(job)
        if self._pending is not None:
            self._flush()
        if was_current and self.current is None:
            self.busy_changed.emit(False)
            self.job_changed.emit(None)

    def request_detail(
        self, mesh: TriMesh, rect: tuple[float, float, float, float], token: object
    ) -> None:
        """Build :func:`barymesh.app.view.scene_data.detail_data` of ``rect`` in a thread.

        Emits ``detail_ready``.
        """
        shown = self.model.result
        scene = shown.scene if shown is not None and shown.mesh is mesh else None
        extra = (
            {}
            if scene is None
            else {
                "color_by": self.model.color_by,
                "ranges": scene.ranges,
                "bounds": scene.bounds,
                "pixels": self.view_size() if self.view_size else None,
            }
        )
        self.jobs.submit(
            partial(detail_data, mesh, rect, **extra),
            lambda token, data: self.detail_ready.emit((token, data)),
            token,
        )

    def request_scene(self, mesh: TriMesh, token: object) -> None:
        """Make the scene of ``mesh`` again in a thread, for the model's colouring (a dense
        paper mesh's image gets the per-triangle values it was made without); emits
        ``scene_ready`` with (token, SceneData or None if it failed)."""
        self.jobs.submit(
            partial(
                _scene_or_none,
                mesh,
                color_by=self.model.color_by,
                pixels=self.view_size() if self.view_size else None,
            ),
            lambda token, scene: self.scene_ready.emit((token, scene)),
            token,
        )

    def stop(self) -> None:
        """Forget pending requests and abandon running builds (the window is closing).

        Returns at once: an abandoned build stops at its next checkpoint in its own
        (daemon) thread and its result goes nowhere.
        """
        self.jobs.close()  # no thread delivers into this controller after this
        self._timer.stop()
        self._paint_wait.stop()
        self._held = None
        self._pending = None
        self._recent.clear()
        if self.current is not None:
            self.current.cancelled = True
            self._stale.append(self.current)
            self.current = None
        try:
            self.model.params_changed.disconnect(self._on_params_changed)
        except ValueError:
            pass
