"""VTK objects are made on the GUI thread only; worker threads hand over numpy arrays.

VTK is not thread-safe. A worker that made pyvista datasets while the GUI thread rendered
deadlocked the window (the worker held the GIL and waited for VTK's garbage-collector
lock; the GUI thread held that lock inside a render and waited for the GIL in a Python
observer) or corrupted the heap (``malloc_consolidate(): unaligned fastbin chunk
detected``, aborts in the window and at exit). These tests record every pyvista dataset
made while the real window builds dense meshes, details, the compare view and the
painter's previews in their worker threads, and check that each was made on the GUI
thread; and that what the workers return holds no VTK object at all.
"""

import dataclasses
import threading

import numpy as np
import pytest

pytest.importorskip("pyvistaqt")

import pyvista as pv  # noqa: E402
from vtkmodules.vtkCommonCore import vtkObjectBase  # noqa: E402

from barymesh import MeshParams, build_mesh  # noqa: E402
from barymesh.app.edit.painter_preview import build_preview  # noqa: E402
from barymesh.app.model import compute  # noqa: E402
from barymesh.app.teach.compare_view import compute_halves  # noqa: E402
from barymesh.app.view.polydata import Layer  # noqa: E402
from barymesh.app.view.scene_data import detail_data, scene_data  # noqa: E402
from barymesh.cell import load_cell_preset  # noqa: E402

DENSE = MeshParams(subdivisions=6)  # Fig. 12(a) at n = 6: 51,840 triangles, an overview


def vtk_objects(value, path="result", seen=None):
    """Paths of every VTK object reachable from ``value`` through dataclass fields,
    mappings and sequences (numpy arrays are leaves)."""
    seen = set() if seen is None else seen
    if id(value) in seen or isinstance(value, (str, bytes, int, float, np.ndarray)):
        return []
    seen.add(id(value))
    if isinstance(value, vtkObjectBase):
        return [path]
    found = []
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        for f in dataclasses.fields(value):
            found += vtk_objects(getattr(value, f.name), f"{path}.{f.name}", seen)
    elif isinstance(value, dict):
        for k, v in value.items():
            found += vtk_objects(v, f"{path}[{k!r}]", seen)
    elif isinstance(value, (list, tuple)):
        for i, v in enumerate(value):
            found += vtk_objects(v, f"{path}[{i}]", seen)
    return found


@pytest.fixture
def made_off_the_gui_thread(monkeypatch):
    """The pyvista datasets made by threads other than the main (GUI) thread."""
    off = []
    original = pv.DataObject.__init__

    def init(self, *args, **kwargs):
        if threading.current_thread() is not threading.main_thread():
            off.append((type(self).__name__, threading.current_thread().name))
        original(self, *args, **kwargs)

    monkeypatch.setattr(pv.DataObject, "__init__", init)
    return off


def test_the_recorder_sees_a_dataset_made_in_a_thread(made_off_the_gui_thread):
    """The check below can fail: a PolyData made in a thread is recorded."""
    thread = threading.Thread(target=pv.PolyData, name="probe")
    thread.start()
    thread.join()
    assert made_off_the_gui_thread == [("PolyData", "probe")]


@pytest.mark.parametrize(
    "params", [MeshParams(angle_step=15.0, subdivisions=2), DENSE], ids=["full-detail", "overview"]
)
def test_scene_data_holds_plain_arrays(params):
    mesh = build_mesh(params)
    data = scene_data(mesh)
    assert vtk_objects(data) == []
    assert all(isinstance(layer, Layer) for layer in data.layers.values())
    if data.overview is None:  # every triangle and every shared edge, as arrays
        assert data.layers["faces"].n_cells == mesh.n_triangles
        assert data.layers["shared_edges"].n_cells == len(mesh.interior_edges)
        assert data.layers["centroids"].n_points == mesh.n_triangles
    x0, x1, y0, y1 = data.bounds
    rect = (x0, x0 + 0.1 * (x1 - x0), y0, y0 + 0.1 * (y1 - y0))
    detail = detail_data(mesh, rect, pixels=(800, 600), ranges=data.ranges, bounds=data.bounds)
    assert detail is not None and vtk_objects(detail) == []


def test_a_part_too_dense_for_detail_comes_as_an_image_of_plain_arrays():
    mesh = build_mesh(MeshParams(subdivisions=12))  # 207,360 triangles
    data = scene_data(mesh, pixels=(800, 600))
    zoom = detail_data(mesh, data.bounds, pixels=(800, 600), ranges=data.ranges, bounds=data.bounds)
    assert zoom is not None and zoom.overview is not None  # an image, not polygons
    assert vtk_objects(zoom) == []


def test_compute_compare_and_painter_results_hold_no_vtk_object():
    assert vtk_objects(compute(DENSE, prepare=scene_data)) == []
    generation, halves = compute_halves(MeshParams(angle_step=30.0), 7)
    assert generation == 7 and [h.mode for h in halves] == ["paper", "conforming"]
    assert vtk_objects(halves) == []
    cell = load_cell_preset("coding-16x16")
    built = build_preview(cell, cell.pixels.mask, 1e-3, 1)
    assert built.error is None and vtk_objects(built) == []
    assert built.faces.n_cells == built.cell_mesh.mesh.n_triangles  # drawn as triangles
    assert built.edges.n_cells == len(built.cell_mesh.mesh.edges)


def test_the_window_makes_datasets_on_the_gui_thread_only(window, qtbot, made_off_the_gui_thread):
    """Dense meshes, their details and the compare view, built by the real window's
    worker threads: every dataset on screen was made by the GUI thread."""
    window.model.set_params(DENSE)
    qtbot.waitUntil(
        lambda: window.model.result is not None and window.model.result.mesh.n_triangles == 51_840,
        timeout=120_000,
    )
    scene = window.scene
    qtbot.waitUntil(lambda: scene.overview is not None, timeout=60_000)
    # rest the camera on a small part of the inner ring: the worker builds its detail
    camera = window.plotter.camera
    camera.focal_point = (4.5, 0.0, 0.0)
    camera.position = (4.5, 0.0, 50.0)
    camera.parallel_scale = 0.3
    window.plotter.iren.interactor.InvokeEvent("EndInteractionEvent")  # the camera rests
    qtbot.waitUntil(lambda: scene.detail_rect is not None, timeout=60_000)
    assert scene.datasets["faces"].n_cells > 0
    # the paper-vs-conforming window meshes both halves in its own worker
    compare = window.teaching_windows.show_compare()
    qtbot.waitUntil(
        lambda: (
            compare.halves.get("conforming") is not None
            and compare.halves["conforming"].result is not None
        ),
        timeout=120_000,
    )
    assert (
        compare.scenes["paper"].datasets["faces"].n_cells > 0
        or compare.scenes["paper"].overview is not None
    )
    assert made_off_the_gui_thread == []


def test_an_abandoned_build_stops_inside_the_scene_stage():
    """Esc on a dense build: the overview's stages poll the cancel flag, so the worker stops
    there (it ran its 3 s on before) and the result says cancelled, not a mesh."""
    from functools import partial

    from barymesh import BuildCancelled

    mesh = build_mesh(DENSE)
    polls = []

    def cancel_after_the_first_poll():
        polls.append(1)
        return len(polls) > 1

    with pytest.raises(BuildCancelled):
        scene_data(mesh, cancel=cancel_after_the_first_poll)
    assert len(polls) == 2  # stopped at the second checkpoint, before the line layers
    assert scene_data(mesh, cancel=lambda: False).overview is not None
    flag = {"on": False}

    def prepare(m, **kw):
        flag["on"] = True  # Esc arrives while the scene is being made
        return scene_data(m, cancel=lambda: flag["on"])

    result = compute(DENSE, prepare=partial(prepare))
    assert result.cancelled and result.mesh is None


def test_garbage_made_in_a_worker_is_collected_in_the_gui_thread(window, qtbot):
    # CPython runs its cyclic collector in whichever thread crosses the allocation
    # threshold; a worker that collected a VTK object deadlocked the window against a
    # render (tests/test_app_views.py, the Infinite array tab's figure in a worker). With
    # the window up, collection is the GUI thread's timer's: cycles dropped in a worker,
    # with far more allocations than a generation-0 threshold, die in the GUI thread.
    import gc

    from barymesh.app.gui_gc import collect_in_gui_thread

    assert not gc.isenabled()
    collector = collect_in_gui_thread()  # the window's own: one per process
    assert collect_in_gui_thread() is collector
    died_in: list[int] = []

    class Node:
        def __init__(self) -> None:
            self.me = self  # a reference cycle: only the cyclic collector frees it

        def __del__(self) -> None:
            died_in.append(threading.get_ident())

    kept: list = []

    def worker() -> None:
        for _ in range(50):
            Node()
        # live containers past the generation-0 threshold (the count is allocations less
        # deallocations): the automatic collector would run here, in the worker
        kept.extend([i] for i in range(3 * gc.get_threshold()[0]))

    thread = threading.Thread(target=worker)
    thread.start()
    thread.join()
    assert died_in == []  # nothing collected in the worker
    before = collector.collections
    qtbot.waitUntil(lambda: len(died_in) == 50, timeout=10_000)
    assert set(died_in) == {threading.get_ident()}  # all in the GUI thread
    assert collector.collections > before
    kept.clear()


def test_the_gui_collector_collects_with_no_gl_context_current(qtbot):
    # VTK objects of a closed window die at a collection; whatever GL resource one still
    # frees must not be freed in another window's context (barymesh.app.gui_gc)
    import gc

    from PySide6.QtGui import QOffscreenSurface, QOpenGLContext

    from barymesh.app import gui_gc

    surface = QOffscreenSurface()
    surface.create()
    context = QOpenGLContext()
    assert context.create()
    seen: list = []

    class Node:
        def __init__(self) -> None:
            self.me = self  # a cycle: only a collection frees it

        def __del__(self) -> None:
            seen.append(QOpenGLContext.currentContext())

    enabled = gc.isenabled()
    gc.disable()  # no automatic collection between the steps below
    try:
        gc.collect()
        assert context.makeCurrent(surface)
        assert QOpenGLContext.currentContext() is context
        Node()
        assert gui_gc.collect() >= 1
        assert seen == [None]  # what the garbage freed, it freed with no context current
        assert QOpenGLContext.currentContext() is None
        # the timer's collections go the same way
        collector = gui_gc.GuiThreadCollector(None, dragging=lambda: False)
        collector.timer.stop()
        collector.thresholds = (0, 0, 0)
        assert context.makeCurrent(surface)
        Node()
        collector.collect()
        assert collector.collections == 1
        assert seen == [None, None]
    finally:
        if enabled:
            gc.enable()
